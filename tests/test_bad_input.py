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
expansion_phases=[] (match)     ValueError   expansion_phases: expected at least one expansion...
huge coordinates (insert)       ValueError   points: point i at (x, y) m is outside the grid's
                                             range of ±R m (cell index would overflow)
huge coordinates (match)        ValueError   same
pose of 2 or 4 values, (3, 3)   ValueError   pose: expected 3 values [x, y, theta], got shape ..
pose / guess with NaN or inf    ValueError   pose: expected finite values, got nan at index i
cell_size < 1 mm, NaN, inf      ValueError   cell_size: expected a finite cell size >= 0.001 m, ...
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

Laser scans (``Mapper.insert_scan``, ``Odometry.step``, ``ranges_to_points``); the
state compared after each failure is the map's cell states, the scan count and the
removal counters (Mapper), and the poses, insertions, both maps and the filter's scan
count (Odometry):

==============================  ===========  =================================================
input                           exception    message
==============================  ===========  =================================================
angles shorter than ranges      ValueError   angles: expected B values (one per range), got …
an angle NaN / inf              ValueError   angles: expected finite values, got NaN at index i
ranges / angles 2-D or scalar   ValueError   ranges: expected a 1-D array, got shape (1, B)
ranges complex / bool / str     TypeError    ranges: expected real numbers (float64), got dtype
ranges = None / ragged lists    TypeError    ranges: expected an array-like of real numbers...
ranges an object ndarray        TypeError    ranges: expected real numbers ..., got dtype object
pose / odom of 2 values         ValueError   pose: expected 3 values [x, y, theta], got shape ..
pose / odom with NaN            ValueError   pose: expected finite values, got NaN at index i
a range beyond ±2**30 cells     ValueError   ranges: point i at (x, y) m is outside the grid's
                                             range of ±R m (cell index would overflow)
                                             (Odometry: ``points: point i …``, from the
                                             match that runs before the insert)
a pose beyond it                ValueError   same (Odometry: when nothing matched and the
                                             prediction lies there; an odometry jump with
                                             a matching scan falls back to the constant-
                                             velocity prior, tested)
bad ranges_to_points limits     ValueError   min_range: expected a finite range >= 0 m, got ..;
                                             max_range: expected a range > min_range, got ..
==============================  ===========  =================================================

Options (the constructor raises; nothing is built): every ``MapperOptions`` length
``< 0`` or NaN, ``cluster_spacing_factor`` inf, ``max_range <= min_range``,
``check_interval`` / ``min_observations`` 0 or negative; every ``OdometryConfig`` field
out of range, including ``levels`` outside 1..6 (refused at construction, not at the
second scan). Unknown options raise ``TypeError``; a non-number where a number is
expected raises PyO3's ``TypeError: must be real number, not str``.

Legal rather than refused (and tested): ranges that are NaN, ±inf, 0, negative, below
``min_range`` or at/above ``max_range`` are skipped beam by beam; a scan with no valid
beam (all invalid, or ``B = 0``) changes nothing in a Mapper (not even ``scan_count``),
and in an Odometry gives the predicted pose (recorded) without matching or inserting.
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
        "points: expected an array-like of real numbers, got NoneType",
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
        "no expansion phases",
        lambda g: g.match(GOOD, POSE, expansion_phases=[]),
        ValueError,
        "expansion_phases: expected at least one expansion, got 0",
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
        "points: point 0 at (2.999999884529946e7, -2) m is outside the grid's range of "
        "±21474836.48 m (cell index would overflow)",
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
        "pose inf",
        lambda g: g.insert(GOOD, [0.0, 0.0, np.inf]),
        ValueError,
        "pose: expected finite values, got inf at index 2",
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
        "rotation gate NaN",
        lambda g: g.match(GOOD, POSE, rotation_gate=float("nan")),
        ValueError,
        "rotation_gate: expected a score per point >= 0 (inf = the multi-start always), got NaN",
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
    assert str(info.value) == message
    assert same(before, snapshot(grid))
    # The grid still works after the error.
    assert grid.match(GOOD, POSE).num_matched > 0


@pytest.mark.parametrize("bad", [0.0, -0.02, float("nan"), float("inf"), 1e-8, 0.000999])
def test_bad_cell_size(bad: float) -> None:
    with pytest.raises(
        ValueError, match=r"^cell_size: expected a finite cell size >= 0\.001 m, got"
    ):
        ndtgrid.NdtGrid(bad)


