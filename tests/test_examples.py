"""The runnable examples and the command line's entry points."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import ndtgrid

ROOT = Path(__file__).resolve().parents[1]


def run_example(name: str) -> str:
    """The standard output of ``examples/<name>``, run as a user would."""
    return subprocess.run(
        [sys.executable, str(ROOT / "examples" / name)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout


def test_quickstart_recovers_the_pose() -> None:
    out = run_example("quickstart.py")
    assert "converged=True" in out
    m = re.search(r"error \[mm, deg\]: (\S+) (\S+)", out)
    assert m is not None, out
    assert float(m.group(1)) < 1.0
    assert abs(float(m.group(2))) < 0.05


def test_threads_example_pins_its_workers_and_matches_alike() -> None:
    out = run_example("threads.py")
    assert "same poses: True" in out, out
    m = re.search(r"worker CPUs: (\[.*\])", out)
    assert m is not None, out
    cpus = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    if len(cpus) >= 2:
        assert m.group(1) == f"[[{cpus[0]}], [{cpus[1]}]]"
    else:
        assert m.group(1) == "[]"
    assert re.search(r"one thread: \d+ matches/s", out), out
    assert re.search(r"one match_many call: \d+ matches/s", out), out


def test_version_from_the_command_line() -> None:
    out = subprocess.run(
        [sys.executable, "-m", "ndtgrid", "--version"], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip() == f"ndtgrid {ndtgrid.__version__}"


def test_demo_maps_the_simulated_room(tmp_path: Path, capsys: object) -> None:
    from ndtgrid.cli import main

    assert main(["demo", "--out", str(tmp_path), "--quiet"]) == 0
    out = capsys.readouterr().out  # type: ignore[attr-defined]
    for name in ("map.png", "map.pgm", "map.yaml", "trajectory.tum", "map.ndtgrid"):
        assert (tmp_path / name).stat().st_size > 0, name
    m = re.search(
        r"pose error against the truth: (\S+) cm RMS, (\S+) cm max "
        r"\(odometry alone: (\S+) cm max\); (\d+) small objects",
        out,
    )
    assert m is not None, out
    rms, worst, odometry = (float(m.group(i)) for i in (1, 2, 3))
    assert rms < 1.0 and worst < 2.0 and worst < odometry / 3
    assert int(m.group(4)) >= 8


def test_demo_shows_progress_while_simulating_and_mapping(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from ndtgrid import sim
    from ndtgrid.cli import main

    monkeypatch.setitem(sys.modules, "tqdm", None)  # the plain counter: predictable text
    assert main(["demo", "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    n = len(sim.trajectory(sim.sticks_room().tour, step=0.05))
    assert f"\rsimulating: {n} scans\n" in err
    assert f"\rmapping: {n} scans\n" in err
    assert err.index("simulating") < err.index("mapping")
