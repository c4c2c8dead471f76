"""The NdtGrid surface of docs/API.md: names, statistics, matching, threads."""

from __future__ import annotations

import ast
import inspect
import re
import threading
from pathlib import Path

import numpy as np
import pytest

import ndtgrid
from ndtgrid import se2

from ._room import scan


def room_map(cell: float = 0.02) -> ndtgrid.NdtGrid:
    grid = ndtgrid.NdtGrid(cell_size=cell)
    for i, pose in enumerate([(0, 0, 0), (0.3, 0.2, 1.0), (-0.4, -0.3, 2.5), (0.5, -0.5, -1.8)]):
        grid.insert(scan(pose, seed=i), pose)
    return grid


def test_api_names_and_shapes() -> None:
    grid = ndtgrid.NdtGrid(cell_size=0.02)
    assert len(grid) == 0
    assert grid.cell_size == 0.02
    assert ndtgrid.NdtGrid().cell_size == 0.02
    pts = scan((0, 0, 0))
    grid.insert(pts, np.zeros(3))
    centers, counts = grid.cells()
    assert centers.shape == (len(grid), 2) and centers.dtype == np.float64
    assert counts.shape == (len(grid),) and counts.sum() == len(pts)
    res = grid.match(pts, [0.01, 0.0, 0.0])
    assert isinstance(res, ndtgrid.MatchResult)
    assert res.pose.shape == (3,) and res.hessian.shape == (3, 3)
    assert res.covariance.shape == (3, 3)
    assert isinstance(res.converged, bool) and isinstance(res.iterations, int)
    assert isinstance(res.score, float) and isinstance(res.num_matched, int)
    assert 0 < res.num_matched <= len(pts)
    original = grid.match(
        pts, [0.0, 0.0, 0.0], expansion=1.0, neighbor_search=False, fuse_minority=False
    )
    assert original.num_matched > 0
    assert re.fullmatch(
        r"MatchResult\(pose=\[.*\], converged=(True|False), iterations=\d+, "
        r"score=[\d.]+, num_matched=\d+, degenerate=(True|False)\)",
        repr(res),
    )
    assert repr(grid) == f"NdtGrid(cell_size=0.02, cells={len(grid)})"


@pytest.mark.parametrize("cell", [0.02, 0.07, 0.5])
def test_cell_statistics_equal_naive_sums(cell: float) -> None:
    rng = np.random.default_rng(int(cell * 100))
    pts = rng.uniform(-1.5, 1.0, size=(4000, 2)) + np.array([-7.3, 2.9])
    pose = np.array([0.4, -1.1, 0.7])
    grid = ndtgrid.NdtGrid(cell)
    grid.insert(pts[:2500], pose)
    grid.insert(pts[2500:], pose)
    world = se2_apply(pose, pts)
    keys = np.floor(world / cell).astype(np.int64)
    uniq, inv = np.unique(keys, axis=0, return_inverse=True)
    inv = inv.ravel()
    n = np.bincount(inv)
    m = np.stack([np.bincount(inv, world[:, i]) for i in range(2)], axis=1)
    s = np.zeros((len(uniq), 2, 2))
    np.add.at(s, inv, world[:, :, None] * world[:, None, :])
    idx, counts, sums, scatters = grid.cell_statistics()
    assert np.array_equal(idx, uniq) and np.array_equal(counts, n)
    np.testing.assert_allclose(sums, m, rtol=0, atol=1e-9)
    np.testing.assert_allclose(scatters, s, rtol=0, atol=1e-8)
    centers, counts2 = grid.cells()
    np.testing.assert_allclose(centers, (uniq + 0.5) * cell, rtol=0, atol=1e-12)
    assert np.array_equal(counts2, n)


def se2_apply(pose: np.ndarray, pts: np.ndarray) -> np.ndarray:
    c, s = np.cos(pose[2]), np.sin(pose[2])
    return pts @ np.array([[c, s], [-s, c]]) + pose[:2]


