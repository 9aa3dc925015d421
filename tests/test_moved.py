"""Old import paths of the modules that moved into the stage packages (README, "Where modules moved").

Reference: a fresh interpreter's import system (each old path must give the very module object of the new
path, and old-style ``from gyrocal.calibration import Calibration`` the same class), README's table read as
text, and the import statements of the source and the tests (ast).
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

from test_layers import _imports

from gyrocal._moved import MOVED

ROOT = Path(__file__).resolve().parents[1]


def test_every_old_path_gives_the_module_at_its_new_place():
    code = ("import importlib, sys\n"
            "from gyrocal._moved import MOVED\n"
            "bad = [old for old, new in MOVED.items() if importlib.import_module(old) is not importlib.import_module(new)]\n"
            "bad += [new for new in MOVED.values() if sys.modules[new].__spec__.name != new]\n"
            "from gyrocal.calibration import Calibration\n"
            "from gyrocal.results.calibration import Calibration as C\n"
            "import gyrocal.timebase, gyrocal.recording.timebase\n"
            "print(bad, Calibration is C, gyrocal.timebase is gyrocal.recording.timebase)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert out.stdout.split() == ["[]", "True", "True"], out.stdout + out.stderr


def test_readme_lists_every_move():
    text = (ROOT / "README.md").read_text()
    table = text[text.index("### Where modules moved"):]
    listed = dict(re.findall(r"`(gyrocal\.[\w.]+)` \| `(gyrocal\.[\w.]+)`", table))
    assert listed == MOVED


def test_nothing_of_gyrocal_imports_an_old_path():
    """Only this file uses the old names; everything else imports the new ones."""
    found = []
    for path in sorted([*(ROOT / "src").rglob("*.py"), *(ROOT / "tests").glob("*.py"), *(ROOT / "tools").glob("*.py"),
                        *(ROOT / "bench").glob("*.py")]):
        if path.name == "test_moved.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else (
                [node.module or ""] if isinstance(node, ast.ImportFrom) and node.level == 0 else [])
            found += [f"{path.relative_to(ROOT)}:{node.lineno}: {n}" for n in names
                      if any(n == old or n.startswith(old + ".") for old in MOVED)]
    for path in sorted((ROOT / "src").rglob("*.py")):  # relative imports, resolved
        found += [f"{path.relative_to(ROOT)}:{line}: {target}" for target, _, line, _ in _imports(path)
                  if any(target == old or target.startswith(old + ".") for old in MOVED)]
    assert found == []
