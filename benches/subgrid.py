"""The Fig. 8 experiment of Takubo et al. (IROS 2009, §V-VI), simulated, and §V on a real log.

Part 1 (simulation). The sticks room of :func:`ndtgrid.sim.sticks_room` (six 1.5 cm wooden
and two 1.3 cm iron sticks), a URG-04LX with the false detections of §V-A, a robot driving
the room's tour with 2 % odometry drift. For several seeds (each also shifts the world by a
random sub-cell offset against the 2 cm lattice), the map is built with elimination off,
each step alone (a = a-1..a-4, b = b-1 + b-2, c, d) and all steps on, once with the true
poses and once with poses from our own scan-to-map matching (odometry increment as the
guess, ``mapper.grid.match``). Measured on the final map:

- per-stick CoM error: distance from the true centre to the mean of the centres of the
  occupied cells within 10 cm of it (the map as a robot sees it; works for every variant),
  and to the centre of the nearest ``Mapper.small_objects()`` object within 5 cm;
- sticks found: sticks with a cell within 10 cm / with an object within 5 cm;
- false cells: occupied cells whose centre is more than 3 cm from every surface.

Part 2 (real data). The BreezySLAM/MinesRover URG-04LX log ``exp1.dat`` (from
``../shared/data/real``), odometry from the wheel ticks, our own matching: maps with the
elimination off and on, and the cells each step removed.

Usage::

    python benches/subgrid.py [--out out/subgrid] [--seeds 5] [--skip-real] [--skip-sensitivity]

Prints markdown tables and writes PNGs to ``--out``. Needs ``pip install ndtgrid[plot]``
for the pictures (``--no-plots`` skips them).
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

import ndtgrid
from ndtgrid import se2, sim

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


# --------------------------------------------------------------------------------------
# Part 1: simulation
# --------------------------------------------------------------------------------------


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
            est = mapper.grid.match(pts, guess).pose if len(pts) >= 10 else guess
        mapper.insert_scan(ranges[k], angles, est)
        used[k] = est
    ms = 1e3 * (time.perf_counter() - t0) / max(1, len(ranges))
    return mapper, used, ms


def measure(mapper: ndtgrid.Mapper, world: sim.World) -> tuple[int, int, F64, F64, int]:
    """cells, false cells, per-stick map CoM error [cm], object CoM error [cm], spurious objects."""
    cells = mapper.occupied_cells()
    false_cells = int((world.distance_to_surface(cells) > FALSE_DISTANCE).sum())
    centres = [o.center for o in mapper.small_objects()]
    map_err = np.full(len(world.sticks), np.nan)
    obj_err = np.full(len(world.sticks), np.nan)
    used = set()
    for i, (x, y, _) in enumerate(world.sticks):
        near = np.hypot(cells[:, 0] - x, cells[:, 1] - y) < MAP_RADIUS
        if near.any():
            map_err[i] = 100 * np.hypot(*(cells[near].mean(axis=0) - (x, y)))
        if centres:
            d = np.hypot(*(np.asarray(centres) - (x, y)).T)
            j = int(np.argmin(d))
            if d[j] < OBJECT_RADIUS:
                obj_err[i] = 100 * d[j]
                used.add(j)
    return len(cells), false_cells, map_err, obj_err, len(centres) - len(used)


def false_kinds(cells: F64, scn: Scenario) -> tuple[int, int, int]:
    """False cells within 15 cm of a stick, outside the room (behind its walls or inside the
    cabinet), and elsewhere in free space. Knows the sticks room's layout."""
    w = scn.world
    false = w.distance_to_surface(cells) > FALSE_DISTANCE
    x, y = (cells - scn.offset).T
    inside = (np.abs(x) < 2.5) & (np.abs(y) < 2.0) & ~((np.abs(x) < 0.4) & (y > 1.75))
    d = np.hypot(cells[:, None, 0] - w.sticks[None, :, 0], cells[:, None, 1] - w.sticks[None, :, 1])
    near = d.min(axis=1) < 0.15
    return (
        int((false & near).sum()),
        int((false & ~inside).sum()),
        int((false & inside & ~near).sum()),
    )


