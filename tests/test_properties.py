"""Property tests of the Python surface (issue 6), with hypothesis.

Arbitrary arguments (random shapes; float32/64, int, uint, bool, complex and object dtypes;
non-contiguous and Fortran-ordered views; NaN, inf, empty arrays, huge values; None, scalars,
strings, lists) to ``NdtGrid.insert`` / ``match``, ``ranges_to_points``,
``Mapper.insert_scan`` and ``Odometry.step``: each call either raises ``ValueError`` or
``TypeError`` and leaves the map unchanged, or succeeds with a valid result, and succeeds
*only* on valid input (a real array of the right shape with finite values). No other
exception, no crash.

Examples per test: the ``ci`` profile (default, a few seconds for the module) or
``HYPOTHESIS_PROFILE=long`` for the run recorded in BENCHMARK.md ("Reliability (issue 6)")::

    HYPOTHESIS_PROFILE=long PYTHONPATH=$PWD/python python -m pytest -q tests/test_properties.py
"""

from __future__ import annotations

import math
import os
from typing import Any, Literal

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import ndtgrid

from ._room import scan

settings.register_profile(
    "ci", max_examples=25, deadline=None, suppress_health_check=list(HealthCheck)
)
settings.register_profile(
    "long", max_examples=5000, deadline=None, suppress_health_check=list(HealthCheck)
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

DTYPES = [
    np.dtype(np.float64),
    np.dtype(np.float32),
    np.dtype(np.int64),
    np.dtype(np.int32),
    np.dtype(np.uint8),
    np.dtype(np.uint64),
    np.dtype(np.bool_),
    np.dtype(np.complex128),
    np.dtype(object),
]
OBJECTS = st.one_of(st.floats(), st.none(), st.text(max_size=2), st.integers())
ROOM = scan((0.0, 0.0, 0.0), beams=181)
ANGLES = np.linspace(-1.5, 1.5, 181)


def float_width(dtype: np.dtype[Any]) -> Literal[32, 64]:
    """The bits of a float32 or float64 dtype, as hypothesis's ``floats`` takes them."""
    return 32 if dtype.itemsize == 4 else 64


def elements(dtype: np.dtype[Any]) -> st.SearchStrategy[Any]:
    if dtype.kind == "O":
        return OBJECTS
    if dtype.kind == "f":
        # Mostly moderate values (so the success path is exercised), sometimes anything.
        width = float_width(dtype)
        return st.one_of(
            st.floats(-5.0, 5.0, width=width),
            st.floats(-5.0, 5.0, width=width),
            hnp.from_dtype(dtype),
        )
    return hnp.from_dtype(dtype)


REAL = [np.dtype(d) for d in (np.float64, np.float32, np.int64, np.int32)]
SPOIL = st.sampled_from([np.nan, np.inf, -np.inf, 1e300, -3e7])


@st.composite
def arrays(
    draw: st.DrawFn, shape: st.SearchStrategy[tuple[int, ...]], good: tuple[int, ...] | None
) -> Any:
    """An array of any dtype and layout, or now and then not an array at all. Half the
    time it is nearly valid: a real dtype, the ``good`` shape (``-1``: any length),
    moderate values, and one spoiled value (NaN, inf, huge) in a quarter of those."""
    kind = draw(st.integers(0, 19))
    if kind == 0:
        return draw(st.one_of(st.none(), st.floats(), st.text(max_size=3), st.integers()))
    if kind == 1:
        return draw(st.lists(st.one_of(st.floats(), st.lists(st.floats(), max_size=3))))
    if kind >= 10 and good is not None:
        dtype = draw(st.sampled_from(REAL))
        dims = tuple(draw(st.integers(0, 12)) if d < 0 else d for d in good)
        values = (
            st.floats(-5.0, 5.0, width=float_width(dtype))
            if dtype.kind == "f"
            else st.integers(-5, 5)
        )
        arr = draw(hnp.arrays(dtype, dims, elements=values))
        if dtype.kind == "f" and arr.size and draw(st.integers(0, 3)) == 0:
            with np.errstate(over="ignore"):  # 1e300 into float32 is inf: fine
                arr.flat[draw(st.integers(0, arr.size - 1))] = draw(SPOIL)
    else:
        dtype = draw(st.sampled_from(DTYPES))
        arr = draw(hnp.arrays(dtype, draw(shape), elements=elements(dtype)))
    layout = draw(st.sampled_from(["plain", "strided", "fortran", "list"]))
    if layout == "strided" and arr.ndim > 0:
        arr = np.repeat(arr, 2, axis=0)[::2]  # same values, non-contiguous
    elif layout == "fortran":
        arr = np.asfortranarray(arr)
    elif layout == "list" and arr.dtype.kind in "fiu":
        return arr.tolist()
    return arr


def points_shapes() -> st.SearchStrategy[tuple[int, ...]]:
    return st.one_of(
        st.tuples(st.integers(0, 12), st.just(2)),
        hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=4),
    )


