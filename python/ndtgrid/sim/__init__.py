"""A small, deterministic 2D laser simulator for tests, demos and benchmarks.

Numpy only. Worlds are line segments and circles (:mod:`.world`), the laser
model reproduces the false detections of the paper's §V-A (:mod:`.laser`),
and robots drive through waypoints with drifting odometry
(:mod:`.trajectory`).

Examples
--------
>>> import numpy as np
>>> from ndtgrid import sim
>>> room = sim.sticks_room()                     # the paper's Fig. 8 world
>>> poses = sim.trajectory(room.tour, step=0.05)
>>> odom = sim.odometry(poses, drift=0.02, seed=1)
>>> ranges, angles = sim.URG04LX.scan(room, poses[0], rng=0)
>>> ranges.shape, angles.shape
((683,), (683,))
"""

from __future__ import annotations

from ndtgrid.sim.laser import SICK_LMS, URG04LX, Laser, cast_rays
from ndtgrid.sim.trajectory import odometry, scan_ranges, simulate, trajectory
from ndtgrid.sim.world import SMALL_DIAMETER, World, sticks_room

__all__ = [
    "SICK_LMS",
    "SMALL_DIAMETER",
    "URG04LX",
    "Laser",
    "World",
    "cast_rays",
    "odometry",
    "scan_ranges",
    "simulate",
    "sticks_room",
    "trajectory",
]
