"""ndtgrid.Mapper: the §V elimination, step by step on constructed scans, and end to end.

Constructed scans use beams at the URG-04LX step (0.352 deg) over +-60 deg; a range of 0 is
"no return". Sticks are placed mid-cell (x = 0.41 m, y offset 0.01 m) so that which cell a
point falls in is not a matter of round-off.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest

import ndtgrid
from ndtgrid import sim

from ._data import require_real

STEP = np.radians(240.0 / 682.0)
ANGLES = np.arange(-170, 171) * STEP  # 341 beams over +-60 deg, beam 170 at 0 deg
CENTRE = 170
POSE = np.array([0.0, 0.01, 0.0])


def wall(distance: float) -> np.ndarray:
    """Ranges to a wall perpendicular to the sensor's x axis."""
    return distance / np.cos(ANGLES)


def stick(ranges: np.ndarray, values: list[float], first: int = CENTRE - 2) -> np.ndarray:
    """``ranges`` with beams ``first, first+1, ...`` replaced by ``values``."""
    out = ranges.copy()
    out[first : first + len(values)] = values
    return out


def cells_in(mapper: ndtgrid.Mapper, x0: float, x1: float, y0: float, y1: float) -> int:
    c = mapper.occupied_cells()
    return int(((c[:, 0] > x0) & (c[:, 0] < x1) & (c[:, 1] > y0) & (c[:, 1] < y1)).sum())


def only(**steps: bool) -> dict[str, bool]:
    """Every step off except the ones named."""
    names = [
        "edge_removal",
        "area1_confirmation",
        "backshift_rejection",
        "observation_check",
        "radial_confirmation",
    ]
    return {n: steps.get(n, False) for n in names}


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
        ({"cell_size": 0.0}, ValueError, "cell_size: expected a finite cell size > 0 m"),
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


# --- each step on a constructed scan -----------------------------------------------------

#: A 1.5 cm stick at 0.41 m (Area 1): three direct returns and two mixed returns behind it.
STICK_NEAR = [0.445, 0.411, 0.410, 0.411, 0.455]


def test_a1_only_clusters_narrower_than_small_object_size_are_small_objects() -> None:
    """a-1: a cluster is a small object when its extent across the beam is at most
    small_object_size (5 cm); wider clusters are stored whole, as big objects."""
    for width_beams, small in ((7, True), (40, False)):  # 1.5 cm and 10 cm at 0.41 m
        first = CENTRE - width_beams // 2
        scan = stick(np.zeros_like(ANGLES), [0.41] * width_beams, first)
        m = ndtgrid.Mapper(**only(edge_removal=True))
        m.insert_scan(scan, ANGLES, POSE)
        assert len(m.small_objects()) == (1 if small else 0)
        stored = int(m.grid.cells()[1].sum())
        assert (stored < width_beams) if small else (stored == width_beams)


def test_a3_drops_points_behind_the_centre_of_mass() -> None:
    """a-2/a-3: in a small cluster the points behind its centre of mass are not stored."""
    scan = stick(np.zeros_like(ANGLES), STICK_NEAR)
    on = ndtgrid.Mapper(**only(edge_removal=True))
    off = ndtgrid.Mapper(**only())
    on.insert_scan(scan, ANGLES, POSE)
    off.insert_scan(scan, ANGLES, POSE)
    # The two mixed returns (4 cm behind) are behind the CoM (at 0.426 m).
    assert on.removal_counts().behind_com_points == 2
    assert on.removal_counts().behind_com_cells == 1
    assert cells_in(on, 0.44, 0.46, -0.1, 0.1) == 0
    assert cells_in(off, 0.44, 0.46, -0.1, 0.1) == 1
    assert on.grid.cells()[1].sum() == 3


def test_a4_keeps_only_the_forefront_cell() -> None:
    """a-4: a small cluster's remaining points are stored in its forefront cell only."""
    # Six returns at 0.41 m whose y runs from -5 mm to +7.5 mm: three in each of two cells.
    # a-3 is neutralised (margin 1 m) so that a-4 acts alone; its cell is the one holding
    # the points' centre of mass (y = +1.2 mm).
    scan = stick(np.zeros_like(ANGLES), [0.41] * 6, CENTRE - 4)
    pose = np.array([0.0, 0.005, 0.0])
    on = ndtgrid.Mapper(**only(edge_removal=True), behind_com_margin=1.0)
    off = ndtgrid.Mapper(**only())
    on.insert_scan(scan, ANGLES, pose)
    off.insert_scan(scan, ANGLES, pose)
    assert len(off) == 2 and len(on) == 1
    counts = on.removal_counts()
    assert (counts.behind_com_points, counts.forefront_points, counts.forefront_cells) == (0, 3, 1)
    (obj,) = on.small_objects()
    assert obj.num_points == 3
    np.testing.assert_allclose(obj.cells, [[0.41, 0.01]], atol=1e-12)


