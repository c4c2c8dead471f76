"""``NdtGrid.match_many``: many scans in one call, each result bit for bit its own ``match``."""

from __future__ import annotations

import ast
import math
import os
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ndtgrid

from ._cpus import TWO_CPUS, needs_two_cpus
from ._results import exact
from ._room import scan

#: Poses in the room of ``_room.scan`` (the map's four and ten more).
MAP_POSES = [(0, 0, 0), (0.3, 0.2, 1.0), (-0.4, -0.3, 2.5), (0.5, -0.5, -1.8)]


def room_map() -> ndtgrid.NdtGrid:
    grid = ndtgrid.NdtGrid(0.02)
    for i, pose in enumerate(MAP_POSES):
        grid.insert(scan(pose, seed=i), pose)
    return grid


def batch(k: int, seed: int = 3) -> tuple[list[np.ndarray], np.ndarray]:
    """``k`` scans from random poses in the room, with guesses 1-4 cm and 0.6° off."""
    rng = np.random.default_rng(seed)
    truths = np.column_stack(
        [rng.uniform(-0.8, 0.8, k), rng.uniform(-0.6, 0.6, k), rng.uniform(-np.pi, np.pi, k)]
    )
    scans = [
        scan(t, beams=int(rng.integers(180, 700)), noise=0.005, seed=i)
        for i, t in enumerate(truths)
    ]
    offsets = np.column_stack(
        [rng.uniform(0.01, 0.04, k), -rng.uniform(0.01, 0.04, k), np.full(k, 0.01)]
    )
    return scans, truths + offsets


@pytest.mark.parametrize("threads", [None, 1, 2, 3])
@pytest.mark.parametrize(
    "options",
    [
        {},
        {"expansion_phases": [100.0, 10.0]},
        {**ndtgrid.presets.PAPER, "skip_levels": ()},
    ],
    ids=["default", "phases", "paper"],
)
def test_each_result_is_its_own_match(threads: int | None, options: dict[str, Any]) -> None:
    grid = room_map()
    scans, guesses = batch(17)
    want = [exact(grid.match(s, g, **options)) for s, g in zip(scans, guesses)]
    got = grid.match_many(scans, guesses, threads=threads, **options)
    assert [exact(r) for r in got] == want
    assert sum(r.converged for r in got) >= 15


def test_takes_every_keyword_of_match() -> None:
    """Every option of ``match`` (the core's defaults, written out) goes through, and the
    stub's option type lists exactly ``match``'s keywords."""
    grid = room_map()
    scans, guesses = batch(4)
    core = ndtgrid.default_match_options()
    got = grid.match_many(scans, guesses, **core)
    assert [exact(r) for r in got] == [exact(grid.match(s, g)) for s, g in zip(scans, guesses)]
    tree = ast.parse(Path(ndtgrid.__file__).with_name("_core.pyi").read_text())
    typed = next(c for c in tree.body if isinstance(c, ast.ClassDef) and c.name == "_MatchOptions")
    keys = {
        n.target.id
        for n in typed.body
        if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name)
    }
    assert keys == set(core)


