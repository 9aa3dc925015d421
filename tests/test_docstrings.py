"""Docstrings and comments in src/gyrocal say what the code does and why; the history of a change goes to git.

References: the package's sources, their docstrings read with ast and their comments with tokenize.
"""

from __future__ import annotations

import ast
import io
import re
import tokenize
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "gyrocal"

#: Phrases that tell the story of a change rather than what the code does.
HISTORY = re.compile(r"\bbefore:|\bused to\b|\bpreviously\b|\bno longer\b|\bformerly\b|\bold (rule|code|version)\b"
                     r"|\bissue \d+\b|\bround \d\b|\blast round\b", re.IGNORECASE)

#: (file, the line's text around the phrase): a use of a phrase that is no history, and why.
ALLOWED = {
    ("segmentation/_measure.py", "Used to show people what was there"): "'is used to': what the measures are for",
    ("results/sections.py", "used to catch unit mistakes later"): "'is used to': what the section is for",
    ("studies/servo_convergence.py", "per case used to count iterations"): "'are used to': what the runs are for",
    ("capture/device.py", "the device no longer holds it"): "the simulated port's state while it runs",
}


def _texts(path: Path):
    """(line, text) of every module, class and function docstring line and every comment of `path`."""
    source = path.read_text(encoding="utf-8")
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=False)
            first = node.body[0].lineno if doc else 0
            yield from ((first + i, line) for i, line in enumerate((doc or "").splitlines()))
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT:
            yield tok.start[0], tok.string


def _found() -> list[str]:
    found = []
    for path in sorted(SRC.rglob("*.py")):
        name = path.relative_to(SRC).as_posix()
        for line, text in _texts(path):
            if HISTORY.search(text) and not any(f == name and part in text for f, part in ALLOWED):
                found.append(f"{name}:{line}: {text.strip()}")
    return found


def test_docstrings_and_comments_tell_no_history():
    found = _found()
    assert not found, "say what the code does and why; the history goes to git:\n" + "\n".join(found)


def test_every_allowed_use_is_still_there():
    texts = {(path.relative_to(SRC).as_posix(), text) for path in SRC.rglob("*.py") for _, text in _texts(path)}
    stale = [key for key in ALLOWED if not any(f == key[0] and key[1] in t for f, t in texts)]
    assert not stale, stale


def test_the_check_sees_a_planted_phrase(tmp_path):
    planted = tmp_path / "planted.py"
    planted.write_text('"""Fits k (before: RMS z 2.5)."""\n\n\ndef f():\n    """What f does."""\n'
                       "    return 1  # the old rule, see issue 21\n")
    assert [line for line, text in _texts(planted) if HISTORY.search(text)] == [1, 6]