class _Tagged(np.ndarray):
    """An ndarray subclass: converted by ``numpy.asarray``, as other array-likes are."""


@pytest.mark.parametrize(
    "convert",
    [
        lambda a: a.view(_Tagged),
        lambda a: np.ma.masked_array(a, mask=np.zeros_like(a, dtype=bool)),
        lambda a: a.tolist(),
        lambda a: np.asfortranarray(a),
        lambda a: np.repeat(a, 2, axis=-1)[..., ::2],
    ],
    ids=["subclass", "masked", "list", "fortran", "strided"],
)
def test_array_likes_insert_as_their_ndarray(convert: Callable[[Any], Any]) -> None:
    # Plain float64 arrays skip numpy.asarray in the binding; everything else goes
    # through it: both must give the same map.
    plain, other = ndtgrid.NdtGrid(0.02), ndtgrid.NdtGrid(0.02)
    plain.insert(GOOD, POSE)
    other.insert(convert(np.asarray(GOOD, dtype=np.float64)), convert(POSE))
    assert same(snapshot(plain), snapshot(other))


def test_empty_insert_is_a_no_op() -> None:
    grid = ndtgrid.NdtGrid(0.02)
    grid.insert(GOOD, POSE)
    before = snapshot(grid)
    grid.insert(np.zeros((0, 2)), POSE)
    assert same(before, snapshot(grid))


# --- laser scans: Mapper.insert_scan, Odometry.step, ranges_to_points ------------------

ANGLES = np.linspace(-1.5, 1.5, 181)
RANGES = np.full(181, 2.0)
LIMIT = "±21474836.48 m (cell index would overflow)"


def with_nan(values: np.ndarray, index: int, value: float = np.nan) -> np.ndarray:
    out = values.copy()
    out[index] = value
    return out


#: (name, call, exception, exact message) for Mapper.insert_scan and Odometry.step.
SCAN_CASES: list[tuple[str, Callable[[Callable[..., Any]], Any], type[Exception], str]] = [
    (
        "lengths differ",
        lambda f: f(RANGES, ANGLES[:-1]),
        ValueError,
        "angles: expected 181 values (one per range), got 180",
    ),
    (
        "angle NaN",
        lambda f: f(RANGES, with_nan(ANGLES, 3)),
        ValueError,
        "angles: expected finite values, got NaN at index 3",
    ),
    (
        "angle inf",
        lambda f: f(RANGES, with_nan(ANGLES, 4, np.inf)),
        ValueError,
        "angles: expected finite values, got inf at index 4",
    ),
    (
        "ranges 2-D",
        lambda f: f(RANGES.reshape(1, -1), ANGLES),
        ValueError,
        "ranges: expected a 1-D array, got shape (1, 181)",
    ),
    (
        "ranges scalar",
        lambda f: f(2.0, ANGLES),
        ValueError,
        "ranges: expected a 1-D array, got shape ()",
    ),
    (
        "angles 2-D",
        lambda f: f(RANGES, np.zeros((181, 1))),
        ValueError,
        "angles: expected a 1-D array, got shape (181, 1)",
    ),
    (
        "ranges complex",
        lambda f: f(RANGES.astype(complex), ANGLES),
        TypeError,
        "ranges: expected real numbers (float64), got dtype complex128",
    ),
    (
        "ranges bool",
        lambda f: f(RANGES > 0, ANGLES),
        TypeError,
        "ranges: expected real numbers (float64), got dtype bool",
    ),
    (
        "ranges strings",
        lambda f: f(["a"] * 181, ANGLES),
        TypeError,
        "ranges: expected real numbers (float64), got dtype <U1",
    ),
    (
        "ranges None",
        lambda f: f(None, ANGLES),
        TypeError,
        "ranges: expected an array-like of real numbers, got NoneType",
    ),
    (
        "ranges ragged",
        lambda f: f([[1.0], [1.0, 2.0]], ANGLES),
        TypeError,
        "ranges: expected an array-like of real numbers, got list",
    ),
    (
        "range beyond the grid",
        lambda f: f(with_nan(RANGES, 90, 3e7), ANGLES),
        ValueError,
        f"ranges: point 90 at (3e7, 0) m is outside the grid's range of {LIMIT}",
    ),
]


