"""Shared pieces of ``benches/subgrid.py``: constants, the variants, the scenario and the
scan-by-scan map building loop."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

import ndtgrid
from ndtgrid import se2, sim
from ndtgrid.presets import SCAN_TO_MAP

F64 = npt.NDArray[np.float64]

CELL = 0.02
#: A cell farther than this from every surface is a false cell [m] (the issue's definition).
FALSE_DISTANCE = 0.03
#: Occupied cells within this of a stick make its map CoM [m].
MAP_RADIUS = 0.10
#: A small object within this of a stick detects it [m].
OBJECT_RADIUS = 0.05

STEPS_OFF = {
    "edge_removal": False,
    "area1_confirmation": False,
    "backshift_rejection": False,
    "observation_check": False,
    "radial_confirmation": False,
}
VARIANTS: dict[str, dict[str, bool]] = {
    "off": {"outlier_filter": False},
    "a only": {**STEPS_OFF, "edge_removal": True},
    "b only": {**STEPS_OFF, "area1_confirmation": True, "backshift_rejection": True},
    "c only": {**STEPS_OFF, "observation_check": True},
    "d only": {**STEPS_OFF, "radial_confirmation": True},
    "all on": {},
}

REAL_LOG = (
    Path(__file__).resolve().parents[1].parent
    / "shared/data/real/breezyslam-mines-urg04lx/exp1.dat"
)


@dataclass
class Scenario:
    """One simulated run: world, true poses, odometry and scans."""

    seed: int
    offset: F64
    world: sim.World
    poses: F64
    odom: F64
    ranges: F64
    angles: F64


@dataclass
class Result:
    """Measures of one final map."""

    variant: str
    seed: int
    own: bool
    cells: int
    false_cells: int
    map_err: F64  # (8,) cm, NaN = not found
    obj_err: F64  # (8,) cm, NaN = not found
    spurious_objects: int
    pose_rmse: float  # cm
    pose_max: float  # cm
    ms_per_scan: float
    counts: dict[str, int] = field(default_factory=dict)
    kinds: tuple[int, int, int] = (0, 0, 0)  # false cells near sticks / behind walls / free space


def scenario(seed: int, laser: sim.Laser = sim.URG04LX) -> Scenario:
    """The sticks room shifted by a random sub-cell offset, the tour, odometry, scans."""
    offset = np.random.default_rng(1000 + seed).uniform(0.0, CELL, 2)
    world = sim.sticks_room().translated(*offset)
    poses = sim.trajectory(world.tour)
    odom = sim.odometry(poses, drift=0.02, seed=seed)
    ranges, angles = sim.simulate(world, laser, poses, seed=seed)
    return Scenario(seed, offset, world, poses, odom, ranges, angles)


def build(
    ranges: F64,
    angles: F64,
    odom: F64,
    options: dict[str, Any],
    *,
    truth: F64 | None = None,
    max_range: float = np.inf,
    min_range: float = 0.0,
) -> tuple[ndtgrid.Mapper, F64, float]:
    """Build a map scan by scan; with ``truth`` at those poses, else with our own matching.

    Returns the mapper, the (T, 3) poses used and the mean time per scan [ms].
    """
    mapper = ndtgrid.Mapper(CELL, min_range=min_range, max_range=max_range, **options)
    used = np.empty_like(odom)
    est = odom[0] if truth is None else truth[0]
    t0 = time.perf_counter()
    for k in range(len(ranges)):
        if truth is not None:
            est = truth[k]
        elif k > 0:
            guess = se2.compose(est, se2.between(odom[k - 1], odom[k]))
            pts = ndtgrid.ranges_to_points(
                ranges[k], angles, min_range=max(min_range, 1e-9), max_range=max_range
            )
            est = mapper.grid.match(pts, guess, **SCAN_TO_MAP).pose if len(pts) >= 10 else guess
        mapper.insert_scan(ranges[k], angles, est)
        used[k] = est
    ms = 1e3 * (time.perf_counter() - t0) / max(1, len(ranges))
    return mapper, used, ms


STICK_NAMES = ["W1", "W2", "W3", "W4", "W5", "W6", "I1", "I2"]
# The per-step counters, in the order the core reports them.
COUNT_KEYS = list(ndtgrid.Mapper().removal_counts().as_dict())
