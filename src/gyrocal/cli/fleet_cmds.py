"""Command ``fleet``: the distribution, capability, control charts, yield and drift of the units in a store."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import InputError
from ._options import StoreUrl, iso_time
from ._outputs import check_output
from .app import app, console

__all__ = ["fleet"]


def _calibrations(url: str, since: str | None, kind: str | None) -> list:
    """The store's calibration records (of `kind` or its family), created at or after `since`."""
    from ..store import is_calibration_kind, open_store, parse_url

    if kind is not None and not is_calibration_kind(kind):
        raise InputError(f"--kind {kind!r} is not a calibration kind; give calibration, imu or thermal, or one of "
                         "those with a dotted suffix (calibration.servo)")
    parsed = parse_url(url)
    if parsed.path is not None and not parsed.path.is_file():
        raise InputError(f"no store at {parsed.display}: the fleet report reads an existing store")
    start = iso_time(since, "--since")
    with open_store(parsed) as st:
        if st.count() == 0:
            raise InputError(f"the store {parsed.display} is empty")
        records = st.list(since=start)
    calibrations = [r for r in records if is_calibration_kind(r.kind)
                    and (kind is None or r.kind == kind or r.kind.startswith(kind + "."))]
    if not calibrations:
        what = "calibration" if kind is None else f"{kind!r}"
        raise InputError(f"the store {parsed.display} holds no {what} records"
                         + (f" created since {start:%Y-%m-%dT%H:%M:%SZ}" if start else ""))
    return calibrations


def _finite(x):
    """JSON without NaN: non-finite numbers become null."""
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_finite(v) for v in x]
    return x


@app.command()
def fleet(
    store: StoreUrl,
    output: Annotated[Optional[Path], typer.Option(
        "-o", "--output", help="Report folder: fleet.md and a histogram and control chart (PNG) per parameter (default: none, --json only).")] = None,
    limits: Annotated[Optional[Path], typer.Option(
        "--limits", help="Specification limits (TOML; default: the records' own acceptance sections).",
        metavar="FILE")] = None,
    since: Annotated[Optional[str], typer.Option("--since", help="Only records created at or after this ISO 8601 "
                                                 "time (default: all).")] = None,
    kind: Annotated[Optional[str], typer.Option("--kind", help="Only calibrations of this kind or family "
                                                "(calibration, calibration.servo, imu; default: all).")] = None,
    confidence: Annotated[float, typer.Option("--confidence", help="Level of the intervals.")] = 0.95,
    as_json: Annotated[bool, typer.Option("--json", help="Print the statistics as JSON.")] = False,
) -> None:
    """The fleet: each parameter's spread across units (newest calibration each), Cp and Cpk with intervals,
    control charts per station, yield with Wilson intervals, and the units that drifted most."""
    if output is None and not as_json:
        raise InputError("give -o FOLDER for the report, or --json for the statistics")
    if not 0 < confidence < 1:
        raise InputError(f"--confidence must lie between 0 and 1 (0.95 for 95%), got {confidence:g}")
    check_output(output, folder=True, inputs=(limits,))
    from ..station.fleet import fleet_statistics

    bounds = None
    if limits is not None:
        from ..station.limits import read_limits

        bounds = read_limits(limits)
    stats = fleet_statistics(_calibrations(store, since, kind), bounds, confidence)
    if output is not None:
        from ..station.fleet_report import write_report

        written = write_report(stats, output)
        if not as_json:
            console.print(f"wrote {output}: {len(written)} file(s) on {stats['units']} unit(s), "
                          f"{stats['records']} calibration(s)", highlight=False)
    if as_json:
        typer.echo(json.dumps(_finite(stats), indent=1, allow_nan=False))
