"""One laser scan read from a log file: ranges, bearings, poses and where it came from."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

__all__ = ["Scan"]


def _as_vector(name: str, value: object) -> npt.NDArray[np.float64]:
    """Return ``value`` as a 1-D float64 array, or raise ``ValueError`` naming ``name``."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"Scan.{name} must be a 1-D array of numbers, got {type(value).__name__}: {exc}"
        ) from None
    if array.ndim != 1:
        raise ValueError(f"Scan.{name} must be 1-D, got shape {array.shape}")
    return array


def _as_pose(name: str, value: object) -> npt.NDArray[np.float64] | None:
    """Return ``value`` as a (3,) float64 pose, ``None`` unchanged, or raise ``ValueError``."""
    if value is None:
        return None
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"Scan.{name} must be None or an (x, y, theta) array, got {type(value).__name__}: {exc}"
        ) from None
    if array.shape != (3,):
        raise ValueError(f"Scan.{name} must have shape (3,) = (x, y, theta), got {array.shape}")
    return array


def _fmt_pose(pose: npt.NDArray[np.float64] | None) -> str:
    if pose is None:
        return "None"
    return "[" + ", ".join(f"{v:.6g}" for v in pose) + "]"


@dataclass(frozen=True, eq=False, repr=False)
class Scan:
    """One 2-D laser scan as logged, in the sensor frame.

    Beam ``i`` is the point ``ranges[i] * (cos(angles[i]), sin(angles[i]))`` in the laser
    frame (x forward, y left, angles counter-clockwise). Readings at the sensor's maximum
    (``max_range`` when known, e.g. 81.83 m for a SICK LMS "no return") are kept as logged;
    drop them before matching.

    Parameters
    ----------
    timestamp : float
        Time of the scan in seconds (for CARMEN logs the ``ipc_timestamp`` field).
    ranges : numpy.ndarray
        float64 array of shape (B,), metres, one per beam.
    angles : numpy.ndarray
        float64 array of shape (B,), radians, bearing of each beam in the sensor frame.
    odom : numpy.ndarray or None
        Shape (3,) pose ``[x, y, theta]`` (m, m, rad) of the robot at this scan, as logged
        (odometry, or a corrected pose in "corrected" logs); ``None`` when the log has none.
    laser_pose : numpy.ndarray or None
        Shape (3,) pose ``[x, y, theta]`` of the laser as logged, or ``None``.
    max_range : float or None
        Maximum range of the sensor in metres when the message states it, else ``None``.
    source : str
        Kind of message the scan came from, e.g. ``"FLASER"`` or ``"ROBOTLASER1"``.
    line : int
        1-based line number of the message in its file (0 when not read from a file).

    Raises
    ------
    ValueError
        If ``ranges`` or ``angles`` is not 1-D, their lengths differ, a pose is not of
        shape (3,), or ``timestamp``/``max_range``/``line`` is not a number.

    Notes
    -----
    The object is frozen (its fields cannot be reassigned) and compares by identity. The
    arrays are float64 copies only when the input was not float64 already.
    """

    timestamp: float
    ranges: npt.NDArray[np.float64]
    angles: npt.NDArray[np.float64]
    odom: npt.NDArray[np.float64] | None = None
    laser_pose: npt.NDArray[np.float64] | None = None
    max_range: float | None = None
    source: str = ""
    line: int = 0

    def __post_init__(self) -> None:
        ranges = _as_vector("ranges", self.ranges)
        angles = _as_vector("angles", self.angles)
        if ranges.shape != angles.shape:
            raise ValueError(
                "Scan.ranges and Scan.angles must have the same length, got "
                f"{ranges.shape[0]} ranges and {angles.shape[0]} angles"
            )
        try:
            timestamp = float(self.timestamp)
        except (TypeError, ValueError):
            raise ValueError(
                f"Scan.timestamp must be a number of seconds, got {self.timestamp!r}"
            ) from None
        max_range: float | None = None
        if self.max_range is not None:
            try:
                max_range = float(self.max_range)
            except (TypeError, ValueError):
                raise ValueError(
                    f"Scan.max_range must be None or a number of metres, got {self.max_range!r}"
                ) from None
            if math.isnan(max_range) or max_range <= 0.0:
                raise ValueError(f"Scan.max_range must be > 0 m, got {max_range!r}")
        if not isinstance(self.source, str):
            raise ValueError(f"Scan.source must be a str, got {type(self.source).__name__}")
        if isinstance(self.line, bool) or not isinstance(self.line, (int, np.integer)):
            raise ValueError(f"Scan.line must be an int, got {self.line!r}")
        object.__setattr__(self, "timestamp", timestamp)
        object.__setattr__(self, "ranges", ranges)
        object.__setattr__(self, "angles", angles)
        object.__setattr__(self, "odom", _as_pose("odom", self.odom))
        object.__setattr__(self, "laser_pose", _as_pose("laser_pose", self.laser_pose))
        object.__setattr__(self, "max_range", max_range)
        object.__setattr__(self, "line", int(self.line))

    @property
    def n_beams(self) -> int:
        """Number of beams ``B``."""
        return int(self.ranges.shape[0])

    def points(
        self, *, min_range: float = 0.0, max_range: float | None = None
    ) -> npt.NDArray[np.float64]:
        """Scan-frame points of the valid beams.

        Parameters
        ----------
        min_range : float, default 0.0
            Smallest valid range [m].
        max_range : float, optional
            Ranges at or above it mean "no return" [m]. Defaults to the
            message's ``max_range`` when it has one, else no limit (0, NaN and
            infinite ranges are always skipped).

        Returns
        -------
        ndarray, shape (N, 2)
            ``(r cos a, r sin a)`` of the N valid beams [m].
        """
        from ndtgrid._core import ranges_to_points

        limit = max_range if max_range is not None else self.max_range
        return ranges_to_points(
            self.ranges,
            self.angles,
            min_range=min_range,
            max_range=math.inf if limit is None else limit,
        )

    def __repr__(self) -> str:
        if self.n_beams:
            span = f"[{self.angles[0]:.4f} .. {self.angles[-1]:.4f}] rad"
        else:
            span = "[]"
        return (
            f"Scan(timestamp={self.timestamp!r}, ranges=<{self.n_beams} float64>, "
            f"angles=<{self.n_beams} float64 {span}>, odom={_fmt_pose(self.odom)}, "
            f"laser_pose={_fmt_pose(self.laser_pose)}, max_range={self.max_range!r}, "
            f"source={self.source!r}, line={self.line})"
        )
