"""``benches/speed.py --json``: every section's results as strict JSON, the thread
section's run by run, agreeing with what the run prints."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ._benches import BENCHES, cells, load_bench
from ._data import require_real

speed = load_bench("speed")


def test_json_ready_gives_what_strict_json_holds() -> None:
    value = {
        1: (np.float64(0.5), np.int64(3), math.nan),
        "row": {"seconds": math.inf, "poses": np.array([[1.0, 2.0]])},
        "flags": [True, None, np.bool_(False)],
        "text": "x",
    }
    assert speed.json_ready(value) == {
        "1": [0.5, 3, None],
        "row": {"seconds": None, "poses": [[1.0, 2.0]]},
        "flags": [True, None, False],
        "text": "x",
    }
    # NumPy's scalars come back as Python's, so json needs no default.
    assert type(speed.json_ready(np.float32(0.25))) is float
    json.dumps(speed.json_ready(value), allow_nan=False)


def test_the_thread_section_as_json(tmp_path: Path) -> None:
    require_real("radish-gfs-corrected/intel-corrected.log.gz")
    path = tmp_path / "out" / "speed.json"
    proc = subprocess.run(
        [
            *(sys.executable, str(BENCHES / "speed.py")),
            *("--quick", "--sections", "threads", "--json", str(path)),
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    data = json.loads(path.read_text())
    assert "commit" in data["machine"]
    assert data["argv"][-2:] == ["--json", str(path)]
    assert data["complete"] is True
    assert not path.with_name(path.name + ".part").exists()
    assert list(data["sections"]) == ["threads"]
    t = data["sections"]["threads"]
    # --quick: three one- and two-thread runs, each with its ratio, start and CPUs.
    runs = len(t["late_s"])
    assert runs == 3
    assert set(t["per_run"]) == {
        *("unpinned", "pinned", "bundles", "many", "steady"),
        *("bundles_share", "bundles_cost", "pinned_share", "pinned_cost"),
    }
    for key in ("unpinned", "bundles", "many", "bundles_share", "bundles_cost"):
        assert len(t["per_run"][key]) == runs
    # The bundles' rounds apart: CPU over wall of two threads (at most 2 and a little for
    # the clocks), their CPU time over one thread's, and the seconds stolen meanwhile;
    # the printed section lists the same numbers.
    assert all(0.0 < x <= 2.05 for x in t["per_run"]["bundles_share"])
    assert all(x > 0.0 for x in t["per_run"]["bundles_cost"])
    assert len(t["bundles_steal_s"]) == runs
    assert all(x is None or x >= 0.0 for x in t["bundles_steal_s"])
    shares = ", ".join(f"{x:.2f}" for x in t["per_run"]["bundles_share"])
    costs = ", ".join(f"{x:.2f}" for x in t["per_run"]["bundles_cost"])
    assert f"Per run, the two threads' CPU / wall: {shares}; their CPU time over one " in (
        proc.stdout
    )
    assert f"as fast as one thread alone): {costs}. Time stolen" in proc.stdout
    # --quick: two rounds of threads that keep matching for 0.2 s.
    assert len(t["per_run"]["steady"]) == 2
    assert t["steady_seconds"] == 0.2
    # Pinned workers need two CPUs; without them their ratio is NaN, null in the JSON.
    pinned = t["pinned_ratio"] is not None
    for key in ("pinned", "pinned_share", "pinned_cost"):
        assert len(t["per_run"][key]) == (runs if pinned else 0)
    assert len(t["one_cpu_first"]) == len(t["one_cpu_half"]) == runs
    assert t["late_runs"] == sum(x >= speed.LATE_START for x in t["late_s"])
    # The printed targets row says what the JSON holds.
    times = "\N{MULTIPLICATION SIGN}"
    row = re.search(
        rf"\| two threads ≥ 1\.7{times} one \(threads started[^|]*\| ([\d.]+){times}", proc.stdout
    )
    assert row is not None
    assert row.group(1) == f"{t['ratio']:.2f}"
    assert f"late in {t['late_runs']} of {runs} runs)" in proc.stdout
    steady = re.search(
        rf"\| two threads ≥ 1\.7{times} one, threads that keep matching \(0\.2 s rounds, "
        rf"placed by the kernel\) \| ([\d.]+){times} \(best rounds ([\d.]+){times}\)",
        proc.stdout,
    )
    assert steady is not None
    assert steady.groups() == (f"{t['steady_ratio']:.2f}", f"{t['steady_ratio_best']:.2f}")
    assert f"Results as JSON: `{path}`." in proc.stdout
    # benches/speed_runs.py tables the document: the threads row judges what it holds.
    speed_runs = load_bench("speed_runs")
    lines = speed_runs.run_tables([speed_runs.read_run(path)], columns=8)
    (started,) = [line for line in lines if "started for each run" in line]
    shown = cells(started)
    assert shown[1].endswith(f"({t['control']:.2f}; {t['bundle_ratio']:.2f})")
    assert shown[2] == ("1 of 1" if t["ratio"] >= 1.7 else "0 of 1")


def test_a_run_stopped_part_way_keeps_the_sections_it_ran(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The JSON is written after each section, marked incomplete until the end."""
    path = tmp_path / "speed.json"

    def fails(args: object) -> dict[str, object]:
        raise RuntimeError("insert section failed")

    monkeypatch.setattr(speed, "section_match", lambda args: {"median_ms": np.float64(0.1)})
    monkeypatch.setattr(speed, "section_insert", fails)
    monkeypatch.setattr(
        sys, "argv", ["speed.py", "--quick", "--sections", "match", "insert", "--json", str(path)]
    )
    with pytest.raises(RuntimeError, match=r"^insert section failed$"):
        speed.main()
    data = json.loads(path.read_text())
    assert data["complete"] is False
    assert data["sections"] == {"match": {"median_ms": 0.1}}
    assert data["argv"][-1] == str(path)


def test_a_failed_write_leaves_the_last_document_and_no_part_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A write that fails half-way removes its ``.part`` file; the JSON at the path is
    still the last whole document."""
    path = tmp_path / "speed.json"
    part = path.with_name(path.name + ".part")
    speed.write_json(path, "machine A", {"match": {"ours": 0.1}}, complete=False)
    first = path.read_text()

    def full_disk(self: Path, target: Path) -> Path:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Path, "replace", full_disk)
    with pytest.raises(OSError, match=r"No space left on device$"):
        speed.write_json(
            path, "machine A", {"match": {"ours": 0.1}, "insert": {"ours": 4e-5}}, complete=True
        )
    assert not part.exists()
    assert path.read_text() == first
    assert json.loads(first)["sections"] == {"match": {"ours": 0.1}}


def test_a_failed_write_reports_its_own_error_when_the_cleanup_fails_too(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """If the part file cannot be removed either, the write's error is the one raised."""
    path = tmp_path / "speed.json"

    def full_disk(self: Path, target: Path) -> Path:
        raise OSError(28, "No space left on device")

    def denied(self: Path, missing_ok: bool = False) -> None:
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(Path, "replace", full_disk)
    monkeypatch.setattr(Path, "unlink", denied)
    with pytest.raises(OSError, match=r"No space left on device$") as info:
        speed.write_json(path, "machine A", {}, complete=False)
    assert not isinstance(info.value, PermissionError)
