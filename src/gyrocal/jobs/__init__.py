"""Jobs: every command's core (calibrate, imu, thermal, thermal-bias, noise, verify) as one interface.

A job is built from typed inputs (paths or recordings already read, options in internal units: rad/s,
radians, rad/s/sqrt(Hz)); its ``run()`` returns one :class:`~gyrocal.jobs.result.JobResult` (the
document written to the file, warnings, notes, fit quality, the figures it can draw) or refuses with
:class:`~gyrocal.errors.InputError`. The CLI commands parse their flags into a job and print, save and
stamp its result; the production station (``gyrocal batch``) runs every row through :func:`run_job`.

This package owns the registry :data:`JOBS` (name -> ``module:Class``, imported only when a job of that
name is made), :func:`run_job`, :class:`JobResult` and :class:`Job`. At module level it imports only the
standard library and ``gyrocal.errors``, so ``import gyrocal.jobs`` loads no job and no numpy.

Layer 8 (firmware, exports, simulation, figures and the store) of docs/architecture.md: imports the package
root and layers 1 to 8 only, and not store or simulation; the CLI and the station import jobs, never the
reverse.
"""

from __future__ import annotations

import importlib

from ..errors import InputError

__all__ = ["JOBS", "Job", "JobResult", "job_class", "make_job", "run_job"]

#: Job name (the command's) -> the class that runs it, as ``module:Class``.
JOBS = {
    "calibrate": "gyrocal.jobs.calibrate:CalibrateJob",
    "imu": "gyrocal.jobs.imu:ImuJob",
    "thermal": "gyrocal.jobs.thermal:ThermalJob",
    "thermal-bias": "gyrocal.jobs.thermal_bias:ThermalBiasJob",
    "noise": "gyrocal.jobs.noise:NoiseJob",
    "verify": "gyrocal.jobs.verify:VerifyJob",
}


def job_class(name: str):
    """The class of the job `name`, imported now; an unknown name is refused with the names there are."""
    if name not in JOBS:
        raise InputError(f"unknown job {name!r}; the jobs are {', '.join(JOBS)}")
    module, cls = JOBS[name].split(":")
    return getattr(importlib.import_module(module), cls)


def make_job(name: str, **options):
    """The job `name` built from `options` (its fields); an option it does not take is refused in one line."""
    import dataclasses

    cls = job_class(name)
    known = [f.name for f in dataclasses.fields(cls)]
    unknown = sorted(set(options) - set(known))
    if unknown:
        raise InputError(f"job {name} takes no option {unknown[0]!r}; it takes {', '.join(known)}")
    missing = [f.name for f in dataclasses.fields(cls) if f.name not in options
               and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING]
    if missing:
        raise InputError(f"job {name} needs {', '.join(missing)}")
    return cls(**options)


def run_job(name: str, **options):
    """Build the job `name` from `options` and run it: its :class:`JobResult`."""
    return make_job(name, **options).run()


def __getattr__(name: str):
    if name in ("Job", "JobResult"):
        from . import result

        return getattr(result, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
