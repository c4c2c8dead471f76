"""Constructed laser scans for the Mapper tests.

Beams at the URG-04LX step (0.352 deg) over +-60 deg; a range of 0 is "no return". Sticks
are placed mid-cell (x = 0.41 m, y offset 0.01 m) so that which cell a point falls in is
not a matter of round-off.
"""

from __future__ import annotations

import numpy as np

import ndtgrid

STEP = np.radians(240.0 / 682.0)
ANGLES = np.arange(-170, 171) * STEP  # 341 beams over +-60 deg, beam 170 at 0 deg
CENTRE = 170
POSE = np.array([0.0, 0.01, 0.0])


def wall(distance: float) -> np.ndarray:
    """Ranges to a wall perpendicular to the sensor's x axis."""
    return distance / np.cos(ANGLES)


def stick(ranges: np.ndarray, values: list[float], first: int = CENTRE - 2) -> np.ndarray:
    """``ranges`` with beams ``first, first+1, ...`` replaced by ``values``."""
    out = ranges.copy()
    out[first : first + len(values)] = values
    return out


def cells_in(mapper: ndtgrid.Mapper, x0: float, x1: float, y0: float, y1: float) -> int:
    c = mapper.occupied_cells()
    return int(((c[:, 0] > x0) & (c[:, 0] < x1) & (c[:, 1] > y0) & (c[:, 1] < y1)).sum())


def only(**steps: bool) -> dict[str, bool]:
    """Every step off except the ones named."""
    names = [
        "edge_removal",
        "area1_confirmation",
        "backshift_rejection",
        "observation_check",
        "radial_confirmation",
    ]
    return {n: steps.get(n, False) for n in names}