def test_b2_rejects_a_backward_shifted_image_of_a_known_stick() -> None:
    """b-2: in Area 2, a small-cluster point behind a former cell along its beam is not stored."""
    far_pose = np.array([-1.0, 0.01, 0.0])
    # The stick seen from 1.41 m, shifted 5 cm backward (paper, Fig. 7b).
    shifted = stick(np.zeros_like(ANGLES), [1.461, 1.460], CENTRE - 1)
    for steps, expect in ((only(backshift_rejection=True), 0), (only(), 1)):
        m = ndtgrid.Mapper(**steps)
        m.insert_scan(stick(np.zeros_like(ANGLES), [0.411, 0.410, 0.411]), ANGLES, POSE)
        m.insert_scan(shifted, ANGLES, far_pose)
        assert cells_in(m, 0.44, 0.48, -0.1, 0.1) == expect
        assert cells_in(m, 0.40, 0.42, -0.1, 0.1) == 1
        assert m.removal_counts().backshift_points == 2 * (1 - expect)


def test_b1_deletes_small_cells_never_seen_from_area1_at_the_check() -> None:
    """b-1: small-object cells never observed within the reliable range go at the check."""
    far_pose = np.array([-1.0, 0.01, 0.0])
    far_view = stick(np.zeros_like(ANGLES), [1.411, 1.410], CENTRE - 1)
    m = ndtgrid.Mapper(**only(area1_confirmation=True))
    for k in range(3):
        m.insert_scan(far_view, ANGLES, far_pose)
        # Kept until the check after the third scan.
        assert cells_in(m, 0.40, 0.42, -0.1, 0.1) == (1 if k < 2 else 0)
    assert m.removal_counts().area1_cells == 1
    # Seen from Area 1 first: kept.
    m = ndtgrid.Mapper(**only(area1_confirmation=True))
    near_view = stick(np.zeros_like(ANGLES), [0.411, 0.410, 0.411])
    m.insert_scan(near_view, ANGLES, POSE)
    m.insert_scan(far_view, ANGLES, far_pose)
    m.insert_scan(far_view, ANGLES, far_pose)
    assert cells_in(m, 0.40, 0.42, -0.1, 0.1) == 1 and m.removal_counts().area1_cells == 0
    assert len(m.small_objects()) == 1


def test_c_wall_speckle_seen_once_is_gone_after_the_third_scan_check() -> None:
    """c: a cell observed in one scan only is deleted at the check after the third scan."""
    clean = wall(0.41)
    speckled = clean.copy()
    speckled[CENTRE] += 0.08  # one return 8 cm behind the wall (cell x 0.48-0.50), Area 1
    for steps in (None, only(observation_check=True)):
        m = ndtgrid.Mapper(**(steps or {}))
        for k, scan in enumerate([speckled, clean, clean, clean]):
            m.insert_scan(scan, ANGLES, POSE)
            present = cells_in(m, 0.48, 0.50, 0.0, 0.02)
            assert present == (1 if k < 2 else 0), (steps, k)
        assert m.removal_counts().observation_cells == 1
        assert cells_in(m, 0.40, 0.42, -0.3, 0.3) > 20  # the wall stays
    m = ndtgrid.Mapper(**only())
    for scan in [speckled, clean, clean, clean]:
        m.insert_scan(scan, ANGLES, POSE)
    assert cells_in(m, 0.48, 0.50, 0.0, 0.02) == 1


