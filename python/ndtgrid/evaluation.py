"""Accuracy measures for scan matching against reference poses.

Pose arithmetic is the core's (:mod:`ndtgrid.se2`); this module only pairs
scans with their references and summarises errors.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ndtgrid import se2
from ndtgrid.io import BenchmarkIndex, Scan

__all__ = [
    "RelationErrors",
    "RelationSummary",
    "ScanPair",
    "anchored_errors",
    "associate",
    "corrected_pairs",
    "pose_error",
    "relation_errors",
]

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


def anchored_errors(estimate: npt.ArrayLike, reference: npt.ArrayLike) -> F64:
    """Position error of each pose once both trajectories start at their own first pose.

    For an odometry whose frame is its first reading: both trajectories are expressed
    in the frame of their first pose (``first^-1 o pose``), then compared pose by pose.

    Parameters
    ----------
    estimate, reference : array_like, shape (T, 3)
        Poses ``[x, y, theta]`` (m, m, rad), row ``i`` of each for the same time.

    Returns
    -------
    ndarray, shape (T,)
        Distance between the anchored positions [m] (0 for the first pose).

    Raises
    ------
    ValueError
        If the two are not (T, 3) arrays of the same length, T >= 1.
    """
    est = np.asarray(estimate, dtype=np.float64)
    ref = np.asarray(reference, dtype=np.float64)
    if est.ndim != 2 or est.shape[1:] != (3,) or est.shape != ref.shape or len(est) == 0:
        raise ValueError(
            "estimate, reference: expected two (T, 3) arrays of the same T >= 1, got "
            f"{est.shape} and {ref.shape}"
        )
    a = np.array([se2.between(est[0], p) for p in est])
    b = np.array([se2.between(ref[0], p) for p in ref])
    return np.asarray(np.hypot(*(a[:, :2] - b[:, :2]).T), dtype=np.float64)


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


# ----------------------------------------------------------- relation metric (Kümmerle 2009)


@dataclass(frozen=True)
class RelationSummary:
    """Summary of relation errors (Kümmerle et al. 2009).

    Attributes
    ----------
    n : int
        Number of relations.
    translation_mean, translation_std, translation_max : float
        Mean, standard deviation (population, ``ddof=0``) and maximum of the
        translational error [m].
    rotation_mean, rotation_std, rotation_max : float
        The same for the rotational error [deg].
    """

    n: int
    translation_mean: float
    translation_std: float
    translation_max: float
    rotation_mean: float
    rotation_std: float
    rotation_max: float

    def __str__(self) -> str:
        return (
            f"translation {self.translation_mean:.3f} ± {self.translation_std:.3f} m "
            f"(max {self.translation_max:.3f}), rotation {self.rotation_mean:.2f} ± "
            f"{self.rotation_std:.2f} deg (max {self.rotation_max:.2f}), n = {self.n}"
        )


@dataclass(frozen=True, eq=False)
class RelationErrors:
    """Per-relation errors of an estimate against a reference.

    Attributes
    ----------
    pairs : ndarray of int64, shape (R, 2)
        Indices ``(i, j)`` of the poses each relation links.
    translation : ndarray, shape (R,)
        ``hypot(dx, dy)`` of the component-wise difference ``delta`` [m].
    rotation : ndarray, shape (R,)
        ``|dtheta|`` of ``delta``, wrapped to [0, 180] [deg].
    """

    pairs: npt.NDArray[np.int64]
    translation: F64
    rotation: F64

    def summary(self) -> RelationSummary:
        """Mean ± std and max of both errors.

        Returns
        -------
        RelationSummary
            Translation [m] and rotation [deg] statistics and the number of relations
            (NaN statistics when there is none).
        """

        def stats(v: F64) -> tuple[float, float, float]:
            if v.size == 0:
                return math.nan, math.nan, math.nan
            return float(v.mean()), float(v.std()), float(v.max())

        t, r = stats(self.translation), stats(self.rotation)
        return RelationSummary(len(self.translation), *t, *r)


def relation_errors(
    estimate: npt.ArrayLike,
    reference: npt.ArrayLike,
    pairs: npt.ArrayLike | None = None,
) -> RelationErrors:
    """The relation metric of Kümmerle et al. (2009) on pairs of poses.

    For each pair ``(i, j)`` the relative motions ``est_ij = estimate[i]^-1 o estimate[j]``
    and ``ref_ij = reference[i]^-1 o reference[j]`` are compared component-wise:
    ``delta = est_ij - ref_ij`` with the angle wrapped to (-pi, pi]. The translational
    error is ``hypot(delta_x, delta_y)`` [m], the rotational ``|delta_theta|`` [deg]
    (the weights ``{1,1,1,0,0,0}`` and ``{0,0,0,1,1,1}`` of the original tool).

    Parameters
    ----------
    estimate, reference : array_like, shape (K, 3)
        Poses ``[x, y, theta]`` (m, m, rad) of the same K instants, each in its own frame
        (relations do not depend on it).
    pairs : array_like of int, shape (R, 2), optional
        Indices of the related poses; by default consecutive ones, ``(i, i + 1)``.

    Returns
    -------
    RelationErrors
        Per-relation errors; ``.summary()`` gives mean ± std, max and n.

    Raises
    ------
    ValueError
        If the shapes differ or are not (K, 3), or a pair index is out of range.
    """
    est = np.asarray(estimate, dtype=np.float64)
    ref = np.asarray(reference, dtype=np.float64)
    if est.ndim != 2 or est.shape[1:] != (3,) or est.shape != ref.shape:
        raise ValueError(
            f"estimate, reference: expected two arrays of the same shape (K, 3), got "
            f"{est.shape} and {ref.shape}"
        )
    k = est.shape[0]
    if pairs is None:
        idx = np.stack([np.arange(k - 1), np.arange(1, k)], axis=1).reshape(-1, 2)
    else:
        idx = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
        if idx.size and (idx.min() < 0 or idx.max() >= k):
            raise ValueError(f"pairs: expected indices in [0, {k}), got {idx.min()}..{idx.max()}")
    trans = np.empty(len(idx))
    rot = np.empty(len(idx))
    for n, (i, j) in enumerate(idx):
        e = se2.between(est[i], est[j])
        r = se2.between(ref[i], ref[j])
        # Angle difference wrapped by the core: theta of (0,0,r)^-1 o (0,0,e).
        dtheta = se2.between([0.0, 0.0, r[2]], [0.0, 0.0, e[2]])[2]
        trans[n] = math.hypot(e[0] - r[0], e[1] - r[1])
        rot[n] = abs(math.degrees(dtheta))
    return RelationErrors(pairs=idx.astype(np.int64), translation=trans, rotation=rot)


def associate(
    times: npt.ArrayLike, reference_times: npt.ArrayLike, *, max_dt: float
) -> npt.NDArray[np.int64]:
    """For each reference time, the index of the nearest estimate time.

    Parameters
    ----------
    times : array_like, shape (T,)
        Times of the estimated poses, increasing [s] (or scan indices).
    reference_times : array_like, shape (K,)
        Times of the reference poses.
    max_dt : float
        Largest admissible gap [same unit].

    Returns
    -------
    ndarray of int64, shape (K,)
        Index into ``times`` per reference time, or -1 where the nearest is farther than
        ``max_dt``.

    Raises
    ------
    ValueError
        If ``times`` is empty or not increasing.
    """
    t = np.asarray(times, dtype=np.float64)
    ref = np.asarray(reference_times, dtype=np.float64)
    if t.size == 0 or np.any(np.diff(t) < 0) or not np.all(np.isfinite(t)):
        raise ValueError("times: expected finite, non-decreasing times, at least one")
    right = np.clip(np.searchsorted(t, ref), 0, t.size - 1)
    left = np.clip(right - 1, 0, t.size - 1)
    nearest = np.where(np.abs(t[left] - ref) <= np.abs(t[right] - ref), left, right)
    ok = np.abs(t[nearest] - ref) <= max_dt
    return np.where(ok, nearest, -1).astype(np.int64)
