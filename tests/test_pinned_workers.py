"""The pinned worker threads of ``benches/pinned.py`` (the thread section of
``benches/speed.py`` judges two of them against one)."""

from __future__ import annotations

import os
import threading

import numpy as np
import pytest

import ndtgrid

from ._benches import load_bench

pinned = load_bench("pinned")
CPUS = pinned.two_cpus()
needs_two = pytest.mark.skipif(CPUS is None, reason="needs os.sched_setaffinity and two CPUs")


def test_two_cpus_are_allowed_ones() -> None:
    if not hasattr(os, "sched_getaffinity"):
        assert pinned.two_cpus() is None
        return
    allowed = sorted(os.sched_getaffinity(0))
    assert pinned.two_cpus() == (allowed[:2] if len(allowed) >= 2 else None)


@needs_two
def test_each_worker_runs_on_its_own_cpu_only() -> None:
    seen: list[tuple[int, set[int]]] = []
    lock = threading.Lock()

    def task(i: int) -> None:
        with lock:
            seen.append((i, os.sched_getaffinity(0)))

    with pinned.PinnedWorkers(CPUS) as workers:
        for _ in range(3):
            workers.run([lambda: task(0), lambda: task(1)])
        workers.run([None, lambda: task(1)])
    assert sorted(i for i, _ in seen) == [0, 0, 0, 1, 1, 1, 1]
    for i, mask in seen:
        assert mask == {CPUS[i]}
    # The caller's own affinity is untouched.
    assert len(os.sched_getaffinity(0)) >= 2


#: ``current_cpu``'s two readers: glibc's ``sched_getcpu``, and ``/proc`` without it.
READERS = pytest.mark.parametrize("reader", ["sched_getcpu", "proc"])


def use_reader(reader: str, monkeypatch: pytest.MonkeyPatch) -> None:
    if reader == "proc":
        monkeypatch.setattr(pinned, "_SCHED_GETCPU", None)
    elif pinned._SCHED_GETCPU is None:
        pytest.skip("the C library has no sched_getcpu")


@needs_two
@READERS
def test_current_cpu_is_the_cpu_a_pinned_worker_runs_on(
    reader: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    use_reader(reader, monkeypatch)
    seen: list[tuple[int, int | None]] = []
    lock = threading.Lock()

    def task(i: int) -> None:
        with lock:
            seen.append((i, pinned.current_cpu()))

    with pinned.PinnedWorkers(CPUS) as workers:
        for _ in range(3):
            workers.run([lambda: task(0), lambda: task(1)])
    assert len(seen) == 6
    for i, cpu in seen:
        assert cpu == CPUS[i]


@READERS
def test_current_cpu_is_an_allowed_cpu_or_none_without_proc(
    reader: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    use_reader(reader, monkeypatch)
    cpu = pinned.current_cpu()
    if reader == "proc" and not os.path.exists(f"/proc/self/task/{threading.get_native_id()}/stat"):
        assert cpu is None
    elif hasattr(os, "sched_getaffinity"):
        assert cpu in os.sched_getaffinity(0)
    else:
        assert isinstance(cpu, int) and cpu >= 0


@needs_two
def test_matches_on_pinned_workers_equal_the_main_threads() -> None:
    rng = np.random.default_rng(5)
    wall = np.c_[np.linspace(-1, 1, 200), np.full(200, 1.0)]
    grid = ndtgrid.NdtGrid(0.02)
    grid.insert(wall + rng.normal(0, 0.002, wall.shape), [0.0, 0.0, 0.0])
    grid.insert(np.c_[np.full(200, 1.0), np.linspace(-1, 1, 200)], [0.0, 0.0, 0.0])
    guesses = [np.array([0.01 * k, -0.01, 0.01]) for k in range(4)]
    scan = np.vstack([wall, np.c_[np.full(200, 1.0), np.linspace(-1, 1, 200)]])
    expected = [grid.match(scan, g).pose for g in guesses]
    got: list[list[np.ndarray]] = [[], []]

    def part(i: int) -> None:
        got[i].extend(grid.match(scan, g).pose for g in guesses[i::2])

    with pinned.PinnedWorkers(CPUS) as workers:
        workers.run([lambda: part(0), lambda: part(1)])
    assert all(np.array_equal(a, b) for a, b in zip(got[0], expected[0::2]))
    assert all(np.array_equal(a, b) for a, b in zip(got[1], expected[1::2]))
    assert len(got[0]) + len(got[1]) == len(guesses)


@needs_two
def test_a_tasks_error_reaches_the_caller_and_the_workers_go_on() -> None:
    def boom() -> None:
        raise RuntimeError("task failed")

    ran: list[int] = []
    with pinned.PinnedWorkers(CPUS) as workers:
        with pytest.raises(RuntimeError, match=r"^task failed$"):
            workers.run([boom, None])
        workers.run([lambda: ran.append(0), lambda: ran.append(1)])
        with pytest.raises(ValueError, match=r"^1 tasks for 2 workers$"):
            workers.run([None])
    assert sorted(ran) == [0, 1]


def test_pinning_to_a_cpu_not_allowed_fails_and_leaves_no_thread() -> None:
    if not hasattr(os, "sched_setaffinity"):
        pytest.skip("needs os.sched_setaffinity")
    before = threading.active_count()
    bad = max(os.sched_getaffinity(0)) + 4096
    with pytest.raises(OSError):
        pinned.PinnedWorkers([bad])
    assert threading.active_count() == before
