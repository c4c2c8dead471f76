"""Robot trajectories through waypoints, and odometry that drifts from them."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import numpy.typing as npt

from ndtgrid import se2
from ndtgrid.sim.laser import Laser
from ndtgrid.sim.world import World

__all__ = ["odometry", "scan_ranges", "simulate", "trajectory"]

F64 = npt.NDArray[np.float64]


def _wrap(a: float) -> float:
    return float((a + np.pi) % (2 * np.pi) - np.pi)


def trajectory(
    waypoints: npt.ArrayLike,
    *,
    step: float = 0.02,
    turn_step: float = float(np.radians(3.0)),
    heading: float | None = None,
) -> F64:
    """Poses of a robot that drives through ``waypoints``, one per scan.

    On each leg the robot first turns in place towards the next waypoint by
    at most ``turn_step`` per scan, then drives straight in steps of ``step``.

    Parameters
    ----------
    waypoints : array_like, shape (W, 2)
        Points to visit in order [m], ``W >= 2``.
    step : float, default 0.02
        Distance driven between scans [m] (0.2 m/s at 10 Hz).
    turn_step : float, default 3 degrees
        Largest turn between scans [rad].
    heading : float, optional
        Initial heading [rad]; defaults to the direction of the first leg.

    Returns
    -------
    ndarray, shape (T, 3)
        Poses ``[x, y, theta]`` (m, m, rad), the first at ``waypoints[0]``.

    Raises
    ------
    ValueError
        If fewer than 2 waypoints are given or a step is not positive.
    """
    w = np.asarray(waypoints, dtype=np.float64).reshape(-1, 2)
    if len(w) < 2:
        raise ValueError(f"waypoints: expected at least 2 points, got {len(w)}")
    if not (step > 0 and turn_step > 0):
        raise ValueError(f"step, turn_step: expected values > 0, got {step}, {turn_step}")
    first = np.arctan2(*(w[1] - w[0])[::-1])
    th = float(first if heading is None else heading)
    poses = [(w[0, 0], w[0, 1], _wrap(th))]
    for a, b in zip(w[:-1], w[1:]):
        d = b - a
        length = float(np.hypot(*d))
        if length == 0.0:
            continue
        target = float(np.arctan2(d[1], d[0]))
        turn = _wrap(target - th)
        n_turn = int(np.ceil(abs(turn) / turn_step))
        for i in range(1, n_turn + 1):
            poses.append((a[0], a[1], _wrap(th + turn * i / n_turn)))
        th = target
        n = max(1, int(np.ceil(length / step)))
        for i in range(1, n + 1):
            p = a + d * (i / n)
            poses.append((p[0], p[1], _wrap(th)))
    return np.array(poses, dtype=np.float64)


def odometry(
    poses: npt.ArrayLike,
    drift: float = 0.02,
    *,
    bias: float = 0.0,
    seed: int = 0,
) -> F64:
    """Dead-reckoning poses: the true motion with relative noise, integrated.

    Each increment ``u = poses[k-1]^-1 o poses[k]`` is corrupted as
    ``(dx, dy) * (1 + e_t)``, ``dtheta * (1 + e_r) + e_w * |(dx, dy)| + bias *
    |(dx, dy)|`` with ``e_t, e_r, e_w ~ N(0, drift)``, and the corrupted
    increments are composed from ``poses[0]``. The error therefore grows with
    the distance driven, as with wheel odometry.

    Parameters
    ----------
    poses : array_like, shape (T, 3)
        True poses.
    drift : float, default 0.02
        Relative standard deviation of the increments (2 % of the distance,
        2 % of the turn, 0.02 rad of heading per metre).
    bias : float, default 0.0
        Systematic heading drift [rad per metre] (unequal wheels).
    seed : int, default 0
        Seed of the noise.

    Returns
    -------
    ndarray, shape (T, 3)
        Odometry poses, ``out[0] == poses[0]``.
    """
    p = np.asarray(poses, dtype=np.float64).reshape(-1, 3)
    if drift < 0:
        raise ValueError(f"drift: expected a value >= 0, got {drift}")
    rng = np.random.default_rng(seed)
    e = rng.normal(0.0, drift, size=(len(p), 3))
    out = np.empty_like(p)
    if len(p) == 0:
        return out
    out[0] = p[0]
    for k in range(1, len(p)):
        dx, dy, dth = se2.between(p[k - 1], p[k])
        dist = float(np.hypot(dx, dy))
        u = [
            dx * (1 + e[k, 0]),
            dy * (1 + e[k, 0]),
            dth * (1 + e[k, 1]) + (e[k, 2] + bias) * dist,
        ]
        out[k] = se2.compose(out[k - 1], u)
    return out


def simulate(
    world: World,
    laser: Laser,
    poses: npt.ArrayLike,
    *,
    seed: int = 0,
) -> tuple[F64, F64]:
    """Scans of ``world`` from every pose.

    Parameters
    ----------
    world : World
        What the laser sees.
    laser : Laser
        The sensor (e.g. :data:`ndtgrid.sim.URG04LX`).
    poses : array_like, shape (T, 3)
        Sensor poses.
    seed : int, default 0
        Seed of the whole run (scan ``k`` uses its own stream).

    Returns
    -------
    ranges : ndarray, shape (T, B)
        Ranges [m], 0 = no return.
    angles : ndarray, shape (B,)
        Beam angles in the sensor frame [rad].
    """
    p = np.asarray(poses, dtype=np.float64).reshape(-1, 3)
    ranges = np.empty((len(p), laser.num_beams))
    for k, r in enumerate(scan_ranges(world, laser, p, seed=seed)):
        ranges[k] = r
    return ranges, laser.angles


def scan_ranges(
    world: World,
    laser: Laser,
    poses: npt.ArrayLike,
    *,
    seed: int = 0,
) -> Iterator[F64]:
    """The ranges of :func:`simulate`, one scan at a time (e.g. behind a progress bar).

    Parameters
    ----------
    world : World
        As for :func:`simulate`.
    laser : Laser
        As for :func:`simulate`.
    poses : array_like, shape (T, 3)
        As for :func:`simulate`.
    seed : int, default 0
        As for :func:`simulate`.

    Yields
    ------
    ndarray, shape (B,)
        Ranges [m] of each pose in turn, 0 = no return: row ``k`` of :func:`simulate`'s
        ``ranges``.
    """
    p = np.asarray(poses, dtype=np.float64).reshape(-1, 3)
    streams = np.random.SeedSequence(seed).spawn(len(p))
    for pose, ss in zip(p, streams):
        yield laser.scan(world, pose, np.random.default_rng(ss))[0]
