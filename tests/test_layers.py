"""Layers that read one way (CONTRACT.md section 1, docs/architecture.md): a forbidden import fails here.

Reference: the source itself, parsed with ``ast`` (every import, at module level or inside a function),
and, for the lazy command line, a fresh interpreter's ``sys.modules``.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import gyrocal

SRC = Path(gyrocal.__file__).parent

#: The stages a recording passes through, bottom to top (docs/architecture.md): a package imports packages of
#: its own rank or below, never above. Rank 0 is the package root's shared vocabulary (errors, units,
#: constants, choices, models, quaternion and the private helpers).
RANKS: dict[str, int] = {
    "recording": 1,                        # samples, units and the time base
    "segmentation": 2,                     # windows: turns, standstills, stillness
    "io": 3, "observations": 3,            # reading files; windows reduced to observations
    "estimators": 4,                       # the fits
    "checks": 5, "planning": 5,            # self-checks of a fit; predicted accuracy of a design
    "results": 6,                          # the calibration, its sections, the file registry
    "pipeline": 7, "imu": 7, "thermal": 7, "flight": 7, "noise": 7, "verify": 7,   # the methods (jobs' cores)
    "jobs": 8, "firmware": 8, "export": 8, "simulation": 8, "plotting": 8, "store": 8,
    "studies": 9, "capture": 9, "station": 9,
    "cli": 10, "__main__": 11,
}
#: Imports against the ranks, inside one function each, with the reason they are allowed.
UPWARD: dict[tuple[str, str], str] = {
    ("gyrocal.results.calibration", "gyrocal.imu.thermal"): "Calibration.apply corrects an IMU thermal section",
    ("gyrocal.results.calibration", "gyrocal.firmware.header"): "Calibration.c_header, a public method",
    ("gyrocal.thermal.model", "gyrocal.firmware.header"): "ThermalCalibration.c_header, a public method",
    ("gyrocal.results.files", "gyrocal.thermal.model"): "load_thermal / load_correction name the kind they return",
    ("gyrocal.results.legacy", "gyrocal.thermal.model"): "the v1 thermal upgrade applies the model's rule",
}
#: Packages that, within the ranks, must still not import these (same rank or below).
FORBIDDEN: dict[str, set[str]] = {
    "simulation": {"io", "thermal", "plotting", "export", "firmware", "store", "jobs"},
    "plotting": {"store", "jobs", "firmware"},
    "export": {"store", "jobs"},
    # the jobs are the commands' cores: the CLI and the station drive them, never the reverse
    "jobs": {"store", "simulation"},
}
#: Packages that import nothing of gyrocal but the package root's vocabulary.
ROOT_ONLY = {"store"}
#: Modules of gyrocal.cli that hold commands; each may import none of the others.
CMDS_SUFFIX = "_cmds"
#: Module-level imports a command module may make: ``gyrocal --help`` must not load numpy.
LIGHT_FOR_CLI = ("gyrocal.choices", "gyrocal.constants", "gyrocal.errors", "gyrocal.export", "gyrocal.cli", "typer")


def _module_name(path: Path) -> str:
    rel = path.relative_to(SRC.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imports(path: Path) -> list[tuple[str, str | None, int, bool]]:
    """(module imported, name imported or None, line, at module level) for every import in `path`."""
    module = _module_name(path)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    tree = ast.parse(path.read_text(), filename=str(path))
    top = {id(node) for node in tree.body}
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, None, node.lineno, id(node) in top) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[: len(anchor) - (node.level - 1)]
                base = ".".join(anchor + ([base] if base else []))
            for a in node.names:
                full = f"{base}.{a.name}"
                # "from . import x" may import a submodule x: count it as that module
                is_module = (SRC.parent / Path(*full.split("."))).with_suffix(".py").exists() or (
                    SRC.parent / Path(*full.split(".")) / "__init__.py").exists()
                out.append((full, None, node.lineno, id(node) in top) if is_module
                           else (base, a.name, node.lineno, id(node) in top))
    return out


def _component(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if parts[0] == "gyrocal" and len(parts) > 1 else None


def _owner(module: str) -> str:
    """Who may use a private part of `module`: its subpackage, or the module itself at the package root."""
    parts = module.split(".")
    if (SRC.parent / Path(*parts) / "__init__.py").exists() or len(parts) > 2:
        return ".".join(parts[:2])
    return module


def _rank_allows(mine: str, theirs: str, me: str, target: str, top: bool) -> bool:
    """May package `mine` import `target` of package `theirs`? By rank, with the listed exceptions."""
    if mine in ROOT_ONLY and theirs in RANKS:
        return False
    if theirs in FORBIDDEN.get(mine, ()):
        return False
    if theirs not in RANKS:  # the root's vocabulary: anyone may import it
        return True
    if mine not in RANKS:  # a root module importing a stage package
        return me in ("gyrocal", "gyrocal.__main__") or any(me == a and target.startswith(b) for a, b in UPWARD)
    if RANKS[theirs] <= RANKS[mine]:
        return True
    return not top and any(me == a and (target == b or target.startswith(b + ".")) for a, b in UPWARD)


SOURCES = sorted(p for p in SRC.rglob("*.py"))


def _problems() -> list[str]:
    found = []
    for path in SOURCES:
        me = _module_name(path)
        mine = _component(me)
        for target, name, line, top in _imports(path):
            where = f"{path.relative_to(SRC.parent)}:{line}"
            theirs = _component(target)
            if not target.startswith("gyrocal"):
                if mine == "cli" and me.endswith(CMDS_SUFFIX) and top and target.split(".")[0] in (
                        "numpy", "scipy", "rich", "matplotlib", "pyarrow"):
                    found.append(f"{where}: command module imports {target} at module level (lazy imports only)")
                continue
            if theirs is not None and mine is not None and theirs != mine:
                if not _rank_allows(mine, theirs, me, target, top):
                    found.append(f"{where}: {mine} (rank {RANKS.get(mine)}) must not import {target} "
                                 f"(rank {RANKS.get(theirs)})")
            if theirs == "cli" and mine not in ("cli", "__main__"):
                found.append(f"{where}: the library must not import the command line ({target})")
            if target == "gyrocal" and name is not None and me != "gyrocal":
                found.append(f"{where}: import from the package root ({name}); import the defining module")
            parts = target.split(".")
            private_at = next((i for i, part in enumerate(parts) if i >= 2 and part.startswith("_")
                               and not part.startswith("__")), None)
            if private_at is not None:
                owner = ".".join(parts[:private_at])
                if not (me == owner or me.startswith(owner + ".")):
                    found.append(f"{where}: {target} is private to {owner}")
            if name is not None and name.startswith("_") and not name.startswith("__"):
                owner = _owner(target)
                if not (me == owner or me.startswith(owner + ".")):
                    found.append(f"{where}: {target}.{name} is private to {owner}")
            if mine == "cli" and me.endswith(CMDS_SUFFIX) and target.startswith("gyrocal.cli.") and \
                    target.endswith(CMDS_SUFFIX) and target != me:
                found.append(f"{where}: command modules never import each other ({target})")
            if mine == "cli" and me.endswith(CMDS_SUFFIX) and top and not target.startswith(LIGHT_FOR_CLI):
                found.append(f"{where}: command module imports {target} at module level (lazy imports only)")
    return found


def test_no_forbidden_import():
    problems = _problems()
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("bad, message", [
    ("from ..simulation import simulate\n", "thermal (rank 7) must not import gyrocal.simulation (rank 8)"),
    ("from ..results.calibration import Calibration\nfrom ..firmware.header import calibration_header\n",
     "must not import gyrocal.firmware.header"),
    ("from ..store import open_store\n", "thermal (rank 7) must not import gyrocal.store"),
    ("from ..models import _KG_ROWS\n", "gyrocal.models._KG_ROWS is private"),
    ("from ..segmentation._motion import static_level\n", "gyrocal.segmentation._motion is private"),
    ("from ..cli import app\n", "must not import the command line"),
])
def test_the_check_catches_what_it_forbids(tmp_path, monkeypatch, bad, message):
    """The checker itself, on a planted module inside gyrocal/thermal (removed afterwards)."""
    planted = SRC / "thermal" / "_planted_for_test.py"
    planted.write_text(bad)
    try:
        monkeypatch.setattr(sys.modules[__name__], "SOURCES", [planted])
        problems = _problems()
    finally:
        planted.unlink()
    assert any(message in p for p in problems), problems


def test_the_package_imports_without_the_store_extra():
    """gyrocal, gyrocal.store and the command line load no SQLAlchemy; with it blocked, opening a store says
    which extra to install in one line."""
    code = ("import sys\n"
            "import gyrocal, gyrocal.cli, gyrocal.store\n"
            "print(','.join(sorted(m for m in ('sqlalchemy', 'alembic', 'psycopg') if m in sys.modules)))\n"
            "sys.modules['sqlalchemy'] = None\n"
            "from gyrocal.errors import MissingDependencyError\n"
            "try:\n"
            "    gyrocal.store.open_store('never-created.db')\n"
            "except MissingDependencyError as exc:\n"
            "    print(exc)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True,
                         cwd=SRC.parent)
    loaded, message = out.stdout.splitlines()
    assert loaded == "" and message.startswith("the calibration store needs SQLAlchemy")
    assert "pip install 'gyrocal[store]'" in message


def test_the_command_line_starts_without_numpy():
    """Neither ``import gyrocal.cli`` nor ``gyrocal --help`` (which imports every command module for the
    commands' summaries) loads numpy or another heavy library."""
    code = ("import sys, gyrocal.cli; heavy = sorted(m for m in ('numpy', 'scipy', 'matplotlib', 'pyarrow', "
            "'pydantic') if m in sys.modules); print('imported:', ','.join(heavy)); gyrocal.cli.run(['--help']); "
            "heavy = sorted(m for m in ('numpy', 'scipy', 'matplotlib', 'pyarrow', 'pydantic') if m in sys.modules); "
            "print('helped:', ','.join(heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    lines = [line.strip() for line in out.stdout.strip().splitlines()]
    assert lines[0] == "imported:" and lines[-1] == "helped:", out.stdout
    assert "calibrate" in out.stdout


def test_the_bundled_example_calibrates_on_numpy_alone(tmp_path):
    """``calibrate --example`` loads none of scipy, pyarrow, matplotlib or numpy.ma: numpy's median,
    percentile and unique would import numpy.ma (a twentieth of the start), and gyrocal._arrays computes
    the same numbers without (tests/test_arrays_order.py checks them against numpy's)."""
    code = ("import sys, gyrocal.cli; gyrocal.cli.run(['calibrate', '--example', '-o', sys.argv[1]]); "
            "heavy = sorted(m for m in ('numpy.ma', 'scipy', 'matplotlib', 'pyarrow') if m in sys.modules); "
            "print('heavy:', ','.join(heavy))")
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "cal.json")], capture_output=True, text=True,
                         timeout=120, check=True)
    assert out.stdout.strip().splitlines()[-1] == "heavy:", out.stdout
    assert (tmp_path / "cal.json").exists()


