"""The real-log part of ``benches/subgrid.py``: the MinesRover URG-04LX log ``exp1.dat``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from subgrid_common import COUNT_KEYS, F64, VARIANTS, build
from subgrid_plots import plot_real

import ndtgrid
from ndtgrid import se2


def _load_mines_private(path: Path) -> tuple[F64, F64, F64]:
    """PRIVATE minimal reader of the BreezySLAM/MinesRover ``exp*.dat`` format (see its
    SOURCE.md). Bench-only: the proper reader belongs in ``ndtgrid.io``.

    Returns ranges (T, 682) [m] (0 = no return), angles (682,) [rad] and the odometry
    poses (T, 3) of the *laser* (robot pose o 145 mm forward offset).
    """
    rows = np.array([line.split() for line in path.read_text().splitlines()], dtype=np.float64)
    ranges = rows[:, 24:706] / 1000.0  # the shipped loader's tokens 24..705, mm -> m
    # The robot body blocks 70 beams at each end (mines.py's detection margin).
    ranges[:, :70] = 0.0
    ranges[:, -70:] = 0.0
    angles = np.radians(-120.0 + np.arange(682) * 240.0 / 681.0)
    # Wheel odometry as BreezySLAM's vehicles.py: degrees = ticks * 180 / 2000.
    r, half_axle = 77.0, 165.0
    deg = rows[:, 2:4] * 180.0 / 2000.0
    d = np.diff(deg, axis=0)
    dxy = r * (np.radians(d[:, 0]) + np.radians(d[:, 1])) / 1000.0
    dth = np.radians((r / half_axle) * (d[:, 1] - d[:, 0]))
    robot = np.zeros((len(rows), 3))
    for k in range(1, len(rows)):
        robot[k] = se2.compose(robot[k - 1], [dxy[k - 1], 0.0, dth[k - 1]])
    laser = np.array([se2.compose(p, [0.145, 0.0, 0.0]) for p in robot])
    return ranges, angles, laser


def run_real(path: Path, out: Path | None) -> str:
    """The real log: every variant at the same poses, and all on with its own matching.

    The poses come from our matching with the elimination off (wheel odometry as the
    guess), so the maps differ by the elimination alone. A last run matches against the
    filtered map itself, as a SLAM loop would.
    """
    ranges, angles, odom = _load_mines_private(path)
    _, ref_used, _ = build(ranges, angles, odom, VARIANTS["off"], min_range=0.1, max_range=5.0)
    lines = [
        f"Real log `{path.name}`: {len(ranges)} scans, URG-04LX, ranges 0.1-5.0 m, beams 70-611. "
        "Every variant at the same poses (our matching against the unfiltered map, wheel "
        "odometry as the guess); the counters are cumulative over the run (a cell deleted, "
        "re-observed and deleted again counts twice).",
        "",
        "| variant | cells | ms/scan | " + " | ".join(COUNT_KEYS) + " |",
        "|---|---|---|" + "---|" * len(COUNT_KEYS),
    ]
    maps: dict[str, tuple[ndtgrid.Mapper, F64]] = {}
    for name, opts in VARIANTS.items():
        mapper, used, ms = build(
            ranges, angles, odom, opts, truth=ref_used, min_range=0.1, max_range=5.0
        )
        maps[name] = (mapper, used)
        counts = mapper.removal_counts().as_dict()
        lines.append(
            f"| {name} | {len(mapper)} | {ms:.2f} | "
            + " | ".join(str(counts[k]) for k in COUNT_KEYS)
            + " |"
        )
    loop, loop_used, ms = build(
        ranges, angles, odom, VARIANTS["all on"], min_range=0.1, max_range=5.0
    )
    maps["all on, own matching"] = (loop, loop_used)
    dev = 100 * np.hypot(*(loop_used[:, :2] - ref_used[:, :2]).T)
    lines += [
        "",
        f"All on, matching against the filtered map itself: {len(loop)} cells, {ms:.2f} ms/scan; "
        f"its trajectory departs from the reference by {np.sqrt(np.mean(dev**2)):.1f} cm RMS, "
        f"{dev.max():.1f} cm at most (no ground truth: neither is known to be right).",
    ]
    if out is not None:
        plot_real(out, maps)
    return "\n".join(lines)