@pytest.mark.parametrize("coarse_model", [True, False])
def test_synthetic_scan_recovered_to_a_millimetre(coarse_model: bool) -> None:
    grid = room_map()
    truth = np.array([0.12, -0.08, 0.2])
    pts = scan(truth, seed=99)
    rng = np.random.default_rng(5)
    for _ in range(10):
        guess = truth + np.r_[rng.uniform(-0.04, 0.04, 2), np.radians(rng.uniform(-1, 1))]
        res = grid.match(pts, guess, coarse_model=coarse_model)
        assert res.converged
        err = se2.between(truth, res.pose)
        assert np.hypot(err[0], err[1]) < 1e-3
        assert abs(np.degrees(err[2])) < 0.05


def test_covariance_is_inverse_hessian_at_a_well_constrained_optimum() -> None:
    grid = room_map()
    truth = np.array([0.12, -0.08, 0.2])
    res = grid.match(scan(truth, seed=99), truth + np.array([0.01, 0.01, 0.005]))
    assert np.all(np.linalg.eigvalsh(res.hessian) > 0)
    np.testing.assert_allclose(res.covariance @ res.hessian, np.eye(3), atol=1e-8)


def test_non_contiguous_and_other_real_dtypes_give_the_same_result() -> None:
    grid = room_map()
    truth = np.array([0.12, -0.08, 0.2])
    pts = scan(truth, seed=99)
    guess = truth + np.array([0.02, -0.01, 0.01])
    ref = grid.match(pts, guess).pose
    wide = np.zeros((len(pts), 4))
    wide[:, ::2] = pts
    strided = wide[:, ::2]
    assert not strided.flags["C_CONTIGUOUS"]
    assert np.array_equal(grid.match(strided, guess).pose, ref)
    assert np.array_equal(grid.match(np.asfortranarray(pts), guess).pose, ref)
    assert np.array_equal(grid.match(pts.tolist(), tuple(guess)).pose, ref)
    as32 = pts.astype(np.float32)
    assert np.allclose(grid.match(as32, guess).pose, ref, atol=1e-4)


def test_matching_from_four_threads_equals_serial() -> None:
    grid = room_map()
    rng = np.random.default_rng(11)
    jobs = []
    for i in range(24):
        truth = np.array([rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), rng.uniform(-3, 3)])
        guess = truth + np.r_[rng.uniform(-0.03, 0.03, 2), rng.uniform(-0.02, 0.02)]
        jobs.append((scan(truth, seed=100 + i), guess))
    serial = [grid.match(p, g).pose for p, g in jobs]
    results: list[np.ndarray | None] = [None] * len(jobs)

    def work(k: int) -> None:
        for j in range(k, len(jobs), 4):
            results[j] = grid.match(*jobs[j]).pose

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for a, b in zip(serial, results):
        assert b is not None and np.array_equal(a, b)


def _kw_defaults(fn: ast.stmt) -> dict[str, object]:
    """The keyword-only defaults of a parsed function, as Python values."""
    assert isinstance(fn, ast.FunctionDef)
    return {
        a.arg: ast.literal_eval(d)
        for a, d in zip(fn.args.kwonlyargs, fn.args.kw_defaults)
        if d is not None
    }


def test_documented_defaults_are_the_core_defaults() -> None:
    core = ndtgrid.default_match_options()
    text = ndtgrid.NdtGrid.match.__text_signature__
    assert text is not None
    binding = _kw_defaults(ast.parse(f"def f{text.replace('$self', 'self')}: pass").body[0])
    stub = Path(ndtgrid.__file__).with_name("_core.pyi").read_text()
    tree = ast.parse(stub)
    fn = next(
        n
        for c in tree.body
        if isinstance(c, ast.ClassDef) and c.name == "NdtGrid"
        for n in c.body
        if isinstance(n, ast.FunctionDef) and n.name == "match"
    )
    stub_defaults = _kw_defaults(fn)
    assert set(core) == set(stub_defaults) == set(binding)
    # `help()` and editors show the signature as `inspect` parses its text: the same
    # values (a one-element tuple default read as `1` before Python 3.13).
    shown = inspect.signature(ndtgrid.NdtGrid.match).parameters
    for name, value in binding.items():
        assert shown[name].default == value, name
    # `skip_levels` is documented as None, which asks for the core's default (the
    # implicit match below checks that it is the core's).
    assert stub_defaults.pop("skip_levels") is None
    assert binding.pop("skip_levels") is None
    for name, value in core.items():
        if name != "skip_levels":
            assert stub_defaults[name] == value, name
            assert binding[name] == value, name
    # The signature's text is written out (a tuple default), so also: a match with the
    # binding's own defaults equals one given the core's explicitly (this catches a
    # default that changes this match, e.g. sigma_floor, expansion or skip_levels).
    pts, guess = scan((0.1, 0.0, 0.2), seed=9), np.array([0.12, -0.01, 0.21])
    implicit, explicit = room_map().match(pts, guess), room_map().match(pts, guess, **core)
    assert (implicit.pose.tolist(), implicit.score, implicit.iterations) == (
        explicit.pose.tolist(),
        explicit.score,
        explicit.iterations,
    )