def run_sim(seeds: int, plots: Path | None) -> list[Result]:
    """Every variant x pose source x seed."""
    try:
        from tqdm import tqdm
    except ImportError:  # progress bars are optional

        def tqdm(x: Any, **_: Any) -> Any:
            return x

    results: list[Result] = []
    for seed in tqdm(range(seeds), desc="seeds"):
        scn = scenario(seed)
        for own in (False, True):
            for name, opts in VARIANTS.items():
                mapper, used, ms = build(
                    scn.ranges, scn.angles, scn.odom, opts, truth=None if own else scn.poses
                )
                cells, false_cells, map_err, obj_err, spurious = measure(mapper, scn.world)
                perr = 100 * np.hypot(*(used[:, :2] - scn.poses[:, :2]).T)
                results.append(
                    Result(
                        name,
                        seed,
                        own,
                        cells,
                        false_cells,
                        map_err,
                        obj_err,
                        spurious,
                        float(np.sqrt(np.mean(perr**2))),
                        float(perr.max()),
                        ms,
                        mapper.removal_counts().as_dict(),
                        false_kinds(mapper.occupied_cells(), scn),
                    )
                )
                if plots is not None and seed == 0 and own and name in ("off", "all on"):
                    plot_store[name] = (mapper, used, scn)
        if plots is not None and seed == 0:
            plot_fig8(plots, scn)
    return results


plot_store: dict[str, tuple[ndtgrid.Mapper, F64, Scenario]] = {}

#: The data sheet's accuracy of the URG-04LX: ±10 mm up to 1 m, ±1 % beyond (2 sigma).
DATASHEET_NOISE = replace(sim.URG04LX, range_sigma_relative=0.005)


