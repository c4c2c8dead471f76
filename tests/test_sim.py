"""ndtgrid.sim: worlds, the laser model of §V-A, trajectories and odometry."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ndtgrid import se2, sim

#: A lone wall at x = 2 m, 4 m long.
WALL = sim.World(segments=np.array([[2.0, -2.0, 2.0, 2.0]]))
QUIET = replace(sim.URG04LX, speckle_probability=0.0, dropout=0.0)


def beam_towards(laser: sim.Laser, pose: np.ndarray, point: tuple[float, float]) -> int:
    """Index of the beam whose angle is nearest to the bearing of ``point``."""
    bearing = np.arctan2(point[1] - pose[1], point[0] - pose[0]) - pose[2]
    return int(np.argmin(np.abs(laser.angles - bearing)))


def test_presets_match_the_sensors() -> None:
    urg = sim.URG04LX
    assert urg.num_beams == 683 and len(urg.angles) == 683
    assert urg.angles[0] == pytest.approx(np.radians(-120)) and urg.angles[-1] == pytest.approx(
        np.radians(120)
    )
    assert np.degrees(urg.angle_increment) == pytest.approx(240 / 682)
    assert (urg.range_sigma, urg.max_range, urg.reliable_range, urg.backshift) == (
        0.005,
        4.0,
        0.5,
        0.05,
    )
    sick = sim.SICK_LMS
    assert sick.num_beams == 361 and np.degrees(sick.angle_increment) == pytest.approx(0.5)
    assert sick.backshift == 0.0


def test_scans_are_deterministic_per_seed() -> None:
    room = sim.sticks_room()
    pose = np.array([-1.7, 0.0, 0.2])
    a, angles = sim.URG04LX.scan(room, pose, 5)
    b, _ = sim.URG04LX.scan(room, pose, np.random.default_rng(5))
    c, _ = sim.URG04LX.scan(room, pose, 6)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    np.testing.assert_array_equal(angles, sim.URG04LX.angles)
    poses = sim.trajectory(room.tour)[:5]
    r1, _ = sim.simulate(room, sim.URG04LX, poses, seed=3)
    r2, _ = sim.simulate(room, sim.URG04LX, poses, seed=3)
    np.testing.assert_array_equal(r1, r2)
    assert r1.shape == (5, 683)


def test_range_noise_and_resolution_on_a_flat_wall() -> None:
    pose = np.zeros(3)
    rng = np.random.default_rng(0)
    errors = []
    for _ in range(20):
        r, a = QUIET.scan(WALL, pose, rng)
        ok = (np.abs(a) < np.radians(20)) & (r > 0)
        errors.append(r[ok] - 2.0 / np.cos(a[ok]))
        np.testing.assert_allclose(r[r > 0] * 1000, np.round(r[r > 0] * 1000), atol=1e-9)
    e = np.concatenate(errors)
    assert abs(e.mean()) < 0.0005
    assert e.std() == pytest.approx(0.005, rel=0.1)
    # Beams that miss the wall (and the far ones) return 0 = "no return".
    r, a = QUIET.scan(WALL, pose, 1)
    assert np.all(r[np.abs(a) > np.radians(70)] == 0.0)


def test_mixed_returns_land_behind_a_lone_stick() -> None:
    """Fig. 7(a): the returns at a thin object's edges lie behind it."""
    world = sim.World(segments=np.zeros((0, 4))).with_circle(1.0, 0.0, 0.0075)
    r, _ = replace(QUIET, range_sigma=0.0).scan(world, np.zeros(3), 0)
    hits = r > 0
    assert 1 <= hits.sum() <= 4
    front = 1.0 - 0.0075
    assert np.all(r[hits] >= front - 1e-3)
    # At 1 m the spot (12 mm) is narrower than the stick: the middle beam is direct,
    # the edges are mixed and lie behind the front, at most edge_tail.
    assert r[hits].min() == pytest.approx(front, abs=0.0015)
    assert r[hits].max() > front + 0.01
    assert r[hits].max() <= front + QUIET.edge_tail + 1e-3


def test_a_stick_before_a_wall_is_shifted_back_only_beyond_the_reliable_range() -> None:
    """Fig. 7(b): 5 cm backward beyond 0.5 m, measured correctly within it."""
    world = WALL.with_circle(1.7, 0.0, 0.0075)
    laser = replace(QUIET, range_sigma=0.0)
    for sensor_x, shifted in ((0.0, True), (1.3, False)):
        pose = np.array([sensor_x, 0.0, 0.0])
        r, _ = laser.scan(world, pose, 0)
        k = beam_towards(laser, pose, (1.7, 0.0))
        true_range = 1.7 - 0.0075 - sensor_x
        expected = true_range + (0.05 if shifted else 0.0)
        assert r[k] == pytest.approx(expected, abs=0.002), (sensor_x, r[k])
    # No wall behind within reach: no 5 cm shift, only the mixing of an edge (at 1.7 m
    # the 2.1 cm spot is wider than the stick, so every beam on it is partly covered).
    lone = sim.World(segments=np.zeros((0, 4))).with_circle(1.7, 0.0, 0.0075)
    r, _ = laser.scan(lone, np.zeros(3), 0)
    mixed = r[beam_towards(laser, np.zeros(3), (1.7, 0.0))] - 1.6925
    assert 0.01 < mixed < 0.035


