"""The README's runnable example and the command line's entry points."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import ndtgrid

ROOT = Path(__file__).resolve().parents[1]


def test_quickstart_recovers_the_pose() -> None:
    out = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "quickstart.py")],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    assert "converged=True" in out
    m = re.search(r"error \[mm, deg\]: (\S+) (\S+)", out)
    assert m is not None, out
    assert float(m.group(1)) < 1.0
    assert abs(float(m.group(2))) < 0.05


def test_version_from_the_command_line() -> None:
    out = subprocess.run(
        [sys.executable, "-m", "ndtgrid", "--version"], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip() == f"ndtgrid {ndtgrid.__version__}"
