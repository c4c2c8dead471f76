"""Loading a module of ``benches/`` (not a package) into the tests, reading the
Markdown tables the benches print and the docs quote, and what more than one test file
matches the docs against."""

from __future__ import annotations

import functools
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parents[1]
BENCHES = ROOT / "benches"
# The machine line's start of the Zen 4 VM of sessions 65 on, in `speed.py`'s runs and
# in `criterion_table.py --save`'s files alike.
ZEN4_MACHINE = "2 cores of AMD EPYC (family 25, model 17, stepping 1)"


def load_bench(name: str) -> ModuleType:
    """``benches/<name>.py`` as the module ``bench_<name>``, registered in
    :data:`sys.modules` before it runs (a dataclass looks its module up by name)."""
    spec = importlib.util.spec_from_file_location(f"bench_{name}", BENCHES / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


@functools.cache
def doc(path: str) -> str:
    """The text of the project's file at ``path`` (from the root: ``README.md``,
    ``BENCHMARK.md``, ``benches/SPEED_LOG.md``), read once for every test that quotes it."""
    return (ROOT / path).read_text(encoding="utf-8")


@functools.cache
def flat_doc(path: str) -> str:
    """:func:`doc`'s text of ``path`` as :func:`flat` gives it, worked out once."""
    return flat(doc(path))


def cells(line: str) -> list[str]:
    """The cells of one Markdown table row, stripped."""
    return [c.strip() for c in line.strip().strip("|").split("|")]


def flat(text: str) -> str:
    """``text`` with each run of white space one space, as a reader sees it."""
    return " ".join(text.split())


def listed(names: list[str]) -> str:
    """``names`` as the docs' prose lists them: "a", "a and b", "a, b and c"."""
    assert names, "nothing to list"
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]