def test_wall_speckle_is_rare_and_off_the_surface() -> None:
    laser = replace(sim.URG04LX, speckle_probability=0.01, dropout=0.0)
    pose = np.zeros(3)
    rng = np.random.default_rng(4)
    off, total = 0, 0
    for _ in range(30):
        r, a = laser.scan(WALL, pose, rng)
        ok = (np.abs(a) < np.radians(40)) & (r > 0)
        err = np.abs(r[ok] - 2.0 / np.cos(a[ok]))
        off += int((err > 0.028).sum())
        total += int(ok.sum())
    # 1 % of beams speckled by 3-20 cm (a 5 mm noise beam beyond 2.8 cm is a 5.6 sigma event).
    assert off / total == pytest.approx(0.01, rel=0.3)


def test_world_geometry() -> None:
    room = sim.sticks_room()
    assert room.sticks.shape == (8, 3)
    assert room.stick_materials == ("wood",) * 6 + ("iron",) * 2
    np.testing.assert_allclose(room.sticks[:6, 2], 0.015)
    np.testing.assert_allclose(room.sticks[6:, 2], 0.013)
    d = room.distance_to_surface([[0.0, -2.0], [0.0, -1.6], room.sticks[0, :2]])
    np.testing.assert_allclose(d, [0.0, 0.4, 0.0075], atol=1e-12)
    moved = room.translated(0.01, -0.02)
    np.testing.assert_allclose(moved.sticks[:, :2] - room.sticks[:, :2], [[0.01, -0.02]] * 8)
    np.testing.assert_allclose(moved.tour - room.tour, [[0.01, -0.02]] * len(room.tour))
    # The tour passes every stick inside the reliable range, and hits nothing.
    poses = sim.trajectory(room.tour)
    for x, y, _ in room.sticks:
        assert np.hypot(poses[:, 0] - x, poses[:, 1] - y).min() < 0.4
    assert room.distance_to_surface(poses[:, :2]).min() > 0.3
    pts = room.surface_points(0.01)
    assert room.distance_to_surface(pts).max() < 1e-9
    with pytest.raises(ValueError, match="circles: expected radii > 0"):
        sim.World(segments=np.zeros((0, 4)), circles=[[0, 0, 0]])


def test_trajectory_steps_and_turns() -> None:
    poses = sim.trajectory([[0, 0], [1, 0], [1, 1]], step=0.05, turn_step=np.radians(5))
    steps = np.hypot(*np.diff(poses[:, :2], axis=0).T)
    turns = np.abs(np.angle(np.exp(1j * np.diff(poses[:, 2]))))
    assert steps.max() <= 0.05 + 1e-12 and turns.max() <= np.radians(5) + 1e-12
    np.testing.assert_allclose(poses[-1], [1, 1, np.pi / 2], atol=1e-12)
    assert len(poses) == 20 + 18 + 20 + 1
    with pytest.raises(ValueError, match="waypoints: expected at least 2 points"):
        sim.trajectory([[0, 0]])


def test_odometry_drifts_with_distance_and_is_seeded() -> None:
    poses = sim.trajectory(sim.sticks_room().tour)
    exact = sim.odometry(poses, drift=0.0)
    np.testing.assert_allclose(exact[:, :2], poses[:, :2], atol=1e-9)
    a = sim.odometry(poses, drift=0.02, seed=1)
    np.testing.assert_array_equal(a, sim.odometry(poses, drift=0.02, seed=1))
    assert not np.array_equal(a, sim.odometry(poses, drift=0.02, seed=2))
    err = np.hypot(*(a[:, :2] - poses[:, :2]).T)
    assert err[0] == 0.0 and err[-1] > 0.05 and err[: len(err) // 10].max() < err.max()
    # Increments, not absolute poses, carry the noise.
    d_true = se2.between(poses[100], poses[101])
    d_odom = se2.between(a[100], a[101])
    assert np.hypot(*(d_odom - d_true)[:2]) < 0.005
    biased = sim.odometry(poses, drift=0.0, bias=0.05)
    assert abs(np.angle(np.exp(1j * (biased[-1, 2] - poses[-1, 2])))) > 0.1
