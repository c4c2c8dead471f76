"""Keyword presets of :meth:`ndtgrid.NdtGrid.match` for the methods the defaults grew from.

Examples
--------
>>> import ndtgrid
>>> from ndtgrid.presets import ORIGINAL_NDT, PAPER
>>> grid = ndtgrid.NdtGrid(0.02)
>>> sorted(PAPER)
['freeze_unconstrained', 'levels', 'rotation_search', 'search_radius', 'shape_cell', 'sigma_floor']
"""

from __future__ import annotations

from typing import Any

__all__ = ["ORIGINAL_NDT", "PAPER", "SCAN_TO_MAP"]

#: Takubo et al. (IROS 2009) alone: the fine grid only, k = 10, neighbour search (3 cells)
#: and minority fusion, no pyramid, no rotational multi-start, no frozen directions; the
#: covariance regularised only up to a 5 mm standard deviation (about a URG-04LX's or a
#: SICK's range noise; the paper states none), not the default's 1 cm; each cell's own
#: covariance (eq. 7), not its pyramid ancestor's (``shape_cell=0``).
PAPER: dict[str, Any] = {
    "levels": 1,
    "sigma_floor": 0.005,
    "shape_cell": 0.0,
    "rotation_search": 0.0,
    "freeze_unconstrained": False,
    "search_radius": 3,
}

#: Biber & Strasser's original NDT on the same grid: additionally k = 1, no neighbour
#: search, no fusion.
ORIGINAL_NDT: dict[str, Any] = {
    **PAPER,
    "expansion": 1.0,
    "neighbor_search": False,
    "fuse_minority": False,
}

#: The default match tuned for a map of many scans (what ``ndtgrid.Odometry`` matches
#: against, and a ``Mapper``'s grid): the 5 mm sigma floor, each fine cell's own covariance
#: and freezing only below 2 % curvature. The default's 1 cm floor, 32 cm cell shapes and
#: 10 % freezing were chosen on sparse single-scan maps; on the simulated sticks room
#: (``benches/subgrid.py``, own poses) they raise the stick error from 0.6 to 0.8 cm.
SCAN_TO_MAP: dict[str, Any] = {
    "sigma_floor": 0.005,
    "shape_cell": 0.0,
    "freeze_ratio": 0.02,
}