def run_sensitivity(seeds: int) -> str:
    """Off vs all on, own poses, with the data sheet's range-proportional noise."""
    rows = []
    for seed in range(seeds):
        scn = scenario(seed, DATASHEET_NOISE)
        for name in ("off", "all on"):
            mapper, used, _ = build(scn.ranges, scn.angles, scn.odom, VARIANTS[name])
            cells, false_cells, map_err, obj_err, spurious = measure(mapper, scn.world)
            perr = 100 * np.hypot(*(used[:, :2] - scn.poses[:, :2]).T)
            rows.append((name, seed, cells, false_cells, map_err, obj_err, spurious, perr))
    lines = [
        "Sensitivity: the same, own poses, with the data sheet's noise (sigma = max(5 mm, 0.5 % "
        "of the range)); at 3-4 m range noise alone puts wall cells more than 3 cm off the wall.",
        "",
        "| variant | cells | false cells | false removed vs off | sticks found (map / objects) "
        "| map CoM err [cm] | object CoM err [cm] | pose RMSE [cm] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    off = {r[1]: r[3] for r in rows if r[0] == "off"}
    for name in ("off", "all on"):
        rs = [r for r in rows if r[0] == name]
        me = np.concatenate([r[4] for r in rs])
        oe = np.concatenate([r[5] for r in rs])
        removed = np.mean([1 - r[3] / max(1, off[r[1]]) for r in rs])
        lines.append(
            f"| {name} | {np.mean([r[2] for r in rs]):.0f} | {np.mean([r[3] for r in rs]):.1f} "
            f"| {100 * removed:.1f} % "
            f"| {np.isfinite(me).sum()} / {np.isfinite(oe).sum()} of {len(me)} "
            f"| {_nanmean(me):.2f} | {_nanmean(oe):.2f} "
            f"| {np.mean([np.sqrt(np.mean(r[7] ** 2)) for r in rs]):.2f} |"
        )
    return "\n".join(lines)


def _nanmean(x: F64) -> float:
    return float(np.nanmean(x)) if np.isfinite(x).any() else float("nan")


def report_sim(results: list[Result], seeds: int) -> str:
    """Markdown tables: variants (mean over seeds) and per-stick errors."""
    lines = [
        f"Simulated sticks room, URG-04LX model, {seeds} seeds, "
        f"{scenario_len_cache[0]} scans per run (mean over seeds; sticks found: total over seeds "
        f"out of {8 * seeds}).",
        "",
        "| variant | poses | cells | false cells | false removed vs off | sticks found (map) "
        "| map CoM err [cm] | sticks found (objects) | object CoM err [cm] "
        "| spurious objects | pose RMSE / max [cm] | ms/scan |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for own in (False, True):
        off = {r.seed: r.false_cells for r in results if r.variant == "off" and r.own == own}
        for name in VARIANTS:
            rs = [r for r in results if r.variant == name and r.own == own]
            me = np.concatenate([r.map_err for r in rs])
            oe = np.concatenate([r.obj_err for r in rs])
            removed = np.mean([1 - r.false_cells / max(1, off[r.seed]) for r in rs])
            lines.append(
                f"| {name} | {'own' if own else 'true'} | {np.mean([r.cells for r in rs]):.0f} "
                f"| {np.mean([r.false_cells for r in rs]):.1f} | {100 * removed:.1f} % "
                f"| {np.isfinite(me).sum()}/{len(me)} | {_nanmean(me):.2f} "
                f"| {np.isfinite(oe).sum()}/{len(oe)} | {_nanmean(oe):.2f} "
                f"| {np.mean([r.spurious_objects for r in rs]):.1f} "
                f"| {np.mean([r.pose_rmse for r in rs]):.2f} / {max(r.pose_max for r in rs):.2f} "
                f"| {np.mean([r.ms_per_scan for r in rs]):.2f} |"
            )
    lines += [
        "",
        "Per-stick CoM error [cm], own poses, mean over seeds (map / object):",
        "",
        "| variant | " + " | ".join(STICK_NAMES) + " | mean |",
        "|---|" + "---|" * (len(STICK_NAMES) + 1),
    ]
    for name in ("off", "all on"):
        rs = [r for r in results if r.variant == name and r.own]
        me = np.array([r.map_err for r in rs])
        oe = np.array([r.obj_err for r in rs])
        cols = []
        for i in range(me.shape[1]):
            m = _nanmean(me[:, i])
            o = _nanmean(oe[:, i])
            cols.append(f"{m:.2f}" + ("" if np.isnan(o) else f" / {o:.2f}"))
        tail = f"{_nanmean(me):.2f}" + ("" if np.isnan(_nanmean(oe)) else f" / {_nanmean(oe):.2f}")
        lines.append(f"| {name} | " + " | ".join(cols) + f" | {tail} |")
    lines += [
        "",
        "False cells by kind, own poses, mean over seeds (near: within 15 cm of a stick; "
        "outside: behind the walls or in the cabinet; free space: the rest of the room):",
        "",
        "| variant | near sticks | outside | free space |",
        "|---|---|---|---|",
    ]
    for name in VARIANTS:
        k = np.mean([r.kinds for r in results if r.variant == name and r.own], axis=0)
        lines.append(f"| {name} | {k[0]:.1f} | {k[1]:.1f} | {k[2]:.1f} |")
    lines += [
        "",
        "Cells / points each step removed, all steps on, own poses, mean over seeds:",
        "",
        "| " + " | ".join(COUNT_KEYS) + " |",
        "|" + "---|" * len(COUNT_KEYS),
        "| "
        + " | ".join(
            f"{np.mean([r.counts[k] for r in results if r.variant == 'all on' and r.own]):.0f}"
            for k in COUNT_KEYS
        )
        + " |",
    ]
    return "\n".join(lines)


STICK_NAMES = ["W1", "W2", "W3", "W4", "W5", "W6", "I1", "I2"]
COUNT_KEYS = [
    "behind_com_points",
    "behind_com_cells",
    "forefront_points",
    "forefront_cells",
    "area1_cells",
    "backshift_points",
    "backshift_cells",
    "observation_cells",
    "confirmation_cells",
]
scenario_len_cache: list[int] = []


# --------------------------------------------------------------------------------------
# Pictures
# --------------------------------------------------------------------------------------


def _plt() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as err:  # pragma: no cover - optional dependency
        raise ImportError("the pictures need matplotlib: pip install ndtgrid[plot]") from err
    return plt


def _draw_cells(ax: Any, cells: F64, color: str = "black") -> None:
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle

    rects = [Rectangle((x - CELL / 2, y - CELL / 2), CELL, CELL) for x, y in cells]
    ax.add_collection(PatchCollection(rects, facecolor=color, edgecolor="none"))


def plot_fig8(out: Path, scn: Scenario) -> None:
    """Fig. 8/9-style pictures of seed 0 (own poses): off vs all on, whole map and a zoom."""
    plt = _plt()
    world = scn.world
    panels = [("off", "(a) without elimination"), ("all on", "(b) with the §V elimination")]
    for zoom, fname, size in (
        (None, "fig8_sticks_room.png", (11, 4.6)),
        (3, "fig9_iron_stick.png", (8, 4)),
    ):
        fig, axes = plt.subplots(1, 2, figsize=size, constrained_layout=True)
        for ax, (name, title) in zip(axes, panels):
            mapper, used, _ = plot_store[name]
            cells = mapper.occupied_cells()
            _draw_cells(ax, cells)
            ax.plot(used[:, 0], used[:, 1], color="0.6", lw=0.8)
            for x, y, d in world.sticks:
                ax.add_patch(plt.Circle((x, y), d / 2, fill=False, color="red", lw=1.0))
            for o in mapper.small_objects():
                ax.plot(*o.center, "+", color="tab:blue", ms=8 if zoom else 5, mew=1.2)
            if zoom is None:
                ax.set_xlim(-2.7, 2.7)
                ax.set_ylim(-2.2, 2.2)
                false_cells = int((world.distance_to_surface(cells) > FALSE_DISTANCE).sum())
                ax.set_title(f"{title}\n{len(cells)} cells, {false_cells} false (> 3 cm)")
            else:
                x, y, _ = world.sticks[6]
                ax.set_xlim(x - 0.2, x + 0.2)
                ax.set_ylim(y - 0.2, y + 0.2)
                ax.set_title(f"{title}\niron stick at the centre", fontsize=10)
                ax.grid(True, color="0.9", lw=0.5)
            ax.set_aspect("equal")
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]")
        fig.suptitle(
            "Simulated sticks room, URG-04LX model, own poses, 2 cm cells\n"
            "black: occupied cells, red: true sticks, +: detected small objects",
            fontsize=9,
        )
        fig.savefig(out / fname, dpi=110)
        plt.close(fig)


def plot_real(out: Path, maps: dict[str, tuple[ndtgrid.Mapper, F64]]) -> None:
    """The real log's maps: off and on at the same poses, and on with its own matching."""
    plt = _plt()
    names = ("off", "all on", "all on, own matching")
    fig, axes = plt.subplots(1, 3, figsize=(16, 6), constrained_layout=True)
    for ax, name in zip(axes, names):
        mapper, used = maps[name]
        cells = mapper.occupied_cells()
        _draw_cells(ax, cells)
        ax.plot(used[:, 0], used[:, 1], color="tab:orange", lw=0.8)
        ax.set_title(f"exp1.dat, elimination {name}: {len(cells)} cells", fontsize=10)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.savefig(out / "real_exp1_off_on.png", dpi=100)
    plt.close(fig)


# --------------------------------------------------------------------------------------
# Part 2: the real URG-04LX log
# --------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------


def machine() -> str:
    """nproc, CPU model and commit, for BENCHMARK.md."""
    cpu = "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=False,
            cwd=Path(__file__).parent,
        ).stdout.strip()
    except OSError:
        commit = "unknown"
    return f"{os.cpu_count()} cores ({cpu}), Python {platform.python_version()}, commit {commit}"


