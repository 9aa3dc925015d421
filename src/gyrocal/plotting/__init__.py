"""Pictures of recordings, calibrations and studies (needs the ``plot`` extra).

Each module draws into a caller's matplotlib ``Axes`` or ``Figure`` and returns the
artists it made; none touches pyplot's global state. Import the module you need,
for example ``from gyrocal.plotting.calibration import calibration_figure``.

Layer 8 (firmware, exports, simulation, figures and the store) of docs/architecture.md: imports the package
root and layers 1 to 8 only, and not firmware, jobs, store.
"""

from .figure import check_figure_path, new_figure, save_figure

__all__ = ["check_figure_path", "new_figure", "save_figure"]
