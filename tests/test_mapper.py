"""ndtgrid.Mapper: the surface of docs/API.md, one map shared with mapper.grid, bad input,
threads, and the real URG-04LX log. The §V steps one by one: test_mapper_steps.py."""

from __future__ import annotations

import threading

import numpy as np
import pytest

import ndtgrid
from ndtgrid import sim

from ._data import require_real
from ._scans import ANGLES, POSE, cells_in, stick, wall

# --- the surface of docs/API.md ----------------------------------------------------------


def test_api_names_defaults_and_repr() -> None:
    m = ndtgrid.Mapper()
    assert m.cell_size == 0.02 and len(m) == 0 and m.scan_count == 0
    assert isinstance(m.grid, ndtgrid.NdtGrid)
    assert isinstance(m.options, ndtgrid.MapperOptions)
    assert m.options.as_dict() == ndtgrid.default_mapper_options()
    assert m.options == ndtgrid.MapperOptions()
    o = m.options
    assert (o.reliable_range, o.check_interval, o.min_observations) == (0.5, 3, 2)
    assert (o.backshift_window, o.small_object_size, o.cluster_gap) == (0.10, 0.05, 0.05)
    assert o.outlier_filter and o.edge_removal and o.radial_confirmation
    assert o.max_range == np.inf and o.min_range == 0.0
    assert not ndtgrid.Mapper(outlier_filter=False).options.outlier_filter
    assert ndtgrid.Mapper(0.05, reliable_range=0.8).options.reliable_range == 0.8
    changed = o.replace(edge_removal=False, check_interval=5)
    assert not changed.edge_removal and changed.check_interval == 5 and o.edge_removal
    assert repr(m) == "Mapper(cell_size=0.02, outlier_filter=True, scans=0, cells=0)"
    assert repr(o).startswith("MapperOptions(outlier_filter=True, edge_removal=True,")
    counts = m.removal_counts()
    assert isinstance(counts, ndtgrid.RemovalCounts)
    assert set(counts.as_dict()) == {
        "behind_com_points",
        "behind_com_cells",
        "forefront_points",
        "forefront_cells",
        "area1_cells",
        "backshift_points",
        "backshift_cells",
        "observation_cells",
        "confirmation_cells",
    }
    assert sum(counts.as_dict().values()) == 0
    assert m.small_objects() == [] and m.occupied_cells().shape == (0, 2)


@pytest.mark.parametrize(
    ("kwargs", "exc", "message"),
    [
        ({"reliable_range": -0.5}, ValueError, "reliable_range: expected a finite length >= 0 m"),
        ({"max_range": 0.0}, ValueError, "max_range: expected a range > min_range"),
        ({"check_interval": 0}, ValueError, "check_interval: expected an integer >= 1"),
        ({"min_observations": -1}, ValueError, "min_observations: expected a non-negative"),
        ({"pass_radius": float("nan")}, ValueError, "pass_radius: expected a finite length"),
        ({"cell_size": 0.0}, ValueError, "cell_size: expected a finite cell size >= 0.001 m"),
        ({"no_such_option": 1}, TypeError, "no_such_option"),
    ],
)
def test_bad_options_are_named(
    kwargs: dict[str, float], exc: type[Exception], message: str
) -> None:
    with pytest.raises(exc, match=message):
        ndtgrid.Mapper(**kwargs)


def test_grid_is_the_mappers_map_not_a_copy() -> None:
    m = ndtgrid.Mapper()
    grid = m.grid
    assert m.grid is grid
    m.insert_scan(wall(1.0), ANGLES, POSE)
    assert len(grid) == len(m) > 0
    centres, _ = grid.cells()
    np.testing.assert_array_equal(centres, m.occupied_cells())
    # Matching against it sees the scan: the same scan matches back onto itself.
    pts = ndtgrid.ranges_to_points(wall(1.0), ANGLES)
    res = grid.match(pts, POSE + np.array([0.01, -0.005, 0.0]))
    assert res.num_matched == len(pts)
    # ... and sees removals: step d empties the wall's cells when it is gone.
    before = len(grid)
    m.insert_scan(wall(1.0), ANGLES, POSE)
    m.insert_scan(wall(2.0), ANGLES, POSE)
    assert m.removal_counts().confirmation_cells > 0
    assert cells_in(m, 0.9, 1.1, -1, 1) == 0 and len(grid) == len(m) != before
    # Points inserted into the grid directly show in the mapper.
    grid.insert(np.array([[5.0, 5.0]]), np.zeros(3))
    assert cells_in(m, 4.9, 5.1, 4.9, 5.1) == 1
    # The grid outlives the mapper.
    del m
    assert len(grid) > 0


