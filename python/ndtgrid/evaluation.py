"""Accuracy measures for scan matching against reference poses.

Pose arithmetic is the core's (:mod:`ndtgrid.se2`); this module only pairs
scans with their references and summarises errors.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ndtgrid import se2
from ndtgrid.io import BenchmarkIndex, Scan

__all__ = ["ScanPair", "corrected_pairs", "pose_error"]

F64 = npt.NDArray[np.float64]


def pose_error(estimate: npt.ArrayLike, reference: npt.ArrayLike) -> tuple[float, float]:
    """Translation and rotation error of a pose against its reference.

    Parameters
    ----------
    estimate, reference : array_like, shape (3,)
        Poses ``[x, y, theta]`` (m, m, rad) in the same frame.

    Returns
    -------
    translation : float
        Norm of the translation of ``reference^-1 o estimate`` [m].
    rotation : float
        Absolute angle of it [rad], in [0, pi].
    """
    d = se2.between(reference, estimate)
    return float(np.hypot(d[0], d[1])), float(abs(d[2]))


@dataclass(frozen=True, eq=False)
class ScanPair:
    """Two scans of a log with reference poses and an odometry guess.

    Attributes
    ----------
    reference_points : ndarray, shape (N, 2)
        Scan-frame points of the earlier scan (the map) [m].
    reference_pose : ndarray, shape (3,)
        Corrected pose of the earlier scan.
    points : ndarray, shape (M, 2)
        Scan-frame points of the later scan (to match) [m].
    true_pose : ndarray, shape (3,)
        Corrected pose of the later scan: the answer.
    guess : ndarray, shape (3,)
        ``reference_pose`` composed with the raw odometry increment between
        the scans: what a SLAM loop would start from.
    """

    reference_points: F64
    reference_pose: F64
    points: F64
    true_pose: F64
    guess: F64


def corrected_pairs(
    scans: Sequence[Scan],
    index: BenchmarkIndex,
    *,
    gap: int = 1,
    max_range: float | None = None,
) -> Iterator[ScanPair]:
    """Pairs of corrected scans ``gap`` apart, with odometry-increment guesses.

    Parameters
    ----------
    scans : sequence of Scan
        The scans of a corrected log, in order (row ``i`` of ``index``
        describes ``scans[i]``).
    index : BenchmarkIndex
        The index CSV of the log: corrected poses and raw odometry.
    gap : int, default 1
        Distance between the paired scans, in corrected scans.
    max_range : float, optional
        Ranges at or above it are dropped (see :meth:`Scan.points`).

    Yields
    ------
    ScanPair
        One pair per ``i`` in ``0 .. len(scans) - gap - 1``.

    Raises
    ------
    ValueError
        If ``scans`` and ``index`` differ in length or ``gap < 1``.
    """
    if len(scans) != len(index):
        raise ValueError(
            f"scans: expected {len(index)} scans (one per index row), got {len(scans)}"
        )
    if gap < 1:
        raise ValueError(f"gap: expected an integer >= 1, got {gap}")
    for i in range(len(scans) - gap):
        j = i + gap
        increment = se2.between(index.raw_odom[i], index.raw_odom[j])
        yield ScanPair(
            reference_points=scans[i].points(max_range=max_range),
            reference_pose=index.corrected[i],
            points=scans[j].points(max_range=max_range),
            true_pose=index.corrected[j],
            guess=se2.compose(index.corrected[i], increment),
        )
