"""ndtgrid.Mapper: each §V step on a constructed scan does what its docstring says, and
the must-show scenarios on the simulator (a moved box, a stick before a wall, speckle)."""

from __future__ import annotations

import numpy as np

import ndtgrid
from ndtgrid import sim

from ._scans import ANGLES, CENTRE, POSE, cells_in, only, stick, wall

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