def vector_shapes(n: int = 12) -> st.SearchStrategy[tuple[int, ...]]:
    return st.one_of(
        st.tuples(st.integers(0, n)),
        hnp.array_shapes(min_dims=0, max_dims=2, min_side=0, max_side=4),
    )


def pose_shapes() -> st.SearchStrategy[tuple[int, ...]]:
    return st.one_of(st.just((3,)), hnp.array_shapes(min_dims=0, max_dims=2, max_side=4))


def as_real(x: Any, ndim: int, cols: int | None = None) -> np.ndarray | None:
    """``x`` as float64 if it is valid input of that shape with finite values, else None."""
    try:
        arr = np.asarray(x)
    except ValueError:
        return None
    if arr.dtype.kind not in "fiu" or arr.ndim != ndim:
        return None
    if cols is not None and arr.shape[-1] != cols:
        return None
    out = arr.astype(np.float64)
    return out if np.all(np.isfinite(out)) else None


def as_vector(x: Any) -> np.ndarray | None:
    """``x`` as a float64 1-D array (non-finite values allowed), else None."""
    try:
        arr = np.asarray(x)
    except ValueError:
        return None
    if arr.dtype.kind not in "fiu" or arr.ndim != 1:
        return None
    return arr.astype(np.float64)


def unchanged(before: tuple[Any, ...], after: tuple[Any, ...]) -> bool:
    return all(np.array_equal(a, b) for a, b in zip(before, after))


def room_grid() -> ndtgrid.NdtGrid:
    grid = ndtgrid.NdtGrid(0.02)
    grid.insert(ROOM, np.zeros(3))
    return grid


@given(points=arrays(points_shapes(), (-1, 2)), pose=arrays(pose_shapes(), (3,)))
def test_insert_raises_or_inserts_valid_input_only(points: Any, pose: Any) -> None:
    grid = room_grid()
    before = grid.cell_states()
    try:
        grid.insert(points, pose)
    except (ValueError, TypeError) as e:
        event("error")
        assert unchanged(before, grid.cell_states()), e
        return
    event("inserted")
    pts, p = as_real(points, 2, 2), as_real(pose, 1, 3)
    assert pts is not None and p is not None and p.shape == (3,), (points, pose)
    # The same as inserting the float64 C-contiguous copy.
    ref = room_grid()
    ref.insert(np.ascontiguousarray(pts), p)
    assert unchanged(ref.cell_states(), grid.cell_states())


@given(points=arrays(points_shapes(), (-1, 2)), guess=arrays(pose_shapes(), (3,)))
def test_match_raises_or_returns_a_finite_pose(points: Any, guess: Any) -> None:
    grid = room_grid()
    before = grid.cell_states()
    try:
        res = grid.match(points, guess, max_iterations=10)
    except (ValueError, TypeError):
        event("error")
        assert unchanged(before, grid.cell_states())
        return
    event("matched")
    pts, g = as_real(points, 2, 2), as_real(guess, 1, 3)
    assert pts is not None and len(pts) > 0 and g is not None and g.shape == (3,)
    assert np.all(np.isfinite(res.pose)) and np.isfinite(res.score)
    assert 0 <= res.num_matched <= len(pts)
    assert unchanged(before, grid.cell_states())


def ranges_or_spoiled(draw: st.DrawFn) -> tuple[Any, Any]:
    """Ranges and angles: often a real scan with invalid readings mixed in, else anything."""
    if draw(st.booleans()):
        n = draw(st.integers(0, 181))
        bad = st.sampled_from([np.nan, np.inf, -np.inf, 0.0, -1.0, 5e-324])
        ranges = np.full(n, 2.0) + np.linspace(0.0, 0.5, n)
        for i in draw(st.lists(st.integers(0, max(n - 1, 0)), max_size=20)):
            if n:
                ranges[i] = draw(bad)
        if n and draw(st.integers(0, 9)) == 0:
            # Beyond the grid: an error unless max_range skips it.
            ranges[draw(st.integers(0, n - 1))] = draw(st.sampled_from([1e9, 1e300]))
        angles = np.linspace(-1.5, 1.5, n)
        if draw(st.integers(0, 9)) == 0 and n:
            angles[draw(st.integers(0, n - 1))] = draw(st.sampled_from([np.nan, np.inf]))
        return ranges, angles
    return draw(arrays(vector_shapes(181), (-1,))), draw(arrays(vector_shapes(181), (-1,)))


