"""Rules for the code and the test suite itself, checked in the one CI command (README's test line).

References: ruff (configured in pyproject.toml), pytest run on a planted skipping test, and the test
sources read as text.
"""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TESTS = ROOT / "tests"


def test_ruff_finds_nothing():
    ruff = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which("ruff")
    assert ruff is not None, "ruff is in the test extra: pip install -e '.[test]'"
    out = subprocess.run([ruff, "check", "--no-cache", "src", "tests", "bench", "tools"], cwd=ROOT,
                         capture_output=True, text=True, timeout=120, check=False)
    assert out.returncode == 0, out.stdout + out.stderr


def test_no_test_is_written_to_skip():
    marks = re.compile(r"importorskip|pytest\.skip\(|mark\.skip|skipif")
    found = [f"{p.name}:{i}" for p in TESTS.glob("*.py") if p.name != Path(__file__).name
             for i, line in enumerate(p.read_text().splitlines(), 1) if marks.search(line)]
    assert not found, found


def test_a_run_with_a_skip_fails(tmp_path):
    """The conftest guard: a skipped test turns a green run red (exit status 1)."""
    shutil.copy(TESTS / "conftest.py", tmp_path / "conftest.py")
    (tmp_path / "test_planted.py").write_text("import pytest\n\n\ndef test_skips():\n    pytest.skip('planted')\n\n\n"
                                              "def test_passes():\n    pass\n")
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(tmp_path)],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120, check=False)
    assert out.returncode == 1, out.stdout
    assert "did not run" in out.stdout and "test_planted.py::test_skips" in out.stdout


def test_modules_and_functions_stay_small():
    """No module over 400 lines; no function body over 60 lines (docstring aside) unless its first
    comment says why (``# long function: ...``)."""
    problems = []
    for path in sorted((ROOT / "src" / "gyrocal").rglob("*.py")):
        text = path.read_text()
        lines = text.splitlines()
        if len(lines) > 400:
            problems.append(f"{path.relative_to(ROOT)}: {len(lines)} lines")
        for node in ast.walk(ast.parse(text)):
            if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            body = node.body
            if isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) and len(body) > 1:
                body = body[1:]
            length = node.end_lineno - body[0].lineno + 1
            head = "\n".join(lines[node.lineno - 1:body[0].lineno + 2])
            if length > 60 and "# long function:" not in head:
                problems.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}: {length} lines")
    assert not problems, "\n".join(problems)
