"""ndtgrid: high-resolution 2D NDT scan matching and grid mapping.

A Rust core (``ndtgrid._core``) implements Takubo et al., "NDT Scan Matching
Method for High Resolution Grid Map" (IROS 2009): a sparse grid whose cells
keep only the sums of eq. (6), Newton scan matching on the score of eq. (1),
and the small-cell fixes of §IV-A. Units are metres and radians; poses are
``[x, y, theta]`` arrays that map scan-frame points into the map frame.

Examples
--------
>>> import numpy as np, ndtgrid
>>> grid = ndtgrid.NdtGrid(cell_size=0.02)
>>> len(grid)
0
"""

from __future__ import annotations

from ndtgrid import io, se2
from ndtgrid._core import MatchResult, NdtGrid, __version__, default_match_options
from ndtgrid.odometry import Odometry, OdometryConfig, OdometryStep

__all__ = [
    "MatchResult",
    "NdtGrid",
    "Odometry",
    "OdometryConfig",
    "OdometryStep",
    "__version__",
    "default_match_options",
    "io",
    "se2",
]
