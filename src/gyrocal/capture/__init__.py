"""Live capture from a device: wire formats, the virtual device, the capture loop and the guided protocol.

* :mod:`.frames`: gyrocal frames (binary, CRC-16) and their streaming decoder;
  :mod:`.text`: text lines as an Arduino ``Serial.println`` sends them.
* :mod:`.c_device`: the C library's frame encoder and on-device session through ctypes.
* :mod:`.simulated`: simulated device sessions in raw counts.

Layer 9 (studies, capture and the station) of docs/architecture.md: imports the package root and layers 1 to 9
only.
"""

from .frames import FrameDecoder
from .text import TextDecoder

__all__ = ["FrameDecoder", "TextDecoder"]
