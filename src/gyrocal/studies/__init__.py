"""Monte Carlo studies that reproduce the simulation results of both seeds.

Each study is one module with ``run(out, ..., progress=None) -> StudyOutput`` and
``work_units()``; :func:`run_study` picks one by its command-line name.

Layer 9 (studies, capture and the station) of docs/architecture.md: imports the package root and layers 1 to 9
only.
"""

from __future__ import annotations

from pathlib import Path
from typing import get_args

from ..choices import StudyName
from ..errors import InputError
from ._common import Progress, ServoSettings, StudyOutput

__all__ = ["StudyName", "STUDY_NAMES", "run_study", "study_units", "StudyOutput", "ServoSettings"]

STUDY_NAMES: tuple[str, ...] = get_args(StudyName)


def _check(name: str) -> None:
    if name not in STUDY_NAMES:
        raise InputError(f"study {name!r} is not one of {', '.join(STUDY_NAMES)}")


def study_units(name: StudyName, settings: ServoSettings | None = None, *, gyros: int | None = None,
                **options) -> int:
    """How many progress units :func:`run_study` will report for `name` with the same arguments."""
    _check(name)
    settings = settings or ServoSettings()
    if name in ("servo-normal", "servo-extreme"):
        from .servo_errors import work_units
        return work_units(settings)
    if name == "servo-speed":
        from .servo_speed import PAPER_SPEEDS, work_units
        return work_units(options.get("speeds", PAPER_SPEEDS), settings)
    if name == "servo-convergence":
        from .servo_convergence import work_units
        return work_units()
    from .thermal_compare import work_units
    return work_units(gyros)


def run_study(
    name: StudyName,
    out: str | Path,
    *,
    gyros: int | None = None,
    reps: int | None = None,
    seed: int = 0,
    settings: ServoSettings | None = None,
    progress: Progress | None = None,
    **options,
) -> StudyOutput:
    """Run a study by name and write its figures and tables under `out`.

    Parameters
    ----------
    name : {"servo-normal", "servo-extreme", "servo-speed", "servo-convergence", "thermal-compare"}
    out : path
        Output folder (created).
    gyros, reps : int, optional
        Scale the study down (or up); each study's default is the paper's size.
    seed : int
        Seed of the random generator.
    settings : ServoSettings, optional
        Servo simulation settings (studies of the servo method of Wang et al.; thermal-compare takes ``sample_rate``
        and ``noise`` as options).
    progress : callable, optional
        ``progress(advance, label)`` after each unit of work.
    **options
        Study-specific keywords (for example ``methods`` for ``servo-speed``).
    """
    _check(name)
    for label, value in (("gyros", gyros), ("reps", reps)):
        if value is not None and (int(value) != value or value < 1):
            raise InputError(f"--{label} must be a positive integer, got {value!r}")
    if name == "servo-convergence" and gyros is not None:
        raise InputError("servo-convergence calibrates the servo method of Wang et al., Table I's three fixed gyros; --gyros does not apply")
    sizes = {key: int(v) for key, v in (("gyros", gyros), ("reps", reps)) if v is not None}
    common = dict(seed=seed, progress=progress, **options)
    out = Path(out)
    if name == "thermal-compare":
        from .thermal_compare import run
        return run(out, **sizes, **common)
    if settings is not None:
        common["settings"] = settings
    if name in ("servo-normal", "servo-extreme"):
        from .servo_errors import run
        return run(out, name.split("-")[1], **sizes, **common)
    if name == "servo-speed":
        from .servo_speed import run
        return run(out, **sizes, **common)
    from .servo_convergence import run
    return run(out, **sizes, **common)
