"""Reader for the Mines ParisTech URG-04LX logs of BreezySLAM / CoreSLAM (``exp*.dat``).

One scan per line, whitespace-separated integers (707 per line in the known logs):

=========  ==========================================================================
token      meaning
=========  ==========================================================================
0          timestamp [us]
2, 3       left and right wheel odometer [ticks]
24 .. 705  the 682 ranges [mm] (0 = no return) as BreezySLAM's loader reads them
others     undocumented status fields, ignored
=========  ==========================================================================

**Which tokens are the ranges.** BreezySLAM's ``examples/mines.py`` drops the last token
and reads tokens 24..705. Token 24 is always 0 and is followed by a double space, so the
true scan may be tokens 25..706; the two readings differ by one beam (0.35 deg) of bearing.
This reader follows the loader (``first_range_token=24``) so results compare with
BreezySLAM's; pass 25 for the other reading.

**Beams.** Beam ``k`` of the 682 points at ``-120 deg + k * 240 deg / 681`` (counter-
clockwise, x forward), as the loader's ``URG04LX`` sensor model (CoreSLAM) does.

**Odometry.** As BreezySLAM's ``WheeledVehicle`` with the Mines rover (wheel radius
``r = 77`` mm, half axle ``165`` mm, ``ticks * 180 / 2000`` degrees of wheel rotation):
between consecutive lines ``dxy = r * (dleft + dright)`` [mm, wheel angles in rad] and
``dtheta = (r / half_axle) * (dright - dleft)`` [deg, wheel angles in deg], and the pose
moves ``dxy`` along its current heading, then turns ``dtheta`` (CoreSLAM's update). The
first scan is at ``(0, 0, 0)``. The laser sits 145 mm ahead of the robot centre.
"""

from __future__ import annotations

import math
import os
from collections.abc import Generator

import numpy as np

from .scan import Scan

__all__ = ["HALF_AXLE", "LASER_OFFSET", "TICKS_PER_HALF_TURN", "WHEEL_RADIUS", "read_mines"]

#: Wheel radius of the Mines rover [m].
WHEEL_RADIUS = 0.077
#: Half of the axle length between the odometry wheels [m].
HALF_AXLE = 0.165
#: Odometer ticks per half wheel turn (``ticks * 180 / 2000`` degrees, as coded).
TICKS_PER_HALF_TURN = 2000
#: Distance of the laser ahead of the robot centre [m].
LASER_OFFSET = 0.145
#: Ranges per scan.
N_BEAMS = 682
#: Field of view of the URG-04LX [rad].
FOV = math.radians(240.0)


def read_mines(
    path: str | os.PathLike[str], *, first_range_token: int = 24
) -> Generator[Scan, None, None]:
    """Read the scans of a Mines URG-04LX log, lazily, in file order.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.dat`` file.
    first_range_token : int, default 24
        Index of the first range token: 24 as BreezySLAM's loader, 25 for the other
        reading (see the module notes). The scan is the 682 tokens from there.

    Returns
    -------
    Generator[Scan, None, None]
        One :class:`~ndtgrid.io.Scan` per line: ``timestamp`` [s] (token 0 / 1e6),
        ``ranges`` (682,) [m] (0 = no return), ``angles`` (682,) [rad], ``odom`` (3,) the
        robot pose from the wheel odometry, ``laser_pose`` (3,) ``odom`` moved 0.145 m
        forward, ``max_range`` ``None`` (the log holds returns up to 5.6 m), ``source``
        ``"MINES"``, ``line`` the 1-based line number.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist (raised by this call, before iterating).
    ValueError
        If ``first_range_token`` is not 24 or 25. While iterating: a line with too few
        tokens for the scan or with a non-integer token; the message starts with
        ``"{path}:{line}: "``. Empty lines are skipped.
    """
    name = os.fspath(path)
    if not os.path.exists(name):
        raise FileNotFoundError(f"{name}: no such file")
    if first_range_token not in (24, 25):
        raise ValueError(f"first_range_token: expected 24 or 25, got {first_range_token!r}")
    return _scans(name, first_range_token)


def _scans(name: str, first: int) -> Generator[Scan, None, None]:
    from ndtgrid import se2

    angles = np.radians(-120.0 + np.arange(N_BEAMS) * (240.0 / (N_BEAMS - 1)))
    need = first + N_BEAMS
    deg_per_tick = 180.0 / TICKS_PER_HALF_TURN
    pose = np.zeros(3)
    previous: tuple[float, float] | None = None
    with open(name) as f:
        for number, text in enumerate(f, start=1):
            tokens = text.split()
            if not tokens:
                continue
            if len(tokens) < need:
                raise ValueError(
                    f"{name}:{number}: expected at least {need} tokens (timestamp, odometry, "
                    f"{N_BEAMS} ranges from token {first}), got {len(tokens)}"
                )
            try:
                stamp = int(tokens[0])
                left, right = int(tokens[2]), int(tokens[3])
                ranges_mm = np.array(tokens[first:need], dtype=np.int64)
            except ValueError:
                bad = next(i for i in [0, 2, 3, *range(first, need)] if not _is_int(tokens[i]))
                raise ValueError(
                    f"{name}:{number}: token {bad}: expected an integer, got {tokens[bad]!r}"
                ) from None
            wheels = (left * deg_per_tick, right * deg_per_tick)
            if previous is not None:
                d_left, d_right = wheels[0] - previous[0], wheels[1] - previous[1]
                dxy = WHEEL_RADIUS * (math.radians(d_left) + math.radians(d_right))
                dtheta = (WHEEL_RADIUS / HALF_AXLE) * (d_right - d_left)
                pose = se2.compose(pose, [dxy, 0.0, math.radians(dtheta)])
            previous = wheels
            yield Scan(
                timestamp=stamp * 1e-6,
                ranges=ranges_mm.astype(np.float64) * 1e-3,
                angles=angles,
                odom=pose,
                laser_pose=se2.compose(pose, [LASER_OFFSET, 0.0, 0.0]),
                source="MINES",
                line=number,
            )


def _is_int(token: str) -> bool:
    try:
        int(token)
    except ValueError:
        return False
    return True