def _import_graph(sources) -> dict[str, set[str]]:
    """gyrocal module -> the gyrocal modules it imports anywhere (module level or inside a function)."""
    names = {_module_name(p) for p in sources}
    graph: dict[str, set[str]] = {}
    for path in sources:
        me = _module_name(path)
        found = set()
        for module, _, _, _ in _imports(path):
            while module and module not in names:  # "from gyrocal.x import name": the module that holds it
                module = module.rpartition(".")[0]
            if module and module != me:
                found.add(module)
        graph[me] = found
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected groups of more than one module (Tarjan's algorithm, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                group = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    group.append(member)
                    if member == node:
                        break
                if len(group) > 1:
                    groups.append(sorted(group))
    return groups


def test_no_import_cycle_even_inside_functions():
    """Reference: the import statements themselves (ast), module level and inside functions alike; a package's
    __init__ importing its own modules is not a cycle unless a module imports the package back."""
    assert _cycles(_import_graph(SOURCES)) == []


def test_the_cycle_check_finds_one():
    """A ring of three modules is found, and a module outside it is not."""
    graph = {"gyrocal.a": {"gyrocal.b"}, "gyrocal.b": {"gyrocal.c"}, "gyrocal.c": {"gyrocal.a"}, "gyrocal.d": {"gyrocal.a"}}
    assert _cycles(graph) == [["gyrocal.a", "gyrocal.b", "gyrocal.c"]]


def test_no_cycle_between_packages():
    """Reference: the import statements (ast). Packages of one rank may import each other, but never in a ring;
    the listed exceptions of UPWARD are left out, as they are the only imports against the ranks."""
    graph: dict[str, set[str]] = {}
    for module, targets in _import_graph(SOURCES).items():
        mine = _component(module)
        for target in targets:
            theirs = _component(target)
            if mine and theirs and mine != theirs and not any(module == a and target.startswith(b) for a, b in UPWARD):
                graph.setdefault(f"gyrocal.{mine}", set()).add(f"gyrocal.{theirs}")
    for name in list(graph):
        for child in graph[name]:
            graph.setdefault(child, set())
    assert _cycles(graph) == []


def test_every_stage_package_has_a_rank_and_says_what_it_owns():
    """Every subpackage is placed in RANKS, and its docstring names its layer as RANKS does."""
    inits = sorted(SRC.glob("*/__init__.py"))
    assert [p.parent.name for p in inits if p.parent.name not in RANKS] == []
    wrong = [p.parent.name for p in inits
             if f"Layer {RANKS[p.parent.name]} (" not in (ast.get_docstring(ast.parse(p.read_text())) or "")]
    assert wrong == []
