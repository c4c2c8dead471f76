"""``NdtGrid.match_many``: many scans in one call, each result bit for bit its own ``match``."""

from __future__ import annotations

import ast
import math
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import ndtgrid

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


def test_the_gil_is_free_while_it_runs() -> None:
    """A Python thread keeps counting while the batch runs on the calling thread."""
    grid = room_map()
    scans, guesses = batch(8)
    grid.match_many(scans[:1], guesses[:1])  # distributions built
    # Enough copies for a call of about 0.3 s on this machine.
    t0 = time.perf_counter()
    grid.match_many(scans, guesses, threads=1)
    copies = max(1, math.ceil(0.3 / (time.perf_counter() - t0)))
    scans, guesses = scans * copies, np.vstack([guesses] * copies)
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
