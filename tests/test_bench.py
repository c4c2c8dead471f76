"""``ndtgrid bench`` (:mod:`ndtgrid.bench`): what it times is checked work, its report and
its command line.

No time is asserted here (speed targets live in ``benches/``); what is asserted is that
the run did the work it reports: every match recovered its pose, the odometry followed
the truth, the map is the one the scans make, and the numbers are consistent."""

from __future__ import annotations

import json
import os
import platform
import threading
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ndtgrid import NdtGrid, bench, ranges_to_points, sim
from ndtgrid._core import vector_extension
from ndtgrid._progress import progress
from ndtgrid.cli import main

from ._cpus import TWO_CPUS, needs_two_cpus

SCANS = 40


@pytest.fixture(scope="module")
def report() -> bench.BenchReport:
    return bench.run_bench(SCANS, seed=2, repeats=3)


def test_every_match_recovers_its_pose_and_the_odometry_follows_the_truth(
    report: bench.BenchReport,
) -> None:
    assert report.scans == SCANS
    assert report.matches_recovered == SCANS
    rows = {r.name: r for r in report.rows}
    assert rows["match"].note == f"{SCANS} of {SCANS} within 1 cm and 0.2° of the truth"
    # 40 scans at 2 cm drive 0.8 m with 2 % odometry drift; matching keeps well under it.
    assert 0.0 <= report.odometry_rms_error < 0.005
    assert report.match_many_speedup > 0.0 and report.python_threads_speedup > 0.0


