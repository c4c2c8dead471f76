"""ndtgrid: high-resolution 2D NDT scan matching and grid mapping.

A Rust core (``ndtgrid._core``) implements Takubo et al., "NDT Scan Matching
Method for High Resolution Grid Map" (IROS 2009): a sparse grid whose cells
keep only the sums of eq. (6), Newton scan matching on the score of eq. (1),
the small-cell fixes of §IV-A, and the elimination of false detections of
§V (:class:`Mapper`). Units are metres and radians; poses are
``[x, y, theta]`` arrays that map scan-frame points into the map frame.
:mod:`ndtgrid.sim` is a small laser simulator for tests and demos.

Examples
--------
>>> import numpy as np, ndtgrid
>>> grid = ndtgrid.NdtGrid(cell_size=0.02)
>>> len(grid)
0
"""

from __future__ import annotations

from ndtgrid import (
    io,
    presets,
    se2,
    sim,
)
from ndtgrid._core import (
    Mapper,
    MapperOptions,
    MatchResult,
    NdtGrid,
    RemovalCounts,
    SmallObject,
    __version__,
    default_mapper_options,
    default_match_options,
    ranges_to_points,
)
from ndtgrid.odometry import Odometry, OdometryConfig, OdometryStep

__all__ = [
    "Mapper",
    "MapperOptions",
    "MatchResult",
    "NdtGrid",
    "Odometry",
    "OdometryConfig",
    "OdometryStep",
    "RemovalCounts",
    "SmallObject",
    "__version__",
    "default_mapper_options",
    "default_match_options",
    "io",
    "presets",
    "ranges_to_points",
    "se2",
    "sim",
]
