"""Bad input: every class below raises a clear error and leaves the map unchanged.

The written list (argument -> input -> exception and message):

==============================  ===========  =================================================
input                           exception    message
==============================  ===========  =================================================
points of shape (N, 3)          ValueError   points: expected an array of shape (N, 2), got ...
points of shape (N,)            ValueError   same, ``got shape (N,)``
points of shape (2, 2, 2)       ValueError   same, ``got shape (2, 2, 2)``
points with complex dtype       TypeError    points: expected real numbers (float64), got dtype
points of strings               TypeError    same, ``got dtype <U…``
points = None / an object       TypeError    points: expected an array-like of real numbers...
ragged nested lists             TypeError    points: expected an array-like of real numbers...
points with NaN                 ValueError   points: expected finite values, got NaN at index i
points with +/-inf              ValueError   points: expected finite values, got inf at index i
empty scan to match, (0, 2)     ValueError   points: expected at least one point, got 0
huge coordinates (insert)       ValueError   points: point i at (x, y) m is outside the grid's
                                             range of ±R m (cell index would overflow)
huge coordinates (match)        ValueError   same
pose of 2 or 4 values, (3, 3)   ValueError   pose: expected 3 values [x, y, theta], got shape ..
pose / guess with NaN or inf    ValueError   pose: expected finite values, got nan at index i
cell_size <= 0, NaN, inf        ValueError   cell_size: expected a finite cell size > 0 m, ...
expansion <= 0 or NaN           ValueError   expansion: expected a finite value > 0, got ...
search_radius < 0               ValueError   search_radius: expected a non-negative integer ...
search_radius > 1000            ValueError   search_radius: expected a radius of at most ...
from_bytes / load of a non-map  ValueError   [path: ]not an ndtgrid file (it does not start ...
a mapper file loaded as a grid  ValueError   [path: ]wrong kind of ndtgrid file: expected a ...
other format version            ValueError   [path: ]unsupported ndtgrid file version V: ...
truncated / longer file         ValueError   [path: ]truncated ndtgrid file: expected N bytes..
corrupt file                    ValueError   [path: ]corrupt ndtgrid file: checksum mismatch ..
load / save, path unusable      OSError      [Errno N] cannot read the file: ...: 'path'
==============================  ===========  =================================================

The file errors are tested in test_persist.py.

Accepted rather than refused (and tested to give the same result): non-contiguous or
Fortran-ordered arrays, other real dtypes (float32, integers), lists and tuples; an
empty ``(0, 2)`` scan to ``insert`` is a no-op.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import ndtgrid

from ._room import scan

GOOD = scan((0.0, 0.0, 0.0))
POSE = np.zeros(3)


def snapshot(grid: ndtgrid.NdtGrid) -> tuple[np.ndarray, ...]:
    return grid.cell_statistics()


def same(a: tuple[np.ndarray, ...], b: tuple[np.ndarray, ...]) -> bool:
    return all(np.array_equal(x, y) for x, y in zip(a, b))


def with_value(value: float, index: int = 5) -> np.ndarray:
    pts = GOOD.copy()
    pts[index, 1] = value
    return pts


CASES: list[tuple[str, Callable[[ndtgrid.NdtGrid], Any], type[Exception], str]] = [
    (
        "shape (N,3) insert",
        lambda g: g.insert(np.zeros((4, 3)), POSE),
        ValueError,
        "points: expected an array of shape (N, 2), got shape (4, 3)",
    ),
    (
        "shape (N,) match",
        lambda g: g.match(np.zeros(6), POSE),
        ValueError,
        "points: expected an array of shape (N, 2), got shape (6,)",
    ),
    (
        "shape (2,2,2)",
        lambda g: g.insert(np.zeros((2, 2, 2)), POSE),
        ValueError,
        "points: expected an array of shape (N, 2), got shape (2, 2, 2)",
    ),
    (
        "complex dtype",
        lambda g: g.insert(GOOD.astype(complex), POSE),
        TypeError,
        "points: expected real numbers (float64), got dtype complex128",
    ),
    (
        "strings",
        lambda g: g.insert([["a", "b"]], POSE),
        TypeError,
        "points: expected real numbers (float64), got dtype <U1",
    ),
    (
        "None",
        lambda g: g.insert(None, POSE),
        TypeError,
        "points: expected real numbers (float64), got dtype object",
    ),
    (
        "ragged",
        lambda g: g.insert([[1.0, 2.0], [3.0]], POSE),
        TypeError,
        "points: expected an array-like of real numbers, got list",
    ),
    (
        "NaN insert",
        lambda g: g.insert(with_value(np.nan), POSE),
        ValueError,
        "points: expected finite values, got NaN at index 5",
    ),
    (
        "inf match",
        lambda g: g.match(with_value(np.inf, 7), POSE),
        ValueError,
        "points: expected finite values, got inf at index 7",
    ),
    (
        "-inf insert",
        lambda g: g.insert(with_value(-np.inf, 0), POSE),
        ValueError,
        "points: expected finite values, got -inf at index 0",
    ),
    (
        "empty match",
        lambda g: g.match(np.zeros((0, 2)), POSE),
        ValueError,
        "points: expected at least one point, got 0",
    ),
    (
        "huge insert",
        lambda g: g.insert(with_value(1e9), POSE),
        ValueError,
        f"points: point 5 at ({GOOD[5, 0]}, 1e9) m is outside the grid's range of "
        "±21474836.48 m (cell index would overflow)",
    ),
    (
        "huge pose",
        lambda g: g.insert(GOOD, [3e7, 0.0, 0.0]),
        ValueError,
        "outside the grid's range",
    ),
    (
        "huge match",
        lambda g: g.match(with_value(-1e300, 2), POSE),
        ValueError,
        f"points: point 2 at ({GOOD[2, 0]}, -1e300) m is outside the grid's range of "
        "±21474836.48 m (cell index would overflow)",
    ),
    (
        "pose of 2",
        lambda g: g.insert(GOOD, [0.0, 0.0]),
        ValueError,
        "pose: expected 3 values [x, y, theta], got shape (2,)",
    ),
    (
        "pose of 4",
        lambda g: g.insert(GOOD, np.zeros(4)),
        ValueError,
        "pose: expected 3 values [x, y, theta], got shape (4,)",
    ),
    (
        "pose matrix",
        lambda g: g.insert(GOOD, np.eye(3)),
        ValueError,
        "pose: expected 3 values [x, y, theta], got shape (3, 3)",
    ),
    (
        "guess of 2",
        lambda g: g.match(GOOD, [0.0, 0.0]),
        ValueError,
        "guess: expected 3 values [x, y, theta], got shape (2,)",
    ),
    (
        "pose NaN",
        lambda g: g.insert(GOOD, [0.0, np.nan, 0.0]),
        ValueError,
        "pose: expected finite values, got NaN at index 1",
    ),
    (
        "guess inf",
        lambda g: g.match(GOOD, [0.0, 0.0, np.inf]),
        ValueError,
        "guess: expected finite values, got inf at index 2",
    ),
    (
        "expansion 0",
        lambda g: g.match(GOOD, POSE, expansion=0.0),
        ValueError,
        "expansion: expected a finite value > 0, got 0",
    ),
    (
        "expansion NaN",
        lambda g: g.match(GOOD, POSE, expansion=float("nan")),
        ValueError,
        "expansion: expected a finite value > 0, got NaN",
    ),
    (
        "radius -1",
        lambda g: g.match(GOOD, POSE, search_radius=-1),
        ValueError,
        "search_radius: expected a non-negative integer below 2**32, got -1",
    ),
    (
        "radius 5000",
        lambda g: g.match(GOOD, POSE, search_radius=5000),
        ValueError,
        "search_radius: expected a radius of at most 1000 cells, got 5000",
    ),
]


@pytest.mark.parametrize(("name", "call", "exc", "message"), CASES, ids=[c[0] for c in CASES])
def test_bad_input_raises_and_leaves_map_unchanged(
    name: str, call: Callable[[ndtgrid.NdtGrid], Any], exc: type[Exception], message: str
) -> None:
    grid = ndtgrid.NdtGrid(0.02)
    grid.insert(GOOD, POSE)
    before = snapshot(grid)
    with pytest.raises(exc) as info:
        call(grid)
    assert str(info.value).startswith(message) or message in str(info.value), str(info.value)
    assert same(before, snapshot(grid))
    # The grid still works after the error.
    assert grid.match(GOOD, POSE).num_matched > 0


@pytest.mark.parametrize("bad", [0.0, -0.02, float("nan"), float("inf")])
def test_bad_cell_size(bad: float) -> None:
    with pytest.raises(ValueError, match=r"^cell_size: expected a finite cell size > 0 m, got"):
        ndtgrid.NdtGrid(bad)


def test_empty_insert_is_a_no_op() -> None:
    grid = ndtgrid.NdtGrid(0.02)
    grid.insert(GOOD, POSE)
    before = snapshot(grid)
    grid.insert(np.zeros((0, 2)), POSE)
    assert same(before, snapshot(grid))
