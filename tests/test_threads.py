"""Threads (issue 6): many matchers while one thread inserts; Mapper and Odometry shared.

The contract (README, ``_core.pyi``): a map is many readers / one exclusive writer. ``match``,
``evaluate``, ``cells`` ... take a read lock and ``insert`` / ``insert_many`` / ``insert_scan`` a
write lock, all with the GIL released, so a match sees the map as it was between two inserts
(or batches), never half an insert.

**The reference.** The writer inserts scans ``S_1 .. S_n`` in order; before the threads start,
the same sequence is replayed on a fresh map and every query is matched after each insert:
``ref[k][q]`` is query ``q`` on state ``k`` (``k`` inserts). Every result a reader gets must
equal ``ref[k][q]`` for some ``k``, **bit for bit** (pose, score, Hessian, iterations, counts),
and the ``k`` of one reader's successive results must be able to be non-decreasing.

Exact equality is sound because matching is a function of the cells' sums alone: the
distributions the matcher uses are prepared lazily and then updated in place by each insert,
and an updated distribution is recomputed from the sums exactly as a fresh one would be
(``crates/ndt-core/tests/properties.rs`` checks that a match on an incrementally updated grid
equals the match on a grid rebuilt from its cells, bit for bit, after random inserts, removals
and §V scans). So whether or not a match ran between two inserts does not change later
results, and no tolerance is needed. Consecutive states give different results for each
query here (asserted), so a torn read (a match that mixed two states) could not pass
unnoticed as "some state".
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import ndtgrid

from ._results import exact
from ._room import scan

N_READERS = 4
JOIN_TIMEOUT = 120.0


def path(k: int) -> np.ndarray:
    return np.array([-1.0 + 0.12 * k, -0.3 + 0.05 * np.sin(k / 2.0), 0.15 * np.sin(k / 3.0)])


SCANS = [(scan(path(k), beams=361, noise=0.005, seed=k), path(k)) for k in range(10)]
QUERIES = [
    (scan(path(k) + np.array([0.02, -0.01, 0.0]), beams=181, noise=0.005, seed=100 + k), path(k))
    for k in (0, 3, 6, 9)
]


def run_match(grid: ndtgrid.NdtGrid, q: int) -> tuple[Any, ...]:
    pts, guess = QUERIES[q]
    return exact(grid.match(pts, guess))


def insert_while_reading(
    readers: list[threading.Thread],
    seen: list[Any],
    insert: Callable[[int], None],
    done: threading.Event,
    errors: list[BaseException],
) -> None:
    """Start the readers, make inserts ``1 .. len(SCANS) - 1`` one by one, each once
    every reader has had one more result (without this, on a busy machine they might
    all start after the last insert), then let the readers end; fail on a reader that
    hangs (a deadlock) or raised."""
    for t in readers:
        t.start()
    for k in range(1, len(SCANS)):
        n = results(seen)
        wait_until(lambda n=n: results(seen) >= n + len(readers))
        insert(k)
    done.set()
    for t in readers:
        t.join(JOIN_TIMEOUT)
    assert not any(t.is_alive() for t in readers), "a reader hung (deadlock?)"
    assert not errors, errors


def states_of(insert: Callable[[Any, int], None], make: Callable[[], Any]) -> list[list[Any]]:
    """``ref[k][q]``: query ``q`` after ``k`` inserts, on a fresh replay."""
    target = make()
    grid = target.grid if isinstance(target, ndtgrid.Mapper) else target
    ref = []
    for k in range(len(SCANS) + 1):
        if k > 0:
            insert(target, k - 1)
        ref.append([run_match(grid, q) if len(grid) else None for q in range(len(QUERIES))])
    return ref


def results(seen: list[list[Any]]) -> int:
    return sum(len(s) for s in seen)


def wait_until(condition: Callable[[], bool], timeout: float = 30.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.0005)


def run_writers_then_stop_readers(
    writers: list[threading.Thread], readers: list[threading.Thread], stop: threading.Event
) -> None:
    """Start every thread, wait for the writers, then stop and join the readers; fail if
    any thread is still alive after its timeout (a deadlock)."""
    for t in writers + readers:
        t.start()
    for t in writers:
        t.join(JOIN_TIMEOUT)
    stop.set()
    for t in readers:
        t.join(JOIN_TIMEOUT)
    assert not any(t.is_alive() for t in writers + readers), "deadlock"


def query_readers(
    grid: ndtgrid.NdtGrid,
    seen: list[list[tuple[int, tuple[Any, ...]]]],
    done: threading.Event,
    errors: list[BaseException],
) -> list[threading.Thread]:
    """One thread per list of ``seen``: each matches the queries in turn (reader ``i``
    from query ``i``), appending ``(query, result)``, until a round that began after
    ``done`` was set; exceptions go to ``errors``."""

    def reader(i: int) -> None:
        try:
            q = i
            while True:
                last_round = done.is_set()
                seen[i].append((q % len(QUERIES), run_match(grid, q % len(QUERIES))))
                q += 1
                if last_round:
                    break
        except BaseException as e:  # pragma: no cover - reported by the caller
            errors.append(e)

    return [threading.Thread(target=reader, args=(i,), daemon=True) for i in range(len(seen))]


def states_reached(
    seen: list[list[tuple[int, tuple[Any, ...]]]], ref: list[list[Any]], allowed: Any
) -> set[int]:
    """Checks each reader's results against the states ``ref`` (a result must equal some
    state's, bit for bit, among ``allowed``; a reader's states can only go forward, and its
    last round, begun after the last insert, sees the final state); returns the states
    reached."""
    reached = set()
    for i, results in enumerate(seen):
        assert results, f"reader {i} got no result"
        state = 1
        for q, result in results:
            candidates = [k for k in range(1, len(SCANS) + 1) if ref[k][q] == result]
            assert candidates, f"reader {i}: a result equal to no state (torn read)"
            assert set(candidates) <= set(allowed), f"reader {i}: between states: {candidates}"
            later = [k for k in candidates if k >= state]
            assert later, f"reader {i}: state went back from {state} to {candidates}"
            state = later[0]
            reached.add(state)
        assert state == len(SCANS)
    return reached


def insert_grid(g: ndtgrid.NdtGrid, k: int) -> None:
    g.insert(*SCANS[k])


def insert_mapper(m: ndtgrid.Mapper, k: int) -> None:
    pts, pose = SCANS[k]
    ranges = np.hypot(pts[:, 0], pts[:, 1])
    angles = np.arctan2(pts[:, 1], pts[:, 0])
    m.insert_scan(ranges, angles, pose)


@pytest.mark.parametrize(
    ("make", "insert"),
    [(lambda: ndtgrid.NdtGrid(0.02), insert_grid), (lambda: ndtgrid.Mapper(), insert_mapper)],
    ids=["NdtGrid.insert", "Mapper.insert_scan"],
)
def test_matches_while_one_thread_inserts_see_whole_states_in_order(
    make: Callable[[], Any], insert: Callable[[Any, int], None]
) -> None:
    ref = states_of(insert, make)
    # Every insert changes every query's result: a torn read cannot pass as a state.
    for k in range(1, len(SCANS)):
        for q in range(len(QUERIES)):
            assert ref[k][q] != ref[k + 1][q], (k, q)

    target = make()
    grid = target.grid if isinstance(target, ndtgrid.Mapper) else target
    insert(target, 0)  # readers start on state 1
    done = threading.Event()
    seen: list[list[tuple[int, tuple[Any, ...]]]] = [[] for _ in range(N_READERS)]
    errors: list[BaseException] = []
    threads = query_readers(grid, seen, done, errors)
    insert_while_reading(threads, seen, lambda k: insert(target, k), done, errors)

    reached = states_reached(seen, ref, range(1, len(SCANS) + 1))
    assert len(reached) >= len(SCANS) // 2


def test_matches_while_one_thread_inserts_batches_never_see_half_a_batch() -> None:
    """``insert_many`` holds the write lock for its whole batch: a match sees the map before
    or after a batch, never between two of its scans. Its map is the inserts' one by one,
    bit for bit, so the states between batches are ``ref[1]``, ``ref[4]``, ``ref[7]`` and
    ``ref[10]``, and no result may equal a state inside a batch."""
    ref = states_of(insert_grid, lambda: ndtgrid.NdtGrid(0.02))
    grid = ndtgrid.NdtGrid(0.02)
    insert_grid(grid, 0)
    batches = {1: range(1, 4), 4: range(4, 7), 7: range(7, 10)}
    whole = [1, 4, 7, 10]
    done = threading.Event()
    seen: list[list[tuple[int, tuple[Any, ...]]]] = [[] for _ in range(N_READERS)]
    errors: list[BaseException] = []

    def write(k: int) -> None:
        if k in batches:
            grid.insert_many(
                [SCANS[j][0] for j in batches[k]], np.array([SCANS[j][1] for j in batches[k]])
            )

    threads = query_readers(grid, seen, done, errors)
    insert_while_reading(threads, seen, write, done, errors)
    assert len(states_reached(seen, ref, whole)) >= 3


def test_match_many_while_one_thread_inserts_sees_one_state_per_batch() -> None:
    """``match_many`` holds the read lock for its whole batch: every scan of a batch is
    matched on the same state (bit for bit its ``ref[k]``), and a reader's states only
    go forward."""
    ref = states_of(insert_grid, lambda: ndtgrid.NdtGrid(0.02))
    grid = ndtgrid.NdtGrid(0.02)
    insert_grid(grid, 0)
    scans = [pts for pts, _ in QUERIES]
    guesses = np.array([g for _, g in QUERIES])
    done = threading.Event()
    seen: list[list[list[tuple[Any, ...]]]] = [[] for _ in range(2)]
    errors: list[BaseException] = []

    def reader(i: int) -> None:
        try:
            while True:
                last_round = done.is_set()
                batch = grid.match_many(scans, guesses, threads=1 + i)
                seen[i].append([exact(r) for r in batch])
                if last_round:
                    break
        except BaseException as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=reader, args=(i,), daemon=True) for i in range(2)]
    insert_while_reading(threads, seen, lambda k: insert_grid(grid, k), done, errors)
    for i in range(2):
        states = []
        for batch in seen[i]:
            same = [k for k in range(1, len(SCANS) + 1) if ref[k] == batch]
            assert same, f"reader {i}: a batch equal to no single state"
            states.append(same[0])
        assert states == sorted(states), f"reader {i}: states went back: {states}"
        assert states[-1] == len(SCANS)


def test_mapper_shared_by_threads_neither_deadlocks_nor_crashes() -> None:
    """Two threads insert scans into one Mapper while two read it (occupied cells, small
    objects, counters, matches on its grid). Inserts are serialized: every scan counts."""
    m = ndtgrid.Mapper()
    insert_mapper(m, 0)
    errors: list[BaseException] = []
    stop = threading.Event()

    def writer(ks: list[int]) -> None:
        try:
            for k in ks:
                insert_mapper(m, k)
        except BaseException as e:  # pragma: no cover
            errors.append(e)

    def reader() -> None:
        try:
            while not stop.is_set():
                m.occupied_cells()
                m.small_objects()
                m.removal_counts()
                assert m.grid.match(*QUERIES[0]).num_matched > 0
                len(m)
                repr(m)
        except BaseException as e:  # pragma: no cover
            errors.append(e)

    writers = [threading.Thread(target=writer, args=(ks,)) for ks in ([1, 3, 5, 7], [2, 4, 6, 8])]
    readers = [threading.Thread(target=reader, daemon=True) for _ in range(2)]
    run_writers_then_stop_readers(writers, readers, stop)
    assert not errors, errors
    assert m.scan_count == 9


def test_odometry_shared_by_threads_neither_deadlocks_nor_crashes() -> None:
    """Two threads step one Odometry while another reads it. Steps are serialized (every
    step is recorded, none is lost or torn); their order between the threads is whatever
    the lock gives, which is why a loop should be fed from one thread (see the .pyi)."""
    odo = ndtgrid.Odometry()
    errors: list[BaseException] = []
    stop = threading.Event()
    polar = []
    for pts, _ in SCANS[:6]:
        polar.append((np.hypot(pts[:, 0], pts[:, 1]), np.arctan2(pts[:, 1], pts[:, 0])))

    def stepper() -> None:
        try:
            for r, a in polar:
                pose = odo.step(r, a)
                assert np.all(np.isfinite(pose))
        except BaseException as e:  # pragma: no cover
            errors.append(e)

    def reader() -> None:
        try:
            while not stop.is_set():
                assert np.all(np.isfinite(odo.poses))
                len(odo)
                assert odo.insertions >= 0
                odo.mapper.occupied_cells()
                odo.grid()
        except BaseException as e:  # pragma: no cover
            errors.append(e)

    steppers = [threading.Thread(target=stepper) for _ in range(2)]
    readers = [threading.Thread(target=reader, daemon=True)]
    run_writers_then_stop_readers(steppers, readers, stop)
    assert not errors, errors
    assert odo.poses.shape == (12, 3)