def test_d_removes_cells_a_newer_beam_passed_through() -> None:
    """d: big cells short of a new hit are free space; small ones only in Area 1."""
    box = np.where(np.abs(ANGLES) < np.radians(10), wall(1.0), wall(2.0))
    for steps, expect in ((only(radial_confirmation=True), 0), (only(), 1)):
        m = ndtgrid.Mapper(**steps)
        m.insert_scan(box, ANGLES, POSE)
        m.insert_scan(box, ANGLES, POSE)
        m.insert_scan(wall(2.0), ANGLES, POSE)  # the box has gone
        assert (cells_in(m, 0.98, 1.02, -0.2, 0.2) > 0) == bool(expect)
        assert cells_in(m, 1.98, 2.02, -0.3, 0.3) > 10
    # A small object that has gone: removed when it lies in Area 1 ...
    near = stick(wall(2.0), [0.411, 0.410, 0.411])
    m = ndtgrid.Mapper(**only(radial_confirmation=True))
    m.insert_scan(near, ANGLES, POSE)
    m.insert_scan(wall(2.0), ANGLES, POSE)
    assert cells_in(m, 0.40, 0.42, -0.1, 0.1) == 0
    # ... but not from Area 2, where a beam may slip past a thin object.
    m = ndtgrid.Mapper(**only(radial_confirmation=True))
    m.insert_scan(near, ANGLES, POSE)
    m.insert_scan(wall(2.5), ANGLES, POSE - np.array([0.5, 0.0, 0.0]))
    assert cells_in(m, 0.40, 0.42, -0.1, 0.1) == 1


# --- end to end on the simulator ----------------------------------------------------------


def test_a_box_moved_mid_run_disappears_from_the_map() -> None:
    room = sim.World(
        segments=np.array(
            [[-2.5, -2, 2.5, -2], [2.5, -2, 2.5, 2], [2.5, 2, -2.5, 2], [-2.5, 2, -2.5, -2]]
        )
    )
    with_box = room.with_box(-0.2, -0.15, 0.2, 0.15)
    poses = sim.trajectory(
        [[-1.2, -1.0], [1.2, -1.0], [1.2, 1.0], [-1.2, 1.0], [-1.2, -1.0]], step=0.05
    )
    half = len(poses) // 2
    box_faces = sim.World(segments=with_box.segments[4:])
    remaining = {}
    for name, steps in (("on", {}), ("d off", {"radial_confirmation": False})):
        m = ndtgrid.Mapper(**steps)
        rng = np.random.default_rng(7)
        for k, pose in enumerate(poses):
            ranges, angles = sim.URG04LX.scan(with_box if k < half else room, pose, rng)
            m.insert_scan(ranges, angles, pose)
            if k == half - 1:
                c = m.occupied_cells()
                assert (box_faces.distance_to_surface(c) < 0.02).sum() > 50
        c = m.occupied_cells()
        remaining[name] = int((box_faces.distance_to_surface(c) < 0.02).sum())
        # The walls are all still there.
        on_walls = room.distance_to_surface(c) < 0.02
        assert on_walls.sum() > 600
    assert remaining["on"] == 0
    assert remaining["d off"] > 50


def test_a_stick_before_a_wall_beyond_half_a_metre_is_not_stored_shifted() -> None:
    """Fig. 7(b): seen from 1.5 m the stick reads 5 cm behind; the map keeps it in place."""
    world = sim.World(segments=np.array([[1.2, -1.0, 1.2, 1.0]])).with_circle(
        1.003, 0.011, 0.0075, "wood"
    )
    x, y, _ = world.sticks[0]
    # Pass the stick at 0.35 m, then back off to 1.5 m and look at it for 60 scans.
    near = sim.trajectory([[0.65, -0.4], [0.65, 0.4]], step=0.02)
    far = np.column_stack([np.full(60, -0.5), np.linspace(-0.05, 0.05, 60), np.zeros(60)])
    rng = np.random.default_rng(11)
    shifted = {}
    for name, steps in (
        ("on", {}),
        ("b off", {"backshift_rejection": False, "area1_confirmation": False}),
    ):
        m = ndtgrid.Mapper(**steps)
        for pose in np.vstack([near, far]):
            ranges, angles = sim.URG04LX.scan(world, pose, rng)
            m.insert_scan(ranges, angles, pose)
        c = m.occupied_cells()
        behind = (c[:, 0] > x + 0.02) & (c[:, 0] < x + 0.09) & (np.abs(c[:, 1] - y) < 0.03)
        shifted[name] = int(behind.sum())
        if name == "on":
            near_stick = [o for o in m.small_objects() if np.hypot(*(o.center - (x, y))) < 0.1]
            assert len(near_stick) == 1
            assert np.hypot(*(near_stick[0].center - (x, y))) < 0.015
    assert shifted["on"] == 0
    assert shifted["b off"] >= 1


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