SCAN_IDS = [c[0] for c in SCAN_CASES]
LEVELS = "levels: expected between 1 and 6 pyramid levels (the loop's grid has 6), got"


def mapper_state(m: ndtgrid.Mapper) -> tuple[Any, ...]:
    return (m.grid.cell_states(), m.scan_count, m.removal_counts().as_dict(), len(m))


def odometry_state(o: ndtgrid.Odometry) -> tuple[Any, ...]:
    mapper = o.mapper
    return (
        o.poses,
        o.insertions,
        o.grid().cell_states(),
        mapper.grid.cell_states(),
        mapper.scan_count,
        mapper.removal_counts().as_dict(),
    )


def equal(a: Any, b: Any) -> bool:
    if isinstance(a, tuple):
        return len(a) == len(b) and all(equal(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return bool(np.array_equal(a, b))
    return bool(a == b)


def fresh_mapper() -> ndtgrid.Mapper:
    m = ndtgrid.Mapper()
    for k in range(4):
        m.insert_scan(RANGES + 0.001 * k, ANGLES, [0.0, 0.0, 0.0])
    return m


def fresh_odometry() -> ndtgrid.Odometry:
    o = ndtgrid.Odometry()
    for k in range(3):
        o.step(RANGES - 0.05 * k, ANGLES, [0.05 * k, 0.0, 0.0])
    return o


@pytest.mark.parametrize(("name", "call", "exc", "message"), SCAN_CASES, ids=SCAN_IDS)
def test_mapper_bad_scan_raises_and_changes_nothing(
    name: str, call: Callable[[Callable[..., Any]], Any], exc: type[Exception], message: str
) -> None:
    m = fresh_mapper()
    before = mapper_state(m)
    with pytest.raises(exc) as info:
        call(lambda r, a: m.insert_scan(r, a, [0.0, 0.0, 0.0]))
    assert str(info.value) == message
    assert equal(before, mapper_state(m))
    m.insert_scan(RANGES, ANGLES, [0.0, 0.0, 0.0])
    assert m.scan_count == before[1] + 1


@pytest.mark.parametrize(("name", "call", "exc", "message"), SCAN_CASES, ids=SCAN_IDS)
def test_odometry_bad_scan_raises_and_changes_nothing(
    name: str, call: Callable[[Callable[..., Any]], Any], exc: type[Exception], message: str
) -> None:
    o = fresh_odometry()
    before = odometry_state(o)
    last = o.last_step
    if name == "range beyond the grid":
        # The loop's default max_range (30 m) skips such a beam; lift it.
        o = ndtgrid.Odometry(config=ndtgrid.OdometryConfig(max_range=np.inf))
        o.step(RANGES, ANGLES)
        before, last = odometry_state(o), o.last_step
        # The loop matches before it inserts: the matcher names the scan's points.
        message = message.replace("ranges: point", "points: point")
    with pytest.raises(exc) as info:
        call(lambda r, a: o.step(r, a, [0.2, 0.0, 0.0]))
    assert str(info.value) == message
    assert equal(before, odometry_state(o))
    assert o.last_step is last


@pytest.mark.parametrize(
    ("pose", "message"),
    [
        ([0.0, 0.0], "pose: expected 3 values [x, y, theta], got shape (2,)"),
        ([0.0, np.nan, 0.0], "pose: expected finite values, got NaN at index 1"),
        ([0.0, 0.0, -np.inf], "pose: expected finite values, got -inf at index 2"),
        (
            [3e7, 0.0, 0.0],
            "ranges: point 0 at (3.0000000141474403e7, -1.994989973208109) m is outside the "
            f"grid's range of {LIMIT}",
        ),
    ],
)
def test_mapper_bad_pose(pose: list[float], message: str) -> None:
    m = fresh_mapper()
    before = mapper_state(m)
    with pytest.raises(ValueError) as info:
        m.insert_scan(RANGES, ANGLES, pose)
    assert str(info.value) == message
    assert equal(before, mapper_state(m))


@pytest.mark.parametrize(
    ("odom", "exc", "message"),
    [
        ([0.0, 0.0], ValueError, "odom: expected 3 values [x, y, theta], got shape (2,)"),
        ([0.0, 0.0, np.nan], ValueError, "odom: expected finite values, got NaN at index 2"),
        ([np.inf, 0.0, 0.0], ValueError, "odom: expected finite values, got inf at index 0"),
        ("abc", TypeError, "odom: expected real numbers (float64), got dtype <U3"),
    ],
)
def test_odometry_bad_odom(odom: Any, exc: type[Exception], message: str) -> None:
    o = fresh_odometry()
    before = odometry_state(o)
    with pytest.raises(exc) as info:
        o.step(RANGES, ANGLES, odom)
    assert str(info.value) == message
    assert equal(before, odometry_state(o))


def test_odometry_odom_jump_beyond_the_grid_falls_back_to_constant_velocity() -> None:
    """Odometry that jumps by 10^9 m (a driver's garbage): the match from the odometry
    prior finds nothing, the constant-velocity prior matches and wins, and the map stays
    where the robot is. The next step's odometry increment is sane again."""
    o = fresh_odometry()
    pose = o.step(RANGES - 0.15, ANGLES, [1e9, 0.0, 0.0])
    assert abs(pose[0] - 0.15) < 0.05 and o.last_step is not None and o.last_step.accepted
    pose = o.step(RANGES - 0.2, ANGLES, [1e9 + 0.05, 0.0, 0.0])
    assert abs(pose[0] - 0.2) < 0.05
    centres, _ = o.grid().cells()
    assert np.abs(centres).max() < 3.0


def test_odometry_pose_beyond_the_grid_is_refused() -> None:
    """With nothing to match (an empty scan's neighbour: no map yet), a first odometry
    pose beyond the grid puts the scan outside it: refused, nothing changes."""
    o = ndtgrid.Odometry()
    with pytest.raises(ValueError) as info:
        o.step(RANGES, ANGLES, [3e7, 0.0, 0.0])
    assert str(info.value) == (
        "ranges: point 0 at (3.0000000141474403e7, -1.994989973208109) m is outside the "
        f"grid's range of {LIMIT}"
    )
    assert o.poses.shape == (0, 3) and o.insertions == 0 and len(o) == 0


def test_odometry_finite_odom_jump_is_taken_as_motion() -> None:
    """A finite jump (the odometry resets or skips) is a motion like any other: no error,
    a finite pose; the constant-velocity prior is tried too (see OdometryConfig)."""
    o = fresh_odometry()
    pose = o.step(RANGES - 0.15, ANGLES, [500.0, -300.0, 2.0])
    assert np.all(np.isfinite(pose)) and o.poses.shape == (4, 3)


INVALID = [np.nan, np.inf, -np.inf, 0.0, -1.0]


@pytest.mark.parametrize("value", INVALID, ids=["nan", "inf", "-inf", "zero", "negative"])
def test_invalid_ranges_are_skipped_beam_by_beam(value: float) -> None:
    ranges = RANGES.copy()
    ranges[::3] = value
    a, b = ndtgrid.Mapper(), ndtgrid.Mapper()
    a.insert_scan(ranges, ANGLES, [0.0, 0.0, 0.0])
    keep = np.ones(181, dtype=bool)
    keep[::3] = False
    b.insert_scan(ranges[keep], ANGLES[keep], [0.0, 0.0, 0.0])
    assert equal(mapper_state(a), mapper_state(b)) and len(a) > 0
    pts = ndtgrid.ranges_to_points(ranges, ANGLES)
    assert np.array_equal(pts, ndtgrid.ranges_to_points(ranges[keep], ANGLES[keep]))


@pytest.mark.parametrize("value", INVALID, ids=["nan", "inf", "-inf", "zero", "negative"])
def test_a_scan_without_a_valid_beam_changes_nothing(value: float) -> None:
    m = fresh_mapper()
    before = mapper_state(m)
    for _ in range(6):  # two check intervals: not counted, so no check runs
        m.insert_scan(np.full(181, value), ANGLES, [0.0, 0.0, 0.0])
        m.insert_scan([], [], [0.0, 0.0, 0.0])
    assert equal(before, mapper_state(m))
    assert ndtgrid.ranges_to_points(np.full(181, value), ANGLES).shape == (0, 2)


def test_odometry_scan_without_a_valid_beam_gives_the_prediction() -> None:
    o = fresh_odometry()
    grid, insertions = o.grid().cell_states(), o.insertions
    pose = o.step(np.full(181, np.nan), ANGLES, [0.15, 0.0, 0.0])
    step = o.last_step
    assert step is not None
    assert not step.matched and not step.inserted and step.num_points == 0
    assert np.array_equal(pose, step.prediction)
    assert o.poses.shape == (4, 3) and o.insertions == insertions
    assert equal(grid, o.grid().cell_states())
    pose = o.step([], [], [0.2, 0.0, 0.0])
    assert o.poses.shape == (5, 3) and np.all(np.isfinite(pose))


MAPPER_OPTION_CASES = [
    ({"reliable_range": -1.0}, "reliable_range: expected a finite length >= 0 m, got -1"),
    ({"cluster_gap": np.nan}, "cluster_gap: expected a finite length >= 0 m, got NaN"),
    ({"min_range": np.inf}, "min_range: expected a finite length >= 0 m, got inf"),
    ({"pass_radius": -0.1}, "pass_radius: expected a finite length >= 0 m, got -0.1"),
    (
        {"cluster_spacing_factor": np.inf},
        "cluster_spacing_factor: expected a finite factor >= 0, got inf",
    ),
    (
        {"min_range": 1.0, "max_range": 0.5},
        "max_range: expected a range > min_range (inf allowed), got 0.5",
    ),
    ({"max_range": np.nan}, "max_range: expected a range > min_range (inf allowed), got NaN"),
    ({"check_interval": 0}, "check_interval: expected an integer >= 1 (scans), got 0"),
    (
        {"check_interval": -1},
        "check_interval: expected a non-negative integer below 2**32, got -1",
    ),
    ({"min_observations": 0}, "min_observations: expected an integer >= 1 (scans), got 0"),
]


@pytest.mark.parametrize(("options", "message"), MAPPER_OPTION_CASES)
def test_bad_mapper_options(options: dict[str, Any], message: str) -> None:
    for build in (lambda: ndtgrid.Mapper(**options), lambda: ndtgrid.MapperOptions(**options)):
        with pytest.raises(ValueError) as info:
            build()
        assert str(info.value) == message


def test_bad_mapper_option_types() -> None:
    with pytest.raises(TypeError) as info:
        ndtgrid.Mapper(foo=1)
    assert str(info.value) == "MapperOptions.__new__() got an unexpected keyword argument 'foo'"
    with pytest.raises(TypeError) as info:
        ndtgrid.Mapper(min_range="a")
    assert str(info.value) == "must be real number, not str"
    with pytest.raises(ValueError) as info:
        ndtgrid.Mapper(0.0)
    assert str(info.value) == "cell_size: expected a finite cell size >= 0.001 m, got 0"


ODOMETRY_CONFIG_CASES = [
    ({"max_range": 0.0}, "max_range: expected a range > min_range, got 0"),
    ({"min_range": -1.0}, "min_range: expected a finite value >= 0, got -1"),
    ({"insert_distance": np.nan}, "insert_distance: expected a finite value >= 0, got NaN"),
    ({"insert_angle": -1.0}, "insert_angle: expected a finite value >= 0, got -1"),
    ({"map_window": -1}, "map_window: expected a non-negative integer below 2**32, got -1"),
    (
        {"match_insert_distance": -0.5},
        "match_insert_distance: expected a finite value >= 0, got -0.5",
    ),
    (
        {"match_insert_angle": np.inf},
        "match_insert_angle: expected a finite value >= 0, got inf",
    ),
    (
        {"match_map_window": -1},
        "match_map_window: expected a non-negative integer below 2**32, got -1",
    ),
    ({"min_match_ratio": 1.5}, "min_match_ratio: expected a fraction in [0, 1], got 1.5"),
    ({"min_match_ratio": np.nan}, "min_match_ratio: expected a fraction in [0, 1], got NaN"),
    ({"rotation_search": -0.1}, "rotation_search: expected a finite value >= 0, got -0.1"),
    (
        {"rotation_step": 0.0},
        "rotation_step: expected a finite angle > 0 rad, at least rotation_search / 1000, got 0",
    ),
    (
        {"rotation_search": 0.17, "rotation_step": 1e-6},
        "rotation_step: expected a finite angle > 0 rad, at least rotation_search / 1000, "
        "got 0.000001",
    ),
    (
        {"prior_gap_distance": np.nan},
        "prior_gap_distance: expected a value >= 0 (inf = never), got NaN",
    ),
    ({"prior_gap_angle": -1.0}, "prior_gap_angle: expected a value >= 0 (inf = never), got -1"),
    (
        {"bootstrap_insertions": -1},
        "bootstrap_insertions: expected a non-negative integer below 2**32, got -1",
    ),
    ({"expansion": 0.0}, "expansion: expected a finite value > 0, got 0"),
    ({"search_radius": -1}, "search_radius: expected a non-negative integer below 2**32, got -1"),
    ({"search_radius": 5000}, "search_radius: expected a radius of at most 1000 cells, got 5000"),
    (
        {"max_iterations": -1},
        "max_iterations: expected a non-negative integer below 2**32, got -1",
    ),
    ({"levels": 0}, f"{LEVELS} 0"),
    ({"levels": 7}, f"{LEVELS} 7"),
    ({"coarse_rotation_search": 4.0}, "rotation_search: expected an angle in [0, pi] rad, got 4"),
    (
        {"coarse_rotation_gate": -0.5},
        "coarse_rotation_gate: expected a fraction >= 0 (inf = the multi-start on every scan), "
        "got -0.5",
    ),
    ({"max_step_cells": np.inf}, "max_step_cells: expected a finite value > 0, got inf"),
    ({"max_step_rotation": 0.0}, "max_step_rotation: expected a finite value > 0, got 0"),
    (
        {"build_map": False, "match_filtered_map": True},
        "match_filtered_map: cannot be on with build_map off: the loop would match against "
        "a map it does not build",
    ),
]


@pytest.mark.parametrize(("config", "message"), ODOMETRY_CONFIG_CASES)
def test_bad_odometry_config(config: dict[str, Any], message: str) -> None:
    with pytest.raises(ValueError) as info:
        ndtgrid.Odometry(config=ndtgrid.OdometryConfig(**config))
    assert str(info.value) == message


def test_bad_odometry_construction() -> None:
    with pytest.raises(ValueError) as info:
        ndtgrid.Odometry(cell_size=-1.0)
    assert str(info.value) == "cell_size: expected a finite cell size >= 0.001 m, got -1"
    with pytest.raises(TypeError) as info:
        ndtgrid.Odometry(config={})  # type: ignore[arg-type]
    assert str(info.value) == "config: expected an OdometryConfig, got dict"


RANGES_TO_POINTS_CASES: list[tuple[Callable[[], Any], type[Exception], str]] = [
    (
        lambda: ndtgrid.ranges_to_points(RANGES, ANGLES[:3]),
        ValueError,
        "angles: expected 181 values (one per range), got 3",
    ),
    (
        lambda: ndtgrid.ranges_to_points(RANGES, np.full(181, np.nan)),
        ValueError,
        "angles: expected finite values, got NaN at index 0",
    ),
    (
        lambda: ndtgrid.ranges_to_points(RANGES, ANGLES, min_range=-1.0),
        ValueError,
        "min_range: expected a finite range >= 0 m, got -1",
    ),
    (
        lambda: ndtgrid.ranges_to_points(RANGES, ANGLES, min_range=np.nan),
        ValueError,
        "min_range: expected a finite range >= 0 m, got NaN",
    ),
    (
        lambda: ndtgrid.ranges_to_points(RANGES, ANGLES, min_range=1.0, max_range=1.0),
        ValueError,
        "max_range: expected a range > min_range, got 1",
    ),
    (
        lambda: ndtgrid.ranges_to_points(RANGES, ANGLES, max_range=np.nan),
        ValueError,
        "max_range: expected a range > min_range, got NaN",
    ),
    (
        lambda: ndtgrid.ranges_to_points(np.zeros((3, 1)), ANGLES),
        ValueError,
        "ranges: expected a 1-D array, got shape (3, 1)",
    ),
    (
        lambda: ndtgrid.ranges_to_points(RANGES, ANGLES.astype(complex)),
        TypeError,
        "angles: expected real numbers (float64), got dtype complex128",
    ),
    (
        lambda: ndtgrid.ranges_to_points(RANGES, np.array([object()] * 181)),
        TypeError,
        "angles: expected real numbers (float64), got dtype object",
    ),
]


@pytest.mark.parametrize(("call", "exc", "message"), RANGES_TO_POINTS_CASES)
def test_bad_ranges_to_points(call: Callable[[], Any], exc: type[Exception], message: str) -> None:
    with pytest.raises(exc) as info:
        call()
    assert str(info.value) == message
