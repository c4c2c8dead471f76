"""Tests of ``ndtgrid.Odometry``: tracking, priors, memory bound, config, bad input, real log."""

from __future__ import annotations

import dataclasses
import math
import os
import threading

import numpy as np
import pytest

import ndtgrid
from ndtgrid import se2
from ndtgrid._core import default_odometry_config
from ndtgrid.evaluation import relation_errors
from ndtgrid.io import read_benchmark_index, read_benchmark_split

from ._cpus import TWO_CPUS, needs_two_cpus
from ._room import scan as room_scan

BEAMS = 361


def polar(pose: np.ndarray, seed: int = 0, noise: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Ranges and angles of a 240-degree laser at ``pose`` in the test room."""
    pts = room_scan(pose, beams=BEAMS, noise=noise, seed=seed)
    return np.hypot(pts[:, 0], pts[:, 1]), np.arctan2(pts[:, 1], pts[:, 0])


def trajectory(n: int) -> np.ndarray:
    """A smooth path through the room: 3 cm and about 1 degree per scan."""
    t = np.arange(n, dtype=float)
    return np.stack([-1.0 + 0.03 * t, -0.6 + 0.3 * np.sin(t / 15.0), 0.3 * np.sin(t / 20.0)], 1)


def errors(est: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    d = np.array([se2.between(t, e) for e, t in zip(est, truth)])
    return float(np.max(np.hypot(d[:, 0], d[:, 1]))), float(np.max(np.abs(d[:, 2])))


def test_config_defaults_are_the_cores() -> None:
    py = dataclasses.asdict(ndtgrid.OdometryConfig())
    core = default_odometry_config()
    assert core.pop("cell_size") == 0.02
    assert py.keys() == core.keys()
    for key, value in py.items():
        if isinstance(value, float):
            assert core[key] == pytest.approx(value), key
        else:
            assert core[key] == value, key


def test_tracks_a_path_without_odometry() -> None:
    truth = trajectory(60)
    odo = ndtgrid.Odometry(cell_size=0.02)
    for k, pose in enumerate(truth):
        r, a = polar(pose, seed=k, noise=0.005)
        odo.step(r, a)
    assert odo.poses.shape == (60, 3)
    # The trajectory is expressed in the first scan's frame: compare relative poses.
    est = np.array([se2.between(odo.poses[0], p) for p in odo.poses])
    ref = np.array([se2.between(truth[0], p) for p in truth])
    dt, dr = errors(est, ref)
    assert dt < 0.02 and dr < math.radians(0.5)
    assert 10 <= odo.insertions < 60


def test_odometry_prior_is_used_and_corrected() -> None:
    truth = trajectory(40)
    rng = np.random.default_rng(3)
    # Odometry whose increments are 10 % too long and 1 degree off per scan.
    odom = [truth[0]]
    for a, b in zip(truth[:-1], truth[1:]):
        inc = se2.between(a, b) * [1.1, 1.1, 1.0] + [0, 0, math.radians(1.0)]
        odom.append(se2.compose(odom[-1], inc + rng.normal(0, 0.002, 3)))
    odo = ndtgrid.Odometry()
    for k, (pose, o) in enumerate(zip(truth, odom)):
        r, a = polar(pose, seed=k)
        odo.step(r, a, odom=o)
        step = odo.last_step
        assert step is not None and step.accepted == (k > 0)  # the first scan starts the map
    np.testing.assert_allclose(odo.poses[0], truth[0])  # starts at the first odometry pose
    dt, dr = errors(odo.poses, truth)
    raw_dt, raw_dr = errors(np.array(odom), truth)
    assert dt < 0.02 and dr < math.radians(0.5)
    assert raw_dt > 0.1 and raw_dr > math.radians(20)


def test_multi_start_runs_on_every_scan_or_behind_the_gate() -> None:
    truth = trajectory(30)
    ran = {}
    for gate in (math.inf, 0.8):
        odo = ndtgrid.Odometry(config=ndtgrid.OdometryConfig(coarse_rotation_gate=gate))
        flags = []
        for k, pose in enumerate(truth):
            r, a = polar(pose, seed=k, noise=0.005)
            odo.step(r, a)
            step = odo.last_step
            assert step is not None
            flags.append(step.multi_start)
            assert f"multi_start={step.multi_start}," in repr(step)
        ran[gate] = flags
        est = np.array([se2.between(odo.poses[0], p) for p in odo.poses])
        ref = np.array([se2.between(truth[0], p) for p in truth])
        dt, dr = errors(est, ref)
        assert dt < 0.02 and dr < math.radians(0.5), gate
    # The first scan has no map to match; with the gate, the first 8 accepted
    # matches still run the multi-start, and a smooth path needs it no more.
    assert ran[math.inf] == [False] + [True] * 29
    assert ran[0.8][:9] == [False] + [True] * 8
    assert sum(ran[0.8][9:]) <= 2


def test_map_window_bounds_the_map() -> None:
    truth = trajectory(80)

    # The map (the mapper's) and the matching grid, each with its window.
    def config(window: int) -> ndtgrid.OdometryConfig:
        return ndtgrid.OdometryConfig(
            map_window=window,
            insert_distance=0.02,
            match_map_window=window,
            match_insert_distance=0.02,
        )

    bounded, unbounded = ndtgrid.Odometry(config=config(5)), ndtgrid.Odometry(config=config(0))
    peak, mapped = 0, 0
    for k, pose in enumerate(truth):
        r, a = polar(pose, seed=k, noise=0.01)
        bounded.step(r, a)
        unbounded.step(r, a)
        peak = max(peak, len(bounded))
        mapped = max(mapped, len(bounded.mapper.grid))
    assert peak <= 5 * BEAMS and mapped <= 5 * BEAMS
    assert len(unbounded) > 2 * peak
    assert len(unbounded.mapper.grid) > 2 * mapped
    assert unbounded.grid().cell_size == 0.02 and len(unbounded.grid()) == len(unbounded)


def test_background_mapper_gives_the_same_poses_and_mapper() -> None:
    truth = trajectory(50)
    runs = []
    for background in (False, True):
        config = ndtgrid.OdometryConfig(
            map_window=4, insert_distance=0.02, background_mapper=background
        )
        odo = ndtgrid.Odometry(config=config)
        snapshots = []
        for k, pose in enumerate(truth):
            r, a = polar(pose, seed=k, noise=0.01)
            odo.step(r, a)
            if k % 10 == 9:
                snapshots.append(odo.mapper.to_bytes())
        runs.append((odo.poses, snapshots, odo.mapper.removal_counts().as_dict()))
    (p0, s0, c0), (p1, s1, c1) = runs
    np.testing.assert_array_equal(p0, p1)
    assert len(s0) == 5 and s0 == s1
    assert c0 == c1 and sum(c0.values()) > 0


def test_a_loop_without_a_map_gives_the_same_poses_and_grid() -> None:
    truth = trajectory(40)
    config = dict(map_window=4, insert_distance=0.02)
    full = ndtgrid.Odometry(config=ndtgrid.OdometryConfig(**config))
    bare = ndtgrid.Odometry(config=ndtgrid.OdometryConfig(build_map=False, **config))
    for k, pose in enumerate(truth):
        r, a = polar(pose, seed=k, noise=0.01)
        full.step(r, a)
        bare.step(r, a)
        assert bare.last_step is not None and not bare.last_step.inserted
    np.testing.assert_array_equal(full.poses, bare.poses)
    assert full.insertions > 10 and bare.insertions == 0
    assert bare.grid_insertions == full.grid_insertions > 0
    assert bare.grid().to_bytes() == full.grid().to_bytes()
    assert len(full.mapper.grid) > 0
    with pytest.raises(RuntimeError) as err:
        bare.mapper  # noqa: B018
    assert str(err.value) == (
        "this odometry builds no map (build_map is off): it keeps the poses and the grid "
        "it matches against only"
    )


@pytest.mark.skipif(not hasattr(os, "fork"), reason="os.fork is POSIX only")
def test_forked_child_has_the_whole_mapper_and_goes_on() -> None:
    truth = trajectory(30)
    scans = [polar(pose, seed=k, noise=0.01) for k, pose in enumerate(truth)]
    config = dict(map_window=4, insert_distance=0.02)
    inline = ndtgrid.Odometry(config=ndtgrid.OdometryConfig(background_mapper=False, **config))
    for r, a in scans:
        inline.step(r, a)
    want = inline.mapper.to_bytes()
    odo = ndtgrid.Odometry(config=ndtgrid.OdometryConfig(**config))
    # Fork right after a batch of 8 scans went to the helper (whether it still holds
    # them then is a matter of timing; waiting for it before the fork makes the
    # child's mapper whole either way).
    k = 0
    while k < 8 or odo.insertions % 8:
        odo.step(*scans[k])
        k += 1
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: no helper thread; its mapper goes on in line
        code = 1
        try:
            os.close(read_end)
            for r, a in scans[k:]:
                odo.step(r, a)
            with os.fdopen(write_end, "wb") as f:
                f.write(odo.mapper.to_bytes())
            code = 0
        finally:
            os._exit(code)
    os.close(write_end)
    with os.fdopen(read_end, "rb") as f:
        got = f.read()
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0
    assert got == want
    # The parent's loop is untouched by the child and goes on as well.
    for r, a in scans[k:]:
        odo.step(r, a)
    assert odo.mapper.to_bytes() == want


def test_bad_input_is_rejected_and_leaves_the_loop_unchanged() -> None:
    odo = ndtgrid.Odometry()
    r, a = polar(np.zeros(3))
    odo.step(r, a)
    cells = len(odo)
    with pytest.raises(ValueError, match=r"angles: expected \d+ values \(one per range\), got"):
        odo.step(r, a[1:])
    with pytest.raises(ValueError, match=r"odom: expected 3 values"):
        odo.step(r, a, odom=[0.0, 1.0])
    with pytest.raises(ValueError, match=r"odom: expected finite values, got NaN"):
        odo.step(r, a, odom=[0.0, np.nan, 0.0])
    with pytest.raises(TypeError, match=r"ranges"):
        odo.step("abc", a)
    assert odo.poses.shape == (1, 3) and len(odo) == cells
    with pytest.raises(ValueError, match="min_match_ratio"):
        ndtgrid.Odometry(config=ndtgrid.OdometryConfig(min_match_ratio=2.0))
    with pytest.raises(ValueError, match="max_range"):
        ndtgrid.Odometry(config=ndtgrid.OdometryConfig(max_range=-1.0))
    with pytest.raises(ValueError, match="rotation_step"):
        ndtgrid.Odometry(config=ndtgrid.OdometryConfig(rotation_search=0.17, rotation_step=1e-9))
    with pytest.raises(ValueError, match="cell_size"):
        ndtgrid.Odometry(cell_size=0.0)
    with pytest.raises(
        ValueError, match=r"^translation_tolerance: expected a finite value > 0, got -1$"
    ):
        ndtgrid.Odometry(config=ndtgrid.OdometryConfig(translation_tolerance=-1.0))
    with pytest.raises(
        ValueError, match=r"^rotation_tolerance: expected a finite value > 0, got NaN$"
    ):
        ndtgrid.Odometry(config=ndtgrid.OdometryConfig(rotation_tolerance=math.nan))
    with pytest.raises(TypeError, match="OdometryConfig"):
        ndtgrid.Odometry(config={"max_range": 3.0})  # type: ignore[arg-type]


def drifting_odometry(n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` poses of :func:`trajectory` and an odometry of them drifting by 1 cm and
    0.6 degrees (one sigma) per scan, from the same first pose."""
    truth = trajectory(n)
    rng = np.random.default_rng(5)
    odom = truth + np.cumsum(rng.normal(0.0, [0.01, 0.01, 0.01], truth.shape), axis=0)
    odom[0] = truth[0]
    return truth, odom


def test_stopping_tolerances_reach_the_matcher() -> None:
    # Odometry 1 cm and 0.6 degrees off per scan. With tolerances beyond any Newton step
    # (and no rotational multi-start) every match stops where it starts, so the poses are
    # the odometry's; with the defaults the matches correct them.
    truth, odom = drifting_odometry(25)
    loose = ndtgrid.OdometryConfig(
        translation_tolerance=100.0, rotation_tolerance=100.0, coarse_rotation_search=0.0
    )
    runs = {}
    for name, config in (("loose", loose), ("default", ndtgrid.OdometryConfig())):
        odo = ndtgrid.Odometry(config=config)
        for k, pose in enumerate(truth):
            odo.step(*polar(pose, seed=k, noise=0.003), odom=odom[k])
        runs[name] = odo.poses
    np.testing.assert_allclose(runs["loose"], odom, atol=1e-9)
    assert errors(runs["loose"], truth)[0] > 0.05
    assert errors(runs["default"], truth)[0] < 0.01


def test_skipped_levels_reach_the_matcher() -> None:
    # The loop skips the 4 cm level by default; every level (``skip_levels=()``) gives
    # other poses, and both correct 1 cm / 0.6 degrees per scan of odometry drift.
    truth, odom = drifting_odometry(25)
    assert ndtgrid.OdometryConfig().skip_levels == (1,)
    runs = {}
    for skip in ((1,), (), (1, 3)):
        odo = ndtgrid.Odometry(config=ndtgrid.OdometryConfig(skip_levels=skip))
        assert odo._loop.config()["skip_levels"] == skip
        for k, pose in enumerate(truth):
            odo.step(*polar(pose, seed=k, noise=0.003), odom=odom[k])
        runs[skip] = odo.poses
        assert errors(odo.poses, truth)[0] < 0.01, skip
    assert not np.array_equal(runs[(1,)], runs[()])
    with pytest.raises(
        ValueError, match=r"^skip_levels: expected pyramid levels between 1 and 11, got 0$"
    ):
        ndtgrid.Odometry(config=ndtgrid.OdometryConfig(skip_levels=(0,)))


def test_empty_scans_follow_the_prior() -> None:
    odo = ndtgrid.Odometry()
    angles = np.linspace(-1, 1, 5)
    for x in (0.0, 0.1, 0.3):
        odo.step(np.zeros(5), angles, odom=[x, 0.0, 0.0])
    np.testing.assert_allclose(odo.poses[:, 0], [0.0, 0.1, 0.3])
    assert odo.insertions == 0 and len(odo) == 0
    assert "Odometry(cell_size=0.02, scans=3" in repr(odo)


def test_intel_start_beats_raw_odometry() -> None:
    # The first 2000 raw scans of Intel with raw odometry: relation error on the corrected
    # scans they contain, against the raw odometry's (full-log numbers in BENCHMARK.md).
    from ._data import require_real

    scans = list(read_benchmark_split(require_real("benchmark-scans-split/intel.tar.gz")))[:2000]
    index = read_benchmark_index(
        require_real("benchmark-scans-split/intel__intel-corrected__index.csv")
    )
    odo = ndtgrid.Odometry()
    for s in scans:
        odo.step(s.ranges, s.angles, s.odom)
    keep = index.raw_scan < len(scans)
    ours = relation_errors(odo.poses[index.raw_scan[keep]], index.corrected[keep]).summary()
    raw = np.array([s.odom for s in scans])[index.raw_scan[keep]]
    odom = relation_errors(raw, index.corrected[keep]).summary()
    assert ours.n == 111
    assert ours.translation_mean < 0.75 * odom.translation_mean
    assert ours.rotation_mean < 0.3 * odom.rotation_mean


@needs_two_cpus
def test_the_background_mapper_runs_where_the_thread_that_made_it_may() -> None:
    """The helper starts with the ``Odometry`` and takes the CPU affinity of the thread
    that makes it (as the docs of ``background_mapper`` say): made on a thread pinned to
    one CPU, it is pinned there too; made on this thread, it may run where this one may."""

    def tids() -> set[int]:
        return {int(t) for t in os.listdir("/proc/self/task")}

    def helper_cpus(make: bool, cpu: int | None) -> set[int]:
        made: list[tuple[ndtgrid.Odometry, set[int]]] = []

        def body() -> None:
            if cpu is not None:
                os.sched_setaffinity(0, {cpu})
            before = tids()
            odo = ndtgrid.Odometry(config=ndtgrid.OdometryConfig(background_mapper=make))
            made.append((odo, tids() - before))

        t = threading.Thread(target=body)
        t.start()
        t.join()
        ((odo, new),) = made
        if not make:
            assert new == set()
            return set()
        (helper,) = new
        cpus = os.sched_getaffinity(helper)
        r, a = polar(np.zeros(3))
        odo.step(r, a)  # the loop still runs on another thread than the one that made it
        return cpus

    assert TWO_CPUS is not None
    allowed = os.sched_getaffinity(0)
    first = TWO_CPUS[0]
    assert helper_cpus(True, first) == {first}
    assert helper_cpus(True, None) == allowed
    assert helper_cpus(False, first) == set()
