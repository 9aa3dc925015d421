"""Old import paths of modules that moved into the stage packages, kept working.

``import gyrocal.timebase`` (and ``from gyrocal.calibration import Calibration``) load the module at its new
place (``gyrocal.recording.timebase``) under the old name too: one object, so ``isinstance`` checks and
monkeypatching see the same classes. The table is README's list of moved modules; gyrocal's own code uses
the new paths only (``tests/test_layers.py``).
"""

from __future__ import annotations

import importlib
import sys
from importlib.machinery import ModuleSpec

#: Old module -> new module.
MOVED = {
    "gyrocal.timebase": "gyrocal.recording.timebase",
    "gyrocal.timegaps": "gyrocal.recording.timegaps",
    "gyrocal.breaks": "gyrocal.recording.breaks",
    "gyrocal.saturation": "gyrocal.recording.saturation",
    "gyrocal.windows": "gyrocal.segmentation.windows",
    "gyrocal.stillness": "gyrocal.segmentation.stillness",
    "gyrocal.moments": "gyrocal.observations.moments",
    "gyrocal.window_stats": "gyrocal.observations.window_stats",
    "gyrocal.longrun": "gyrocal.observations.longrun",
    "gyrocal.partial_cycles": "gyrocal.observations.partial_cycles",
    "gyrocal.observed": "gyrocal.observations.observed",
    "gyrocal.turn_angle": "gyrocal.observations.turn_angle",
    "gyrocal.excess": "gyrocal.checks.excess",
    "gyrocal.screening": "gyrocal.segmentation.screening",
    "gyrocal.fit_checks": "gyrocal.checks.fit",
    "gyrocal.quality": "gyrocal.checks.quality",
    "gyrocal.plausibility": "gyrocal.checks.plausibility",
    "gyrocal.noise_terms": "gyrocal.checks.noise_terms",
    "gyrocal.stages": "gyrocal.pipeline.stages",
    "gyrocal.calibration": "gyrocal.results.calibration",
    "gyrocal.files": "gyrocal.results.files",
    "gyrocal.legacy": "gyrocal.results.legacy",
    "gyrocal.sections": "gyrocal.results.sections",
    "gyrocal.noise_file": "gyrocal.noise.document",
    "gyrocal.thermal_bias_file": "gyrocal.flight.thermal_bias_document",
    "gyrocal.thermal_report": "gyrocal.plotting.thermal_report",
    "gyrocal.exporters": "gyrocal.export.builtin",
    "gyrocal.flight_exporters": "gyrocal.export.flight",
    "gyrocal.imucal_export": "gyrocal.export.imucal",
    "gyrocal.design": "gyrocal.planning.design",
}


class _Alias:
    """Finds an old name and hands out the module at its new place (a meta path finder and its loader; the
    protocol is duck-typed, which keeps ``importlib.abc`` and its imports out of ``import gyrocal``)."""

    def find_spec(self, name, path=None, target=None):
        if name not in MOVED:
            return None
        return ModuleSpec(name, self)

    def create_module(self, spec):
        module = importlib.import_module(MOVED[spec.name])
        spec.loader_state = module.__spec__
        return module

    def exec_module(self, module):
        # the import system stamped the old name's spec on the module: give it back its own
        module.__spec__ = module.__spec__.loader_state


def install() -> None:
    """Put the finder on ``sys.meta_path`` once."""
    if not any(isinstance(finder, _Alias) for finder in sys.meta_path):
        sys.meta_path.append(_Alias())
