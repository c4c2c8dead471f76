"""Tests of the relation metric (Kümmerle et al. 2009) in ``ndtgrid.evaluation``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ndtgrid import se2
from ndtgrid.evaluation import associate, relation_errors


def chain(start: list[float], increments: list[list[float]]) -> np.ndarray:
    poses = [np.asarray(start, dtype=float)]
    for inc in increments:
        poses.append(se2.compose(poses[-1], inc))
    return np.array(poses)


INCREMENTS = [[1.0, 0.0, 0.3], [0.5, 0.2, -0.1], [0.8, -0.1, 0.5], [0.2, 0.0, 3.0]]


def test_same_relations_in_another_frame_have_no_error() -> None:
    ref = chain([0, 0, 0], INCREMENTS)
    est = chain([5.0, -2.0, 1.2], INCREMENTS)  # same motion, other start
    e = relation_errors(est, ref)
    np.testing.assert_allclose(e.translation, 0.0, atol=1e-12)
    np.testing.assert_allclose(e.rotation, 0.0, atol=1e-9)
    np.testing.assert_array_equal(e.pairs, [[0, 1], [1, 2], [2, 3], [3, 4]])


def test_errors_are_the_component_wise_difference_of_the_relations() -> None:
    ref = chain([0, 0, 0], INCREMENTS)
    bad = [list(i) for i in INCREMENTS]
    bad[1] = [0.5 + 0.03, 0.2 - 0.04, -0.1 + math.radians(2.0)]
    bad[3] = [0.2, 0.0, 3.0 + math.radians(1.0)]  # crosses +-pi: wrapped
    e = relation_errors(chain([1, 1, 1], bad), ref)
    np.testing.assert_allclose(e.translation, [0.0, 0.05, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(e.rotation, [0.0, 2.0, 0.0, 1.0], atol=1e-9)
    s = e.summary()
    assert s.n == 4
    assert s.translation_mean == pytest.approx(0.0125)
    assert s.translation_std == pytest.approx(np.std([0, 0.05, 0, 0]))
    assert s.translation_max == pytest.approx(0.05)
    assert s.rotation_mean == pytest.approx(0.75)
    assert s.rotation_max == pytest.approx(2.0)
    assert "translation 0.013 ± 0.022 m (max 0.050)" in str(s)


def test_pairs_select_relations_and_are_checked() -> None:
    ref = chain([0, 0, 0], INCREMENTS)
    est = ref.copy()
    est[4] = se2.compose(est[4], [0.1, 0.0, 0.0])
    e = relation_errors(est, ref, pairs=[[0, 4], [0, 2]])
    np.testing.assert_allclose(e.translation, [0.1, 0.0], atol=1e-12)
    with pytest.raises(ValueError, match=r"pairs: expected indices in \[0, 5\)"):
        relation_errors(est, ref, pairs=[[0, 5]])
    with pytest.raises(ValueError, match=r"same shape \(K, 3\)"):
        relation_errors(est[:3], ref)
    empty = relation_errors(est[:1], ref[:1]).summary()
    assert empty.n == 0 and math.isnan(empty.translation_mean)


def test_associate_takes_the_nearest_time_within_the_gap() -> None:
    times = [0.0, 1.0, 2.0, 3.0]
    np.testing.assert_array_equal(
        associate(times, [0.02, 1.6, 2.96, 7.0, -0.04], max_dt=0.05), [0, -1, 3, -1, 0]
    )
    np.testing.assert_array_equal(associate(times, [1.4, 1.6], max_dt=0.5), [1, 2])
    with pytest.raises(ValueError, match="non-decreasing"):
        associate([1.0, 0.0], [0.0], max_dt=1.0)


def test_anchored_errors_ignore_where_each_trajectory_starts() -> None:
    from ndtgrid.evaluation import anchored_errors

    rng = np.random.default_rng(4)
    ref = np.cumsum(rng.normal(0.0, 0.1, size=(30, 3)), axis=0)
    # The same motion seen from another frame: no error at any pose.
    moved = np.array([se2.compose([2.0, -1.0, 0.7], p) for p in ref])
    np.testing.assert_allclose(anchored_errors(moved, ref), 0.0, atol=1e-12)
    # An estimate that is off by 5 cm sideways (in the anchored frame) from pose 10 on.
    anchored = np.array([se2.between(ref[0], p) for p in ref])
    off = anchored.copy()
    off[10:, 1] += 0.05
    est = np.array([se2.compose(moved[0], p) for p in off])
    errors = anchored_errors(est, ref)
    np.testing.assert_allclose(errors[:10], 0.0, atol=1e-12)
    np.testing.assert_allclose(errors[10:], 0.05, atol=1e-12)


@pytest.mark.parametrize(
    ("estimate", "reference"),
    [(np.zeros((4, 3)), np.zeros((5, 3))), (np.zeros((4, 2)), np.zeros((4, 2))), ([], [])],
)
def test_anchored_errors_check_shapes(estimate: object, reference: object) -> None:
    from ndtgrid.evaluation import anchored_errors

    e, r = np.asarray(estimate, dtype=float), np.asarray(reference, dtype=float)
    with pytest.raises(ValueError) as info:
        anchored_errors(estimate, reference)  # type: ignore[arg-type]
    assert str(info.value) == (
        "estimate, reference: expected two (T, 3) arrays of the same T >= 1, got "
        f"{e.shape} and {r.shape}"
    )
