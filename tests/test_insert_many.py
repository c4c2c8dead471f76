"""``NdtGrid.insert_many``: many scans in one call, the map bit for bit that of the inserts
one by one, and nothing changed by a batch that fails."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import ndtgrid

from ._results import exact
from ._room import scan

#: A drive through the room of ``_room.scan``: poses 4 cm and 0.05 rad apart, as a
#: log's consecutive scans are.
DRIVE = np.array([(-0.6 + 0.04 * i, -0.3 + 0.02 * i, 0.05 * i) for i in range(24)])
SCANS = [scan(p, beams=int(180 + 20 * i), noise=0.005, seed=i) for i, p in enumerate(DRIVE)]


def seeded() -> ndtgrid.NdtGrid:
    """A map of two scans, matched once so that its distributions are prepared (the
    inserts must keep them up to date)."""
    grid = ndtgrid.NdtGrid(0.02)
    grid.insert(scan((0, 0, 0), seed=50), (0, 0, 0))
    grid.insert(scan((0.3, 0.2, 1.0), seed=51), (0.3, 0.2, 1.0))
    grid.match(SCANS[0], DRIVE[0])
    return grid


def state(grid: ndtgrid.NdtGrid) -> list[bytes]:
    """Every fine cell's sums as exact bytes."""
    return [a.tobytes() for a in grid.cell_states()]


def matches(grid: ndtgrid.NdtGrid) -> list[tuple[Any, ...]]:
    """Matches of a few scans against ``grid`` (every prepared level read), exactly."""
    return [exact(grid.match(SCANS[i], DRIVE[i] + [0.02, -0.01, 0.01])) for i in (3, 11, 20)]


def test_a_batch_equals_the_inserts_one_by_one() -> None:
    one_by_one = seeded()
    for pts, pose in zip(SCANS, DRIVE):
        one_by_one.insert(pts, pose)
    batched = seeded()
    batched.insert_many(SCANS, DRIVE)
    assert len(batched) == len(one_by_one)
    assert state(batched) == state(one_by_one)
    assert batched.memory_bytes > 0
    assert matches(batched) == matches(one_by_one)
    # And as a map built afresh from those cells (no distributions kept).
    fresh = ndtgrid.NdtGrid.from_cell_states(0.02, *one_by_one.cell_states())
    assert matches(fresh) == matches(one_by_one)


@settings(max_examples=15, deadline=None)
@given(st.lists(st.integers(min_value=1, max_value=len(SCANS)), min_size=1, max_size=6))
def test_any_split_into_batches_gives_the_same_map(cuts: list[int]) -> None:
    bounds = sorted({0, len(SCANS), *cuts})
    batched = seeded()
    for a, b in zip(bounds, bounds[1:]):
        batched.insert_many(SCANS[a:b], DRIVE[a:b])
    one_by_one = seeded()
    for pts, pose in zip(SCANS, DRIVE):
        one_by_one.insert(pts, pose)
    assert state(batched) == state(one_by_one)
    assert matches(batched) == matches(one_by_one)


def test_scans_as_one_3d_array_empty_scans_and_empty_batches() -> None:
    pts = scan((0.1, 0.0, 0.2), seed=9)
    poses = np.array([[0.1, 0.0, 0.2], [0.12, -0.01, 0.21]])
    stacked = seeded()
    stacked.insert_many(np.stack([pts, pts]), poses)
    one_by_one = seeded()
    for pose in poses:
        one_by_one.insert(pts, pose)
    assert state(stacked) == state(one_by_one)
    before = state(stacked)
    stacked.insert_many([], [])
    stacked.insert_many([], np.empty((0, 3)))
    stacked.insert_many([np.empty((0, 2)), np.empty((0, 2))], poses)
    assert state(stacked) == before


def test_angles_are_wrapped_as_insert_wraps_them() -> None:
    """Poses whose angles lie outside (-pi, pi] give the inserts' map, bit for bit."""
    turned = (
        DRIVE[:6]
        + np.array([0.0, 0.0, 1.0]) * (2 * np.pi * np.array([3, -2, 1, 0, -5, 7]))[:, None]
    )
    batched = seeded()
    batched.insert_many(SCANS[:6], turned)
    one_by_one = seeded()
    for pts, pose in zip(SCANS[:6], turned):
        one_by_one.insert(pts, pose)
    assert state(batched) == state(one_by_one)


#: ``DRIVE[:3]`` with the second scan at the origin (its points are map points).
AT_ORIGIN = np.where(np.arange(3)[:, None] == 1, 0.0, DRIVE[:3])


def bad_point(index: int, value: float) -> np.ndarray:
    """``SCANS[1]`` with point ``index`` replaced by ``(value, value)``."""
    pts = SCANS[1].copy()
    pts[index] = value
    return pts


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (
            lambda g: g.insert_many(3, DRIVE[:3]),
            TypeError,
            "scans: expected a sequence of (N, 2) arrays, got int",
        ),
        (
            lambda g: g.insert_many(SCANS[0], DRIVE[:1]),
            TypeError,
            "scans: expected a sequence of (N, 2) arrays, got one array of shape (180, 2) "
            "(one scan: use insert)",
        ),
        (
            lambda g: g.insert_many(SCANS[:3], DRIVE[:2]),
            ValueError,
            "poses: expected 3 poses (one per scan), got 2",
        ),
        (
            lambda g: g.insert_many(SCANS[:3], DRIVE[:3, :2]),
            ValueError,
            "poses: expected an array of shape (K, 3), one [x, y, theta] per row, got shape (3, 2)",
        ),
        (
            lambda g: g.insert_many([SCANS[0], SCANS[1][:, :1], SCANS[2]], DRIVE[:3]),
            ValueError,
            "scan 1: points: expected an array of shape (N, 2), got shape (200, 1)",
        ),
        (
            lambda g: g.insert_many([SCANS[0], bad_point(5, np.nan), SCANS[2]], DRIVE[:3]),
            ValueError,
            "scan 1: points: expected finite values, got NaN at index 5",
        ),
        (
            lambda g: g.insert_many([SCANS[0], bad_point(7, 1e9), SCANS[2]], AT_ORIGIN),
            ValueError,
            "scan 1: points: point 7 at (1e9, 1e9) m is outside the grid's range of "
            "±21474836.48 m (cell index would overflow)",
        ),
        (
            lambda g: g.insert_many(
                SCANS[:3], np.where(np.arange(9).reshape(3, 3) == 8, np.inf, DRIVE[:3])
            ),
            ValueError,
            "scan 2: pose: expected finite values, got inf at index 2",
        ),
        (
            lambda g: g.insert_many([SCANS[0], ["a", "b"]], DRIVE[:2]),
            TypeError,
            "scan 1: points: expected real numbers (float64), got dtype <U1",
        ),
    ],
    ids=[
        "not-a-sequence",
        "one-array",
        "pose-count",
        "pose-shape",
        "point-shape",
        "nan",
        "far",
        "pose-inf",
        "strings",
    ],
)
def test_bad_input_is_rejected_and_changes_nothing(
    call: Callable[[ndtgrid.NdtGrid], None], error: type[Exception], message: str
) -> None:
    grid = seeded()
    before, results = state(grid), matches(grid)
    with pytest.raises(error) as info:
        call(grid)
    assert str(info.value) == message
    assert state(grid) == before
    assert matches(grid) == results
    # The grid still takes a batch afterwards.
    grid.insert_many(SCANS[:2], DRIVE[:2])
    assert len(grid) > 0
