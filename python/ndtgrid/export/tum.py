"""Trajectories in the TUM RGB-D format, one pose per line::

    timestamp tx ty tz qx qy qz qw

Planar poses ``[x, y, theta]`` are written with ``tz = 0`` and the rotation about z as the
unit quaternion ``(0, 0, sin(theta/2), cos(theta/2))``. ``evo`` (``evo_traj tum``,
``evo.tools.file_interface.read_tum_trajectory_file``) reads these files.
"""

from __future__ import annotations

import math
import os

import numpy as np
import numpy.typing as npt

__all__ = ["read_tum", "write_tum"]

F64 = npt.NDArray[np.float64]


def write_tum(
    path: str | os.PathLike[str], timestamps: npt.ArrayLike, poses: npt.ArrayLike
) -> None:
    """Write a planar trajectory as a TUM file.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write (overwritten).
    timestamps : array_like, shape (T,)
        Time of each pose [s], finite and strictly increasing (``evo`` requires it).
    poses : array_like, shape (T, 3)
        Poses ``[x, y, theta]`` (m, m, rad).

    Raises
    ------
    ValueError
        If the shapes disagree, a value is not finite or the times do not increase.
    """
    t = np.asarray(timestamps, dtype=np.float64)
    p = np.asarray(poses, dtype=np.float64)
    if t.ndim != 1 or p.shape != (t.shape[0], 3):
        raise ValueError(
            f"timestamps, poses: expected shapes (T,) and (T, 3), got {t.shape} and {p.shape}"
        )
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(p))):
        raise ValueError("timestamps, poses: expected finite values, got NaN or inf")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        i = int(np.argmax(np.diff(t) <= 0))
        raise ValueError(
            f"timestamps: expected strictly increasing times, got {t[i]!r} then {t[i + 1]!r} "
            f"at pose {i + 1}"
        )
    with open(path, "w") as f:
        f.write("# timestamp tx ty tz qx qy qz qw\n")
        for ti, (x, y, th) in zip(t, p):
            f.write(
                f"{ti:.6f} {x:.9f} {y:.9f} 0 0 0 {math.sin(th / 2):.12f} {math.cos(th / 2):.12f}\n"
            )


def read_tum(path: str | os.PathLike[str]) -> tuple[F64, F64]:
    """Read a TUM trajectory as planar poses.

    Parameters
    ----------
    path : str or os.PathLike
        The file. ``#`` lines and empty lines are skipped; fields may be separated by
        spaces or commas.

    Returns
    -------
    timestamps : ndarray, shape (T,)
        Times [s].
    poses : ndarray, shape (T, 3)
        ``[x, y, yaw]`` (m, m, rad); ``tz`` and the roll and pitch of the quaternion are
        ignored (yaw is the rotation about z of the normalised quaternion).

    Raises
    ------
    ValueError
        If a line does not hold 8 numbers; the message names the file and the line.
    """
    rows = []
    with open(path) as f:
        for number, text in enumerate(f, start=1):
            text = text.strip()
            if not text or text.startswith("#"):
                continue
            fields = text.replace(",", " ").split()
            try:
                if len(fields) != 8:
                    raise ValueError
                rows.append([float(v) for v in fields])
            except ValueError:
                raise ValueError(
                    f"{path}:{number}: expected 8 numbers 'timestamp tx ty tz qx qy qz qw', "
                    f"got {text[:60]!r}"
                ) from None
    table = np.array(rows, dtype=np.float64).reshape(-1, 8)
    qx, qy, qz, qw = table[:, 4], table[:, 5], table[:, 6], table[:, 7]
    yaw = np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    return table[:, 0].copy(), np.stack([table[:, 1], table[:, 2], yaw], axis=1)
