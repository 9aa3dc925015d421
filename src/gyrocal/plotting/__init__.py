"""Pictures of recordings, calibrations and studies (needs the ``plot`` extra).

Each module draws into a caller's matplotlib ``Axes`` or ``Figure`` and returns the
artists it made; none touches pyplot's global state. Import the module you need,
for example ``from gyrocal.plotting.calibration import calibration_figure``.
"""

from .figure import check_figure_path, new_figure, save_figure

__all__ = ["check_figure_path", "new_figure", "save_figure"]