def test_se2_helpers_round_trip() -> None:
    a = np.array([1.0, -2.0, 2.5])
    b = np.array([0.3, 0.4, 1.0])
    c = se2.compose(a, b)
    np.testing.assert_allclose(se2.between(a, c), b, atol=1e-12)
    np.testing.assert_allclose(se2.compose(a, se2.inverse(a)), 0, atol=1e-12)
    assert -np.pi < c[2] <= np.pi


def test_memory_bytes_counts_the_sums_and_the_prepared_distributions() -> None:
    empty = ndtgrid.NdtGrid(0.02).memory_bytes
    grid = room_map()
    sums = grid.memory_bytes
    # Every level's sums: at least one 56-byte record per occupied fine cell.
    assert sums > empty + 56 * len(grid)
    grid.match(scan((0.1, 0.0, 0.2), seed=9), np.array([0.1, 0.0, 0.2]))
    built = grid.memory_bytes
    # The distributions of five levels (4 cm skipped), at least a 64-byte one per fine cell.
    assert built > sums + 64 * len(grid)
    assert built / len(grid) < 2000
    # A second match with the same options adds nothing.
    grid.match(scan((0.1, 0.0, 0.2), seed=9), np.array([0.1, 0.0, 0.2]))
    assert grid.memory_bytes == built


def test_parallel_match_agrees_with_one_thread() -> None:
    grid = room_map()
    truth = np.array([0.1, -0.05, 0.3])
    dense = np.vstack([scan(tuple(truth), seed=s) for s in range(36)])
    assert len(dense) >= 16384
    guess = truth + np.array([0.03, -0.02, 0.02])
    serial = grid.match(dense, guess)
    parallel = grid.match(dense, guess, parallel=True)
    again = grid.match(dense, guess, parallel=True)
    np.testing.assert_array_equal(parallel.pose, again.pose)
    np.testing.assert_allclose(parallel.pose, serial.pose, rtol=0, atol=1e-9)
    np.testing.assert_allclose(parallel.pose, truth, atol=0.01)


def test_skip_levels_passes_over_pyramid_levels() -> None:
    truth = np.array([0.1, 0.0, 0.2])
    pts = scan(tuple(truth), seed=9)
    guess = truth + np.array([0.02, -0.015, 0.01])
    full = room_map().match(pts, guess, skip_levels=())
    skipped = room_map().match(pts, guess, skip_levels=[1, 3])
    for res in (full, skipped):
        np.testing.assert_allclose(res.pose, truth, atol=2e-3)
    assert not np.array_equal(full.pose, skipped.pose)
    # The coarsest matched level (5 of 6) is matched whatever skip_levels says.
    top = room_map().match(pts, guess, skip_levels=[5])
    np.testing.assert_array_equal(top.pose, full.pose)
    # The default (``None``) skips 4 cm, as ``skip_levels=[1]`` does.
    assert ndtgrid.default_match_options()["skip_levels"] == (1,)
    default = room_map().match(pts, guess)
    np.testing.assert_array_equal(default.pose, room_map().match(pts, guess, skip_levels=[1]).pose)
    assert not np.array_equal(default.pose, full.pose)
    for bad in ([0], [12], [-1]):
        with pytest.raises(
            ValueError,
            match=rf"^skip_levels: expected pyramid levels between 1 and 11, got {bad[0]}$",
        ):
            room_map().match(pts, guess, skip_levels=bad)
