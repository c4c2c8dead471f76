"""The type stubs of the compiled core (``_core.pyi``) against the core, and as a
typed user's code sees them."""

from __future__ import annotations

import ast
import inspect
import re
import subprocess
import sys
from pathlib import Path

import pytest

from ndtgrid import _core

STUB = Path(_core.__file__).with_name("_core.pyi")

#: The oldest Python that mypy 2 checks for; the package supports 3.9.
OLDEST = "3.10"

GOOD = """\
import numpy as np
import numpy.typing as npt

import ndtgrid

grid = ndtgrid.NdtGrid(0.02, levels=5)
scan: npt.NDArray[np.float64] = np.zeros((10, 2))
grid.insert(scan, [0.0, 0.0, 0.0])
grid.insert_many([scan, scan], [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
grid.insert_many(np.zeros((2, 10, 2)), np.zeros((2, 3)))
result = grid.match(scan, (0.0, 0.0, 0.0), skip_levels=None, levels=3)
pose: npt.NDArray[np.float64] = result.pose
converged: bool = result.converged
many: list[ndtgrid.MatchResult] = grid.match_many(
    np.zeros((2, 10, 2)), np.zeros((2, 3)), expansion=5.0
)
mapper = ndtgrid.Mapper(0.02, outlier_filter=False)
odometry = ndtgrid.Odometry()
"""

#: Each line that mypy must reject, with the error code it must give.
BAD = {
    "grid.match_many([np.zeros((3, 2))], [[0.0, 0.0, 0.0]], expanson=5.0)": "call-arg",
    'grid.match_many([np.zeros((3, 2))], [[0.0, 0.0, 0.0]], expansion="5")': "arg-type",
    "class Mine(ndtgrid.NdtGrid): pass": "misc",
}


def documented() -> list[tuple[str, object, str]]:
    """Every class, method and function the stubs give a docstring: its name, the
    compiled object and the docstring."""
    out: list[tuple[str, object, str]] = []
    for node in ast.parse(STUB.read_text()).body:
        if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            cls = getattr(_core, node.name)
            out.append((node.name, cls, ast.get_docstring(node) or ""))
            out += [
                (f"{node.name}.{m.name}", getattr(cls, m.name), ast.get_docstring(m) or "")
                for m in node.body
                if isinstance(m, ast.FunctionDef)
                and ast.get_docstring(m)
                # Slots (``len()``) keep Python's own docstrings.
                and m.name not in ("__len__",)
            ]
        elif isinstance(node, ast.FunctionDef) and ast.get_docstring(node):
            out.append((node.name, getattr(_core, node.name), ast.get_docstring(node) or ""))
    return out


def test_help_shows_the_stubs_docstrings() -> None:
    """``help()`` and ``?`` show the compiled objects' docstrings: each is the one
    the stubs give (the build copies them), not a shorter text of the binding's."""
    items = documented()
    assert len(items) >= 60
    for name, obj, doc in items:
        assert inspect.cleandoc(obj.__doc__ or "") == doc, name


def test_stubs_match_the_compiled_core() -> None:
    """``mypy.stubtest``: every name, parameter and default of ``_core.pyi`` is the
    compiled module's (what ``help()`` shows), and every public name of the module
    is in the stubs."""
    pytest.importorskip("mypy", reason="mypy (the test extra) checks the stubs")
    r = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "ndtgrid._core"],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stdout + r.stderr


def test_typed_code_checks_as_the_core_runs(tmp_path: Path) -> None:
    """A user's code checked with ``mypy --strict`` on the oldest Python mypy checks:
    calls the core accepts pass (a (K, N, 2) array of scans too), and a misspelt
    option, a wrong option type and a subclass of a class the core cannot subclass
    are errors."""
    pytest.importorskip("mypy", reason="mypy (the test extra) checks the stubs")
    good = tmp_path / "good.py"
    good.write_text(GOOD)
    bad = tmp_path / "bad.py"
    header = "import numpy as np\n\nimport ndtgrid\n\ngrid = ndtgrid.NdtGrid(0.02)\n"
    bad.write_text(header + "".join(f"{line}\n" for line in BAD))
    command = ["mypy", "--strict", "--no-incremental", "--python-version", OLDEST]
    r = subprocess.run(
        [sys.executable, "-m", *command, "good.py", "bad.py"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    errors = re.findall(r"^(\w+)\.py:(\d+): error: .*\[([\w-]+)\]$", r.stdout, re.M)
    first = header.count("\n") + 1
    expected = [("bad", str(first + i), code) for i, code in enumerate(BAD.values())]
    assert errors == expected, r.stdout + r.stderr
