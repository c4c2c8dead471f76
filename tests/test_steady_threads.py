"""The threads that keep matching of ``benches/steady.py`` (the thread section of
``benches/speed.py`` judges two of them against one)."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

import ndtgrid

from ._benches import load_bench

steady = load_bench("steady")


def test_each_thread_takes_its_own_indices_and_counts_its_calls() -> None:
    seen: list[tuple[int, int]] = []
    lock = threading.Lock()

    def task(i: int) -> None:
        with lock:
            seen.append((threading.get_ident(), i))
        time.sleep(0.001)

    run = steady.keep_matching(task, 3, 0.05)
    assert len(run.calls) == 3
    assert sum(run.calls) == len(seen)
    by_thread: dict[int, list[int]] = {}
    for ident, i in seen:
        by_thread.setdefault(ident, []).append(i)
    assert len(by_thread) == 3
    # Thread k calls k, k + 3, k + 6, ... in order, as many times as it counted.
    got = sorted(by_thread.values())
    for k, indices in enumerate(got):
        assert indices == list(range(k, k + 3 * len(indices), 3))
    assert sorted(len(v) for v in got) == sorted(run.calls)
    assert run.wall >= 0.05
    assert run.rate == pytest.approx(sum(run.calls) / run.wall)
    assert run.cpu_over_wall == pytest.approx(run.cpu / run.wall)


def test_threads_stop_once_the_time_is_up() -> None:
    run = steady.keep_matching(lambda i: time.sleep(0.02), 2, 0.05)
    # Each thread starts a call only before 0.05 s: at most 3 calls of 0.02 s each.
    assert all(1 <= c <= 3 for c in run.calls)
    assert run.wall < 0.05 + 0.02 + 0.05


def test_matches_on_two_threads_give_the_poses_of_one() -> None:
    grid = ndtgrid.NdtGrid(0.02)
    angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    scan = np.column_stack([2.0 * np.cos(angles), 1.5 + 0.3 * np.sin(3 * angles)])
    grid.insert(scan, [0.0, 0.0, 0.0])
    guesses = [[0.01 * (k % 3), -0.01 * (k % 2), 0.01 * (k % 5 - 2)] for k in range(8)]
    poses: dict[int, list[np.ndarray]] = {}
    lock = threading.Lock()

    def task(i: int) -> None:
        pose = grid.match(scan, guesses[i % len(guesses)]).pose
        with lock:
            poses.setdefault(i % len(guesses), []).append(pose)

    run = steady.keep_matching(task, 2, 0.05)
    assert all(c > 0 for c in run.calls)
    for k, got in poses.items():
        alone = grid.match(scan, guesses[k]).pose
        assert all(np.array_equal(p, alone) for p in got)


def test_an_exception_in_a_task_reaches_the_caller() -> None:
    def task(i: int) -> None:
        if i == 3:
            raise KeyError("scan 3")

    with pytest.raises(KeyError, match="scan 3"):
        steady.keep_matching(task, 2, 5.0)


@pytest.mark.parametrize(
    ("threads", "seconds", "message"),
    [
        (0, 1.0, "threads: expected an integer >= 1, got 0"),
        (True, 1.0, "threads: expected an integer >= 1, got True"),
        (2.0, 1.0, "threads: expected an integer >= 1, got 2.0"),
        (2, 0.0, "seconds: expected more than 0, got 0.0"),
        (2, float("nan"), "seconds: expected more than 0, got nan"),
    ],
)
def test_bad_arguments(threads: object, seconds: float, message: str) -> None:
    with pytest.raises(ValueError) as err:
        steady.keep_matching(lambda i: None, threads, seconds)
    assert str(err.value) == message