def test_rows_are_the_timed_operations_with_consistent_numbers(
    report: bench.BenchReport,
) -> None:
    names = [r.name for r in report.rows]
    assert names == [
        "insert",
        f"insert_many, batches of {bench.INSERT_BATCH}",
        "match",
        "match_many, one thread",
        "match_many, every core",
        "match, 1 Python thread",
        "match, 2 Python threads",
        *([bench.PINNED_ROW] if TWO_CPUS is not None else []),
        "odometry step",
    ]
    calls = {r.name: r.calls for r in report.rows}
    assert calls["insert"] == SCANS - bench.UNTIMED_INSERTS
    assert calls[names[1]] == -(-SCANS // bench.INSERT_BATCH)
    assert all(calls[n] == SCANS for n in names[2:])
    batches = {n for n in names if n.startswith("match_many") or "Python" in n}
    for r in report.rows:
        assert r.median > 0.0, r.name
        if r.name in batches:
            assert r.p90 is None, r.name
        else:
            assert r.p90 is not None and r.p90 >= r.median, r.name
    rows = {r.name: r for r in report.rows}
    pairs: list[tuple[str, str, float | None]] = [
        ("match_many, one thread", "match_many, every core", report.match_many_speedup),
        ("match, 1 Python thread", "match, 2 Python threads", report.python_threads_speedup),
    ]
    if TWO_CPUS is not None:
        pairs.append(("match, 1 Python thread", bench.PINNED_ROW, report.pinned_threads_speedup))
    else:
        assert report.pinned_threads_speedup is None
    for first, other, speedup in pairs:
        assert speedup is not None
        assert speedup == pytest.approx(rows[first].median / rows[other].median)
        rate = float(rows[first].note.removesuffix(" scans / s, median of 3 runs"))
        assert rate == pytest.approx(1e3 / rows[first].median, abs=0.5)
        label = first.split(", ")[1]
        lo, hi = map(float, rows[other].note.split("(")[1].removesuffix(" by round)").split(" to "))
        assert lo <= hi
        assert f"; {speedup:.2f} x {label} (" in rows[other].note


def test_the_batched_map_is_checked_against_the_inserts(report: bench.BenchReport) -> None:
    rows = {r.name: r for r in report.rows}
    assert rows[f"insert_many, batches of {bench.INSERT_BATCH}"].note == (
        "per scan, one call per batch; the map equals insert's, bit for bit"
    )


def test_the_map_is_the_one_the_scans_make(report: bench.BenchReport) -> None:
    room = sim.sticks_room()
    truth = sim.trajectory(room.tour)[:SCANS]
    ranges, angles = sim.simulate(room, sim.URG04LX, truth, seed=2)
    grid = NdtGrid(bench.CELL_SIZE)
    points = [ranges_to_points(r, angles) for r in ranges]
    for i, (p, pose) in enumerate(zip(points, truth)):
        if i > 0:
            grid.match(p, pose)  # as the bench: distributions prepared before each insert
        grid.insert(p, pose)
    assert report.map_cells == len(grid)
    assert report.map_bytes_per_cell == pytest.approx(grid.memory_bytes / len(grid))
    assert report.points == int(np.median([len(p) for p in points]))


# Two processors of a VM as /proc/cpuinfo gives them (trimmed): the first one is read.
EPYC_CPUINFO = """processor\t: 0
vendor_id\t: AuthenticAMD
cpu family\t: 25
model\t\t: 17
model name\t: AMD EPYC
stepping\t: 1
flags\t\t: fpu sse2 avx avx2 fma avx512f avx512dq avx512vl

processor\t: 1
vendor_id\t: AuthenticAMD
cpu family\t: 26
model\t\t: 2
model name\t: AMD EPYC 9005
stepping\t: 0
flags\t\t: fpu sse2
"""


def test_the_processor_is_named_with_its_identifiers() -> None:
    assert bench.processor_name(EPYC_CPUINFO) == "AMD EPYC (family 25, model 17, stepping 1)"
    xeon = "model name\t: Intel(R) Xeon(R) Processor\nflags\t: fpu avx avx2 fma\n"
    assert bench.processor_name(xeon) == "Intel(R) Xeon(R) Processor"
    # A Raspberry Pi 5's Cortex-A76 (trimmed): no model name, ARM's identifiers.
    pi5 = (
        "processor\t: 0\nBogoMIPS\t: 108.00\nFeatures\t: fp asimd evtstrm aes crc32\n"
        "CPU implementer\t: 0x41\nCPU architecture: 8\nCPU variant\t: 0x4\n"
        "CPU part\t: 0xd0b\nCPU revision\t: 1\n"
    )
    fallback = platform.processor() or platform.machine()
    assert bench.processor_name(pi5) == (
        f"{fallback} (implementer 0x41, part 0xd0b, variant 0x4, revision 1)"
    )
    # Without the file's text the name falls back to the platform's.
    assert bench.processor_name("") == fallback
    # Read from the file, where there is one, the name is that file's.
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.exists():
        assert bench.processor_name() == bench.processor_name(cpuinfo.read_text())


def test_the_kernels_named_are_those_the_core_runs_and_the_flags_allow() -> None:
    name = bench.kernels_name()
    assert name in {"AVX-512 kernels", "AVX2 kernels", "NEON kernels", "generic kernels"}
    assert name == f"{vector_extension() or 'generic'} kernels"
    # On Linux the processor's flags say which build it can run (the kernels'
    # targets: AVX-512 needs F, DQ and VL with AVX2 and FMA; AVX2 needs FMA).
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.exists() and platform.machine() == "x86_64":
        text = cpuinfo.read_text()
        flags = set(next(ln for ln in text.splitlines() if ln.startswith("flags")).split())
        if {"avx512f", "avx512dq", "avx512vl", "avx2", "fma"} <= flags:
            assert name == "AVX-512 kernels"
        elif {"avx2", "fma"} <= flags:
            assert name == "AVX2 kernels"
        else:
            assert name == "generic kernels"


def test_report_as_json_and_table(report: bench.BenchReport) -> None:
    data = json.loads(json.dumps(report.as_dict()))
    assert data["scans"] == SCANS and len(data["rows"]) == len(report.rows)
    assert data["rows"][2]["name"] == "match"
    assert data["match_many_speedup"] == report.match_many_speedup
    assert data["python_threads_speedup"] == report.python_threads_speedup
    assert data["pinned_threads_speedup"] == report.pinned_threads_speedup
    assert set(data["machine"]) == {
        "processor",
        "kernels",
        "cores",
        "python",
        "ndtgrid",
        "platform",
    }
    assert data["machine"]["processor"] == bench.processor_name()
    assert data["machine"]["kernels"] == bench.kernels_name()
    table = report.table().splitlines()
    m = report.machine
    assert table[0].startswith(
        f"ndtgrid {m['ndtgrid']} on {m['cores']} cores of {m['processor']}, {m['kernels']}, Python "
    )
    assert f"{SCANS} simulated URG-04LX scans" in table[0]
    assert table[2] == "| operation | median | p90 | calls | checked |"
    assert len(table) == 4 + len(report.rows)
    assert table[7].startswith("| match_many, one thread | ") and " | - | " in table[7]
    assert table[9].startswith("| match, 1 Python thread | ")


def test_no_pinned_row_where_threads_cannot_be_pinned(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(bench, "pinnable_cpus", lambda n: None)
    report = bench.run_bench(bench.MIN_SCANS, repeats=1)
    names = [r.name for r in report.rows]
    assert "match, 2 Python threads" in names and bench.PINNED_ROW not in names
    assert report.pinned_threads_speedup is None
    assert json.loads(json.dumps(report.as_dict()))["pinned_threads_speedup"] is None


def test_pinnable_cpus_are_allowed_ones() -> None:
    if not hasattr(os, "sched_setaffinity"):
        assert bench.pinnable_cpus(1) is None
        return
    allowed = sorted(os.sched_getaffinity(0))
    assert bench.pinnable_cpus(1) == allowed[:1]
    assert bench.pinnable_cpus(len(allowed)) == allowed
    assert bench.pinnable_cpus(len(allowed) + 1) is None


class _Recorder:
    """Stands in for the grid: records each calling thread's CPUs and the scans it took."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.calls: list[tuple[int, frozenset[int], int]] = []

    def match(self, points: Any, guess: Any) -> None:
        with self.lock:
            self.calls.append(
                (threading.get_ident(), frozenset(os.sched_getaffinity(0)), int(points))
            )


@needs_two_cpus
def test_pinned_threads_each_run_on_their_own_cpu_and_split_the_scans() -> None:
    assert TWO_CPUS is not None
    before = os.sched_getaffinity(0)
    grid = _Recorder()
    points = list(range(9))
    ns = bench._threads_ns(grid, points, np.zeros((9, 3)), 2, TWO_CPUS)  # type: ignore[arg-type]
    assert ns > 0
    by_thread: dict[int, list[tuple[frozenset[int], int]]] = {}
    for ident, cpus, scan in grid.calls:
        by_thread.setdefault(ident, []).append((cpus, scan))
    got = sorted(
        (sorted(scan for _, scan in calls), {c for c, _ in calls}) for calls in by_thread.values()
    )
    assert got == [
        ([0, 2, 4, 6, 8], {frozenset({TWO_CPUS[0]})}),
        ([1, 3, 5, 7], {frozenset({TWO_CPUS[1]})}),
    ]
    assert os.sched_getaffinity(0) == before  # the caller is not pinned


def test_a_thread_that_cannot_be_pinned_fails_the_run_and_leaves_no_thread() -> None:
    if not hasattr(os, "sched_setaffinity"):
        pytest.skip("needs os.sched_setaffinity")
    bad = max(os.sched_getaffinity(0)) + 4096
    threads = threading.active_count()
    grid = _Recorder()
    with pytest.raises(RuntimeError, match=rf"^could not pin a thread to CPU {bad}: "):
        bench._threads_ns(grid, [0, 1], np.zeros((2, 3)), 1, [bad])  # type: ignore[arg-type]
    assert grid.calls == []
    assert threading.active_count() == threads


def test_cli_bench_reports_a_thread_it_cannot_pin(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    if not hasattr(os, "sched_setaffinity"):
        pytest.skip("needs os.sched_setaffinity")
    bad = max(os.sched_getaffinity(0)) + 4096
    monkeypatch.setattr(bench, "pinnable_cpus", lambda n: [bad] * n)
    assert main(["bench", "--scans", "20", "--quiet", "--repeats", "1"]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith(f"ndtgrid bench: could not pin a thread to CPU {bad}: ")
    assert captured.err.count("\n") == 1


def test_progress_wraps_the_simulation_with_its_total() -> None:
    seen: list[tuple[str, int, int]] = []

    def spy(items: Iterable[Any], label: str, total: int) -> Iterator[Any]:
        got = list(items)
        yield from got
        seen.append((label, total, len(got)))

    rep = bench.run_bench(bench.MIN_SCANS, progress=spy)
    assert seen == [("simulating", bench.MIN_SCANS, bench.MIN_SCANS)]
    assert rep.matches_recovered == bench.MIN_SCANS


@pytest.mark.parametrize("bad", [bench.MIN_SCANS - 1, 0, -5, 10_000, 25.0, True, "30"])
def test_scans_out_of_range_are_refused(bad: object) -> None:
    most = bench.max_scans()
    with pytest.raises(ValueError) as info:
        bench.run_bench(bad)  # type: ignore[arg-type]
    assert str(info.value) == (
        f"scans: expected an integer from {bench.MIN_SCANS} to {most} (the simulated "
        f"tour's poses), got {bad!r}"
    )


@pytest.mark.parametrize("bad", [0, -1, 2.0, True, None])
def test_repeats_below_one_are_refused(bad: object) -> None:
    with pytest.raises(ValueError) as info:
        bench.run_bench(SCANS, repeats=bad)  # type: ignore[arg-type]
    assert str(info.value) == f"repeats: expected an integer >= 1, got {bad!r}"


def test_max_scans_is_the_whole_tour() -> None:
    assert bench.max_scans() == len(sim.trajectory(sim.sticks_room().tour))


def test_cli_bench_table_json_and_errors(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bench", "--scans", "20", "--quiet"]) == 0
    captured = capsys.readouterr()
    assert captured.err == ""
    lines = captured.out.splitlines()
    assert "20 simulated URG-04LX scans" in lines[0]
    assert any(line.startswith("| match | ") for line in lines)
    assert main(["bench", "--scans", "20", "--quiet", "--json", "--seed", "1"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["scans"] == 20 and data["matches_recovered"] == 20
    assert main(["bench", "--scans", "5"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (
        f"ndtgrid bench: scans: expected an integer from {bench.MIN_SCANS} to "
        f"{bench.max_scans()} (the simulated tour's poses), got 5\n"
    )


def test_plain_progress_counter_without_tqdm(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm now fails
    assert list(progress(range(1001), False, "mapping")) == list(range(1001))
    err = capsys.readouterr().err
    assert "\rmapping: 500 scans (" in err and "\rmapping: 1000 scans (" in err
    assert err.endswith("\rmapping: 1001 scans\n")
    assert list(progress(range(3), True, "mapping")) == [0, 1, 2]
    assert capsys.readouterr().err == ""


def test_scan_ranges_are_simulates_rows() -> None:
    room = sim.sticks_room()
    poses = sim.trajectory(room.tour)[100:130]
    ranges, _ = sim.simulate(room, sim.URG04LX, poses, seed=5)
    one_by_one = list(sim.scan_ranges(room, sim.URG04LX, poses, seed=5))
    assert len(one_by_one) == len(poses)
    np.testing.assert_array_equal(np.array(one_by_one), ranges)