def test_unfiltered_equals_plain_insertion() -> None:
    rng = np.random.default_rng(3)
    plain = ndtgrid.NdtGrid(0.02)
    m = ndtgrid.Mapper(0.02, outlier_filter=False, max_range=3.0)
    room = sim.sticks_room()
    for k in range(5):
        pose = np.array([-1.0 + 0.1 * k, 0.2, 0.3 * k])
        ranges, angles = sim.URG04LX.scan(room, pose, rng)
        ranges[::37] = np.nan
        ranges[5::41] = np.inf
        m.insert_scan(ranges, angles, pose)
        plain.insert(ndtgrid.ranges_to_points(ranges, angles, max_range=3.0), pose)
    for a, b in zip(m.grid.cell_statistics(), plain.cell_statistics()):
        np.testing.assert_array_equal(a, b)
    assert sum(m.removal_counts().as_dict().values()) == 0 and m.scan_count == 5


def test_invalid_ranges_are_skipped() -> None:
    m = ndtgrid.Mapper(outlier_filter=False, min_range=0.1, max_range=4.0)
    r = wall(1.0)
    r[[10, 20, 30, 40, 50, 60]] = [0.0, np.nan, np.inf, 4.0, 0.05, -1.0]
    m.insert_scan(r, ANGLES, POSE)
    assert m.grid.cells()[1].sum() == len(r) - 6


@pytest.mark.parametrize(
    ("ranges", "angles", "pose", "exc", "message"),
    [
        (np.ones(5), np.zeros(6), POSE, ValueError, r"angles: expected 5 values \(one per range\)"),
        (np.ones(3), [0.0, np.nan, 0.1], POSE, ValueError, "angles: expected finite values"),
        (np.ones(3), [0.0, 0.1, 0.2], [0.0, 0.0], ValueError, r"pose: expected 3 values"),
        (np.ones(3), [0.0, 0.1, 0.2], [0, np.inf, 0], ValueError, "pose: expected finite values"),
        (np.ones((3, 2)), np.zeros(3), POSE, ValueError, r"ranges: expected a 1-D array"),
        (["a", "b"], [0.0, 0.1], POSE, TypeError, "ranges: expected real numbers"),
        (None, [0.0], POSE, TypeError, "ranges: expected"),
        (
            [1.0, 1e300],
            [0.0, 0.1],
            POSE,
            ValueError,
            "ranges: point 1 at .*cell index would overflow",
        ),
    ],
)
def test_bad_input_raises_and_changes_nothing(
    ranges: object, angles: object, pose: object, exc: type[Exception], message: str
) -> None:
    m = ndtgrid.Mapper()
    for _ in range(2):
        m.insert_scan(stick(wall(1.0), [0.41, 0.41]), ANGLES, POSE)
    before = (m.grid.cell_statistics(), m.removal_counts().as_dict(), m.scan_count)
    with pytest.raises(exc, match=message):
        m.insert_scan(ranges, angles, pose)  # type: ignore[arg-type]
    after = (m.grid.cell_statistics(), m.removal_counts().as_dict(), m.scan_count)
    assert all(np.array_equal(a, b) for a, b in zip(before[0], after[0]))
    assert before[1:] == after[1:]


def test_threads_match_while_another_inserts() -> None:
    room = sim.sticks_room()
    poses = sim.trajectory(room.tour[:3], step=0.05)[:40]
    scans = [sim.URG04LX.scan(room, p, k) for k, p in enumerate(poses)]
    m = ndtgrid.Mapper()
    m.insert_scan(*scans[0], poses[0])
    errors: list[BaseException] = []
    matched: list[int] = []

    def reader() -> None:
        try:
            pts = ndtgrid.ranges_to_points(*scans[0])
            for _ in range(20):
                matched.append(m.grid.match(pts, poses[0]).num_matched)
                m.occupied_cells()
                m.small_objects()
        except BaseException as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=reader) for _ in range(3)]
    for t in threads:
        t.start()
    for scan, pose in zip(scans[1:], poses[1:]):
        m.insert_scan(*scan, pose)
    for t in threads:
        t.join()
    assert not errors and len(matched) == 60 and min(matched) > 100
    assert m.scan_count == 40


def test_real_urg04lx_log_stationary_start() -> None:
    """The first 15 scans of the MinesRover log (the robot stands still): the filtered map
    is a strict subset of the unfiltered one, and every step removes something."""
    path = require_real("breezyslam-mines-urg04lx/exp1.dat")
    lines = path.read_text().splitlines()[:15]
    # Format in the log's SOURCE.md: tokens 24..705 are 682 ranges in mm, 0 = no return;
    # 70 beams at each end see the robot's body.
    ranges = np.array([line.split()[24:706] for line in lines], dtype=float) / 1000.0
    ranges[:, :70] = 0.0
    ranges[:, -70:] = 0.0
    angles = np.radians(-120.0 + np.arange(682) * 240.0 / 681.0)
    maps = {}
    for name, flag in (("off", False), ("on", True)):
        m = ndtgrid.Mapper(outlier_filter=flag, min_range=0.1, max_range=5.0)
        for r in ranges:
            m.insert_scan(r, angles, np.zeros(3))
        maps[name] = m
    off = {tuple(c) for c in np.round(maps["off"].occupied_cells(), 6)}
    on = {tuple(c) for c in np.round(maps["on"].occupied_cells(), 6)}
    assert on < off and len(on) < 0.9 * len(off)
    counts = maps["on"].removal_counts().as_dict()
    assert all(v > 0 for v in counts.values()), counts
