"""Scan matching on real data: 50 consecutive corrected scans of the Intel log.

Reference: the corrected (GMapping) poses, good to a few centimetres. Guess: the
previous corrected pose composed with the raw odometry increment (median about
5 cm / 2.6 deg off). The map is the previous scan alone, inserted at its
corrected pose. Numbers on this machine are in BENCHMARK.md
(``python benches/intel_pairs.py``).
"""

from __future__ import annotations

import numpy as np
import pytest

import ndtgrid
from ndtgrid.evaluation import corrected_pairs, pose_error
from ndtgrid.io import read_benchmark_index, read_carmen
from ndtgrid.presets import PAPER

from ._data import require_real

N_PAIRS = 50
MAX_RANGE = 40.0


@pytest.fixture(scope="module")
def pairs() -> list[ndtgrid.evaluation.ScanPair]:
    log = require_real("radish-gfs-corrected/intel-corrected.log.gz")
    index = read_benchmark_index(
        require_real("benchmark-scans-split/intel__intel-corrected__index.csv")
    )
    scans = list(read_carmen(log))
    out = list(corrected_pairs(scans, index, max_range=MAX_RANGE))
    return out[:N_PAIRS]


def errors(
    pairs: list[ndtgrid.evaluation.ScanPair], cell: float, **options: object
) -> tuple[np.ndarray, ...]:
    guess, match = [], []
    for p in pairs:
        grid = ndtgrid.NdtGrid(cell)
        grid.insert(p.reference_points, p.reference_pose)
        res = grid.match(p.points, p.guess, **options)  # type: ignore[arg-type]
        guess.append(pose_error(p.guess, p.true_pose))
        match.append(pose_error(res.pose, p.true_pose))
    return np.array(guess), np.array(match)


def test_guesses_are_as_described(pairs: list[ndtgrid.evaluation.ScanPair]) -> None:
    guess, _ = errors(pairs[:N_PAIRS], 0.2)
    assert len(pairs) == N_PAIRS
    assert 0.03 < np.median(guess[:, 0]) < 0.08
    assert 1.5 < np.degrees(np.median(guess[:, 1])) < 4.0


def test_matching_beats_the_odometry_guess_on_20cm_grid(
    pairs: list[ndtgrid.evaluation.ScanPair],
) -> None:
    guess, match = errors(pairs, 0.2, **PAPER)
    ok = lambda e: (e[:, 0] < 0.05) & (e[:, 1] < np.radians(1.0))  # noqa: E731
    assert np.median(match[:, 0]) < 0.6 * np.median(guess[:, 0])
    assert np.median(match[:, 1]) < 0.25 * np.median(guess[:, 1])
    assert ok(match).sum() >= 3 * ok(guess).sum()


def test_2cm_default_beats_the_odometry_guess(
    pairs: list[ndtgrid.evaluation.ScanPair],
) -> None:
    # Measured: 36/50 successes (guess 6/50), median 3.0 cm / 0.34 deg
    # (guess 5.1 cm / 2.61 deg); the reference itself is good to a few cm.
    guess, match = errors(pairs, 0.02)
    ok = lambda e: (e[:, 0] < 0.05) & (e[:, 1] < np.radians(1.0))  # noqa: E731
    assert np.median(match[:, 0]) < 0.7 * np.median(guess[:, 0])
    assert np.median(match[:, 1]) < 0.2 * np.median(guess[:, 1])
    assert ok(match).sum() >= 5 * ok(guess).sum()


def test_2cm_paper_method_alone_improves_rotation_only(
    pairs: list[ndtgrid.evaluation.ScanPair],
) -> None:
    # A single 1-degree SICK scan leaves most 2 cm cells with one point: the
    # paper's method alone improves the rotation, not the translation, which is
    # why the default adds the pyramid.
    guess, match = errors(pairs, 0.02, **PAPER)
    assert np.median(match[:, 1]) < 0.85 * np.median(guess[:, 1])
    assert np.median(match[:, 0]) > 0.8 * np.median(guess[:, 0])