def main() -> None:
    """Run both parts and print the tables."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=Path("out/subgrid"), help="directory for PNGs")
    parser.add_argument("--seeds", type=int, default=5, help="simulated runs per variant")
    parser.add_argument("--skip-real", action="store_true", help="skip the real log")
    parser.add_argument(
        "--skip-sensitivity", action="store_true", help="skip the data-sheet-noise run"
    )
    parser.add_argument("--no-plots", action="store_true", help="write no PNGs")
    args = parser.parse_args()
    plots = None if args.no_plots else args.out
    if plots is not None:
        plots.mkdir(parents=True, exist_ok=True)
    scenario_len_cache.append(len(sim.trajectory(sim.sticks_room().tour)))
    print(f"machine: {machine()}\n")
    t0 = time.perf_counter()
    results = run_sim(args.seeds, plots)
    print(report_sim(results, args.seeds))
    print(f"\n(simulation part: {time.perf_counter() - t0:.0f} s)\n")
    if not args.skip_sensitivity:
        print(run_sensitivity(args.seeds) + "\n")
    if args.skip_real:
        return
    if REAL_LOG.exists():
        print(run_real(REAL_LOG, plots))
    else:
        print(f"real log absent ({REAL_LOG}); skipped")
    if plots is not None:
        print(f"\nPNGs in {plots}/")


if __name__ == "__main__":
    main()