def test_scans_as_one_3d_array_and_empty_batches() -> None:
    grid = room_map()
    pts = scan((0.1, 0.0, 0.2), seed=9)
    guesses = np.array([[0.12, -0.01, 0.21], [0.08, 0.01, 0.19]])
    stacked = grid.match_many(np.stack([pts, pts]), guesses)
    assert [exact(r) for r in stacked] == [exact(grid.match(pts, g)) for g in guesses]
    assert grid.match_many([], []) == []
    assert grid.match_many([], np.empty((0, 3)), threads=1) == []


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (
            lambda g, s, q: g.match_many(3, q),
            TypeError,
            "scans: expected a sequence of (N, 2) arrays, got int",
        ),
        (
            lambda g, s, q: g.match_many(s[0], q),
            TypeError,
            "scans: expected a sequence of (N, 2) arrays, got one array of shape (683, 2) "
            "(one scan: use match)",
        ),
        (
            lambda g, s, q: g.match_many(s, q[:2]),
            ValueError,
            "guesses: expected 3 poses (one per scan), got 2",
        ),
        (
            lambda g, s, q: g.match_many(s, q[:, :2]),
            ValueError,
            "guesses: expected an array of shape (K, 3), one [x, y, theta] per row, "
            "got shape (3, 2)",
        ),
        (
            lambda g, s, q: g.match_many([s[0], s[1][:, :1], s[2]], q),
            ValueError,
            "scan 1: points: expected an array of shape (N, 2), got shape (683, 1)",
        ),
        (
            lambda g, s, q: g.match_many([s[0], s[1], np.empty((0, 2))], q),
            ValueError,
            "scan 2: points: expected at least one point, got 0",
        ),
        (
            lambda g, s, q: g.match_many(
                [s[0], np.where(np.arange(683)[:, None] == 5, np.nan, s[1]), s[2]], q
            ),
            ValueError,
            "scan 1: points: expected finite values, got NaN at index 5",
        ),
        (
            lambda g, s, q: g.match_many(s, np.where(np.arange(3)[:, None] == 2, np.inf, q)),
            ValueError,
            "scan 2: guess: expected finite values, got inf at index 0",
        ),
        (
            lambda g, s, q: g.match_many(s, q, threads=0),
            ValueError,
            "threads: expected at least 1 thread (or None: every core), got 0",
        ),
        (
            lambda g, s, q: g.match_many(s, q, threads=-2),
            ValueError,
            "threads: expected a non-negative integer below 2**32, got -2",
        ),
        (
            lambda g, s, q: g.match_many(s, q, expansion=-1.0),
            ValueError,
            "expansion: expected a finite value > 0, got -1",
        ),
        (
            lambda g, s, q: g.match_many(s, q, expansion_phases=[]),
            ValueError,
            "expansion_phases: expected at least one expansion, got 0",
        ),
        (
            lambda g, s, q: g.match_many(s, q, levels=9),
            ValueError,
            "levels: expected between 1 and the grid's number of pyramid levels, got 9",
        ),
        (
            lambda g, s, q: g.match_many(s, q, expansoin=10.0),
            TypeError,
            "match_many() got an unexpected keyword argument 'expansoin'",
        ),
        (
            lambda g, s, q: g.match_many(s, q, search_radius="2"),
            TypeError,
            "argument 'search_radius': 'str' object cannot be interpreted as an integer",
        ),
    ],
)
def test_bad_input_is_refused_with_the_scan_named(
    call: Any, error: type[Exception], message: str
) -> None:
    grid = room_map()
    scans = [scan((0.1 * i, 0.0, 0.1), seed=i) for i in range(3)]
    guesses = np.array([[0.1 * i + 0.01, 0.0, 0.1] for i in range(3)])
    with pytest.raises(error) as info:
        call(grid, scans, guesses)
    assert str(info.value) == message


def long_batch(grid: ndtgrid.NdtGrid, seconds: float) -> tuple[list[np.ndarray], np.ndarray]:
    """Copies of ``batch(8)`` enough for a one-thread call of about ``seconds`` on this
    machine (timed once, with the distributions built first)."""
    scans, guesses = batch(8)
    grid.match_many(scans[:1], guesses[:1])  # distributions built
    t0 = time.perf_counter()
    grid.match_many(scans, guesses, threads=1)
    copies = max(1, math.ceil(seconds / (time.perf_counter() - t0)))
    return scans * copies, np.vstack([guesses] * copies)


def test_the_gil_is_free_while_it_runs() -> None:
    """A Python thread keeps counting while the batch runs on the calling thread."""
    grid = room_map()
    scans, guesses = long_batch(grid, 0.3)
    count = [0]
    stop = threading.Event()

    def counter() -> None:
        while not stop.is_set():
            count[0] += 1

    t = threading.Thread(target=counter)
    t.start()
    try:
        # The counter's pace on its own (this thread sleeping), then during the call.
        t0, before = time.perf_counter(), count[0]
        time.sleep(0.05)
        alone = (count[0] - before) / (time.perf_counter() - t0)
        t0, before = time.perf_counter(), count[0]
        grid.match_many(scans, guesses, threads=1)
        spent = time.perf_counter() - t0
        during = (count[0] - before) / spent
    finally:
        stop.set()
        t.join()
    # Held for the call, the GIL would let the counter run only for the switch interval
    # (5 ms) after the call: under a twentieth of its pace over a call this long.
    assert spent > 0.1
    assert during > 0.2 * alone, (during, alone)


def _thread_names() -> set[str]:
    """The names (``comm``) of this process's threads now (Linux)."""
    names = set()
    for tid in os.listdir("/proc/self/task"):
        try:
            with open(f"/proc/self/task/{tid}/comm") as f:
                names.add(f.read().strip())
        except OSError:  # the thread ended meanwhile
            pass
    return names