@given(
    scan_=st.composite(lambda draw: ranges_or_spoiled(draw))(),
    min_range=st.one_of(st.just(0.0), st.just(0.0), st.floats(0.0, 3.0), st.floats()),
    max_range=st.one_of(st.just(np.inf), st.just(np.inf), st.floats(1.0, 30.0), st.floats()),
)
def test_ranges_to_points_raises_or_keeps_exactly_the_valid_beams(
    scan_: tuple[Any, Any], min_range: float, max_range: float
) -> None:
    ranges, angles = scan_
    try:
        pts = ndtgrid.ranges_to_points(ranges, angles, min_range=min_range, max_range=max_range)
    except (ValueError, TypeError):
        event("error")
        return
    event("converted")
    r, a = as_vector(ranges), as_real(angles, 1)
    assert r is not None and a is not None and len(r) == len(a)
    assert np.isfinite(min_range) and min_range >= 0 and max_range > min_range
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(r) & (r > 0) & (r >= min_range) & (r < max_range)
    assert pts.shape == (int(valid.sum()), 2) and pts.dtype == np.float64
    # The platform's cos, as the core's (NumPy's own cos differs in the last bits on
    # some versions and CPUs).
    cos = np.array([math.cos(x) for x in a[valid]], dtype=np.float64)
    assert np.array_equal(pts[:, 0], r[valid] * cos)


def mapper_state(m: ndtgrid.Mapper) -> tuple[Any, ...]:
    counts = np.array(list(m.removal_counts().as_dict().values()))
    return (*m.grid.cell_states(), np.array([m.scan_count]), counts)


@st.composite
def scans(draw: st.DrawFn) -> tuple[Any, Any, Any]:
    ranges, angles = ranges_or_spoiled(draw)
    return ranges, angles, draw(arrays(pose_shapes(), (3,)))


@given(scan_=scans())
def test_mapper_insert_scan_raises_or_accepts_valid_input_only(scan_: tuple[Any, ...]) -> None:
    ranges, angles, pose = scan_
    m = ndtgrid.Mapper()
    m.insert_scan(np.full(181, 2.0), ANGLES, np.zeros(3))
    before = mapper_state(m)
    try:
        m.insert_scan(ranges, angles, pose)
    except (ValueError, TypeError):
        event("error")
        assert unchanged(before, mapper_state(m))
        return
    event("inserted")
    r, a, p = as_vector(ranges), as_real(angles, 1), as_real(pose, 1, 3)
    assert r is not None and a is not None and len(r) == len(a)
    assert p is not None and p.shape == (3,)
    assert m.scan_count in (1, 2)


@given(scan_=scans(), with_odom=st.booleans())
def test_odometry_step_raises_or_gives_a_finite_pose(
    scan_: tuple[Any, ...], with_odom: bool
) -> None:
    ranges, angles, odom = scan_
    odo = ndtgrid.Odometry()
    odo.step(np.full(181, 2.0), ANGLES, np.zeros(3))
    before = (odo.poses, odo.grid().cell_states()[0], np.array([odo.insertions]))
    try:
        pose = odo.step(ranges, angles, odom if with_odom else None)
    except (ValueError, TypeError):
        event("error")
        after = (odo.poses, odo.grid().cell_states()[0], np.array([odo.insertions]))
        assert unchanged(before, after)
        return
    event("stepped")
    r, a = as_vector(ranges), as_real(angles, 1)
    assert r is not None and a is not None and len(r) == len(a)
    if with_odom and odom is not None:
        o = as_real(odom, 1, 3)
        assert o is not None and o.shape == (3,)
    assert np.all(np.isfinite(pose)) and odo.poses.shape == (2, 3)


@pytest.mark.parametrize("dtype", [np.float32, np.int32, np.uint8, np.float64])
def test_real_dtypes_and_layouts_give_the_float64_result(dtype: type) -> None:
    """The accepted non-float64 or non-contiguous inputs act as their float64 copies."""
    pts = np.round(ROOM * 10).astype(dtype)
    views = [pts, np.asfortranarray(pts), np.repeat(pts, 2, axis=0)[::2], pts.tolist()]
    ref = ndtgrid.NdtGrid(0.02)
    ref.insert(pts.astype(np.float64), np.zeros(3))
    for v in views:
        grid = ndtgrid.NdtGrid(0.02)
        grid.insert(v, np.zeros(3, dtype=dtype))
        assert unchanged(ref.cell_states(), grid.cell_states())
