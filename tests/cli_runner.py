"""One in-process runner for every CLI test.

Runs go through :func:`gyrocal.cli.app.run` (the real error boundary) inside typer's
``CliRunner`` isolation, so stdout, stderr and the exit code are what a user sees.
"""

import sys

from typer.testing import CliRunner

from gyrocal.cli.app import run


def invoke(*args) -> tuple[int, str, str]:
    """Run the CLI in-process; return (exit code, stdout, stderr)."""
    runner = CliRunner()
    with runner.isolation(env={"COLUMNS": "120"}) as (out, err, _):
        code = run([str(a) for a in args])
        sys.stdout.flush()
        sys.stderr.flush()
        return code, out.getvalue().decode(), err.getvalue().decode()


def refused(*args) -> str:
    """Assert the one-line refusal contract (exit 2, no traceback) and return the line."""
    code, out, err = invoke(*args)
    assert code == 2, (out, err)
    assert "Traceback" not in out + err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), err
    return lines[0]


def simulated(path, *args):
    """`gyrocal simulate -o path ARGS`, asserted to succeed; returns `path`."""
    code, _, err = invoke("simulate", "-o", path, *args)
    assert code == 0, err
    return path