def _helpers_seen(call: Callable[[], object]) -> bool:
    """Whether a ``ndtgrid-match`` helper thread existed while ``call`` ran (a Python
    thread polls the thread list; the batch releases the GIL)."""
    seen = [False]
    stop = threading.Event()

    def poll() -> None:
        while not stop.is_set():
            seen[0] |= "ndtgrid-match" in _thread_names()

    t = threading.Thread(target=poll)
    t.start()
    try:
        call()
    finally:
        stop.set()
        t.join()
    return seen[0]


@needs_two_cpus
def test_threads_none_counts_the_cpus_of_the_calling_thread() -> None:
    """``threads=None`` starts helpers only where the calling thread has CPUs for them:
    from a thread pinned to one CPU (which a helper would inherit) the batch stays on
    it, also after unpinned calls (the count is not kept from the first call)."""
    grid = room_map()
    scans, guesses = long_batch(grid, 0.2)
    want = [exact(r) for r in grid.match_many(scans, guesses, threads=1)]
    # Unpinned: a helper, which the poller sees (so it would see one below).
    assert _helpers_seen(lambda: grid.match_many(scans, guesses))
    # A joined helper may still be listed for a moment: wait until it is gone, so the
    # poller below cannot see this call's helpers.
    deadline = time.monotonic() + 5.0
    while "ndtgrid-match" in _thread_names() and time.monotonic() < deadline:
        time.sleep(0.001)
    assert "ndtgrid-match" not in _thread_names()
    got: list[list[Any]] = []

    def pinned() -> None:
        assert TWO_CPUS is not None
        os.sched_setaffinity(0, {TWO_CPUS[0]})
        got.append([exact(r) for r in grid.match_many(scans, guesses)])

    def run_pinned() -> None:
        t = threading.Thread(target=pinned)
        t.start()
        t.join()

    assert not _helpers_seen(run_pinned)
    assert got == [want]


_PARALLEL_POOL_SCRIPT = """
import os, threading, time, numpy as np, ndtgrid
grid = ndtgrid.NdtGrid(0.02)
rng = np.random.default_rng(0)
t = rng.uniform(0, 2 * np.pi, 20000)
points = np.column_stack([2 * np.cos(t), 2 * np.sin(t)]) + rng.normal(0, 0.003, (20000, 2))
grid.insert(points, np.zeros(3))
cpu = int(os.environ["NDT_TEST_CPU"]) if os.environ["NDT_TEST_CPU"] else None
before = set(os.listdir("/proc/self/task"))
caller = []
def first_parallel_match():
    caller.append(str(threading.get_native_id()))
    if cpu is not None:
        os.sched_setaffinity(0, {cpu})
    grid.match(points, np.array([0.01, 0.0, 0.0]), parallel=True)
th = threading.Thread(target=first_parallel_match)
th.start()
th.join()
# The calling thread itself may still be listed for a moment after join() returns, and
# a new thread may show in /proc a moment late (seen on Python 3.12 in 1 run of 100):
# wait up to 5 s for as many as expected, then report what is there.
expected, deadline = int(os.environ["NDT_TEST_EXPECT"]), time.monotonic() + 5.0
while True:
    pool = set(os.listdir("/proc/self/task")) - before - set(caller)
    if len(pool) >= expected or time.monotonic() > deadline:
        break
    time.sleep(0.01)
print(sorted(sorted(os.sched_getaffinity(int(tid))) for tid in pool))
"""


@needs_two_cpus
def test_the_parallel_option_pool_takes_the_first_callers_cpus() -> None:
    """As the docs of ``parallel`` say: rayon's pool, started by the first parallel
    match, has one thread per CPU of the thread that made it, on those CPUs (in a
    child process: the pool is the process's)."""
    assert TWO_CPUS is not None
    allowed = sorted(os.sched_getaffinity(0))

    def pool(cpu: int | None) -> list[list[int]]:
        env = {k: v for k, v in os.environ.items() if k != "RAYON_NUM_THREADS"}
        env["NDT_TEST_CPU"] = "" if cpu is None else str(cpu)
        env["NDT_TEST_EXPECT"] = str(len(allowed) if cpu is None else 1)
        out = subprocess.run(
            [sys.executable, "-c", _PARALLEL_POOL_SCRIPT],
            env=env,
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        pools: list[list[int]] = ast.literal_eval(out.strip())
        return pools

    assert pool(TWO_CPUS[0]) == [[TWO_CPUS[0]]]
    assert pool(None) == [allowed] * len(allowed)
