"""``gyrocal capture --write-back``: the accepted calibration to the device, read back and recorded."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import GyrocalError, InputError
from .app import console, message


@dataclass(frozen=True)
class WriteBack:
    """Where and how to write back: the capture's open `link` (None: the link ended), its wire, the timeout [s],
    and the device's hello frame (its rate unit)."""

    link: object
    wire: str | None
    timeout: float
    hello: object = None

    def __call__(self, cal, doc: dict) -> tuple[dict, GyrocalError | None]:
        """Send `cal` and check the echo; `doc` with its ``device`` section, and the refusal to raise once the file
        and the record are written (they say it was not written back), or None."""
        from ..capture.write_back import request_for, write_back

        device = dict(doc.get("device") or {})
        try:
            if self.wire != "frames" or self.link is None or self.hello is None:
                raise InputError("--write-back needs the link to a device that sends gyrocal frames, still open "
                                 f"after the capture (here: {self._missing()})")
            request = request_for(cal, self.hello.rate_unit)
            answer = write_back(self.link, request, self.timeout)
        except GyrocalError as exc:
            return {**doc, "device": {**device, "written_back": False, "refusal": message(exc)}}, exc
        serial = (doc.get("unit") or {}).get("serial")
        console.print(f"{serial + ': ' if serial else ''}written to the device and read back", highlight=False)
        device.update(written_back=True, request=answer.seq, rate_unit=answer.rate_unit,
                      applied=bool(answer.flags & 1), matrix=[list(answer.matrix[i:i + 3]) for i in (0, 3, 6)],
                      offset=list(answer.offset))
        return {**doc, "device": device}, None

    def _missing(self) -> str:
        return ("the link ended" if self.link is None else "no hello frame" if self.hello is None
                else f"{self.wire or 'no'} wire")
