"""The ``ndtgrid`` command line.

``ndtgrid map LOG --out DIR``
    Run :class:`ndtgrid.Odometry` over a log and write ``map.png``, a ROS ``map_server`` map
    (``map.pgm`` + ``map.yaml``), ``trajectory.tum`` and ``map.ndtgrid`` (the map itself
    in the versioned, checksummed ndtgrid format; it loads back identical with
    :meth:`ndtgrid.NdtGrid.load` or :func:`ndtgrid.export.load_map`).
``ndtgrid eval --estimate traj.tum --reference REF``
    The relation metric of Kümmerle et al. (2009) on consecutive reference poses.

``ndtgrid demo [--out DIR]``
    The same on the paper's simulated sticks room (:mod:`ndtgrid.sim`, a URG-04LX with
    drifting odometry): no data needed; also reports the pose error against the
    simulator's truth and the small objects (sticks) found.
``ndtgrid bench [--scans N] [--json]``
    Time insert, match, ``match_many`` and the odometry loop of the installed library on
    simulated scans (:mod:`ndtgrid.bench`): no data needed.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import sys
import time
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

import numpy as np
import numpy.typing as npt

from ndtgrid import __version__
from ndtgrid._progress import progress
from ndtgrid.io import Scan

if TYPE_CHECKING:
    from ndtgrid.odometry import Odometry

T = TypeVar("T")


def _whole(text: str) -> int:
    """An argument that is a whole number, 0 or more."""
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got {text!r}")
    return value


def _seconds(text: str) -> float:
    """An argument that is a finite number of seconds, 0 or more."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"expected seconds >= 0, got {text!r}")
    return value


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``ndtgrid`` command.

    Returns
    -------
    argparse.ArgumentParser
        Parser with ``--version`` and the subcommands ``map``, ``demo``, ``bench`` and
        ``eval``.
    """
    from ndtgrid import bench
    from ndtgrid.io import LOG_FORMATS

    parser = argparse.ArgumentParser(
        prog="ndtgrid",
        description="High-resolution 2D NDT scan matching and grid mapping.",
    )
    parser.add_argument("--version", action="version", version=f"ndtgrid {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    m = sub.add_parser(
        "map",
        help="map a real log: map.png, map.pgm + map.yaml, trajectory.tum, map.ndtgrid",
        description="Run the scan-to-map odometry over a log and write the map and trajectory.",
    )
    m.add_argument("log", metavar="LOG", help="the log file (or ROS 2 bag directory)")
    m.add_argument("--out", default="out", help="output directory (default: out)")
    m.add_argument(
        "--format",
        choices=sorted(LOG_FORMATS),
        help="log format; by default from the name ("
        + "; ".join(f"{k}: {v}" for k, v in LOG_FORMATS.items())
        + ")",
    )
    m.add_argument("--cell-size", type=float, default=0.02, help="NDT cell size [m] (0.02)")
    m.add_argument(
        "--resolution", type=float, default=0.05, help="pixel size of map.pgm/png [m] (0.05)"
    )
    m.add_argument("--max-scans", type=_whole, default=None, help="stop after this many scans")
    m.add_argument("--quiet", action="store_true", help="no progress bar")
    d = sub.add_parser(
        "demo",
        help="the same on a simulated room with sticks (no data needed)",
        description="Simulate the paper's sticks room with a URG-04LX and drifting odometry, "
        "map it like 'ndtgrid map' and report the error against the truth.",
    )
    d.add_argument("--out", default="demo-out", help="output directory (default: demo-out)")
    d.add_argument("--seed", type=_whole, default=0, help="simulation seed (0)")
    d.add_argument("--quiet", action="store_true", help="no progress bar")
    b = sub.add_parser(
        "bench",
        help="time insert, match and the odometry loop on this machine (no data needed)",
        description="Time the installed library on simulated URG-04LX scans of the sticks "
        "room: insert into a 2 cm map (one scan a call, and in batches by insert_many, "
        "checked to give the same map), match (checked against the truth), match_many on "
        "one thread and on every core, one and two Python threads matching (on Linux also "
        "two pinned ones), and the odometry loop. No data or other library "
        "is needed; benches/speed.py in the source tree compares peers on real logs.",
    )
    b.add_argument(
        "--scans",
        type=int,
        default=None,
        help=f"simulated scans, at least {bench.MIN_SCANS} (default: every pose of the "
        "simulated tour; a run refuses more, naming how many it has)",
    )
    b.add_argument("--seed", type=_whole, default=0, help="simulation seed (0)")
    b.add_argument(
        "--repeats",
        type=int,
        default=5,
        help="rounds of the batches timed as a whole (match_many, Python threads); "
        "their median is shown (5)",
    )
    b.add_argument("--json", action="store_true", help="print the report as JSON")
    b.add_argument("--quiet", action="store_true", help="no progress bars")
    e = sub.add_parser(
        "eval",
        help="relation error of a trajectory against a reference (Kümmerle et al. 2009)",
        description="Relation metric on consecutive reference poses: translation [m] and "
        "rotation [deg], mean ± std and max.",
    )
    e.add_argument("--estimate", required=True, help="estimated trajectory (TUM file)")
    e.add_argument(
        "--reference",
        required=True,
        help="reference: a TUM file, or a benchmark index CSV (its corrected poses)",
    )
    e.add_argument(
        "--reference-time",
        choices=["auto", "raw_scan", "gfs_scan", "ipc_ts"],
        default="auto",
        help="index CSV column matched with the estimate's timestamps: raw_scan (the "
        "full-rate log's scan number), gfs_scan (the corrected log's scan number) or "
        "ipc_ts (time); auto: raw_scan when every estimate timestamp is an integer (scan "
        "numbers, as `ndtgrid map` writes for logs without time, e.g. the benchmark "
        "splits), else ipc_ts. A corrected log whose times are out of order is numbered "
        "by scan too: pair it by gfs_scan",
    )
    e.add_argument(
        "--max-dt", type=_seconds, default=0.05, help="largest time gap of a matched pose [s]"
    )
    e.add_argument("--json", action="store_true", help="print the summary as JSON")
    return parser


def usable_ranges(scan: Scan) -> npt.NDArray[np.float64]:
    """The scan's ranges with readings at or beyond its ``max_range`` (e.g. a LaserScan's
    ``range_max``: no return) replaced by NaN, which the odometry skips; shape (B,) [m]."""
    if scan.max_range is None:
        return scan.ranges
    return np.where(scan.ranges < scan.max_range, scan.ranges, np.nan)


def map_scans(
    scans: Iterable[Scan],
    out: Path,
    *,
    cell_size: float,
    resolution: float,
    quiet: bool,
    title: str,
) -> tuple[Odometry, float] | None:
    """Run :class:`~ndtgrid.Odometry` over ``scans`` and write the map files to ``out``.

    Writes ``map.png``, ``map.pgm`` + ``map.yaml``, ``trajectory.tum`` and ``map.ndtgrid``.
    Returns the odometry and the seconds it took, or ``None`` when there was no scan.
    """
    # Made first, so that a directory that cannot be made fails before the mapping;
    # removed again when this run made it and the mapping fails.
    made = not out.exists()
    out.mkdir(parents=True, exist_ok=True)
    try:
        done = _map_into(scans, out, cell_size, resolution, quiet, title)
    except BaseException:
        if made:
            _remove_if_empty(out)
        raise
    if done is None and made:
        _remove_if_empty(out)
    return done


def _remove_if_empty(path: Path) -> None:
    with contextlib.suppress(OSError):  # not empty (or gone): leave it
        path.rmdir()


def _map_into(
    scans: Iterable[Scan], out: Path, cell_size: float, resolution: float, quiet: bool, title: str
) -> tuple[Odometry, float] | None:
    """The body of :func:`map_scans`, into the directory ``out``, which exists."""
    from ndtgrid import NdtGrid, Odometry
    from ndtgrid._core import FreeSpace
    from ndtgrid.export import occupancy_image, save_map, write_png, write_ros_map, write_tum

    odo = Odometry(cell_size=cell_size)
    cfg = odo.config
    # The odometry's map is bounded (map_window); the exported map keeps every added scan.
    full = NdtGrid(cell_size)
    free = FreeSpace(resolution)
    times: list[float] = []
    start = time.perf_counter()
    for i, scan in enumerate(progress(scans, quiet, "mapping")):
        prior = scan.laser_pose if scan.laser_pose is not None else scan.odom
        pose = odo.step(usable_ranges(scan), scan.angles, prior)
        step = odo.last_step
        if step is not None and step.inserted:
            limit = cfg.max_range if scan.max_range is None else min(cfg.max_range, scan.max_range)
            pts = scan.points(min_range=cfg.min_range, max_range=limit)
            full.insert(pts, pose)
            free.add_scan(pts, pose)
        # Logs without time (benchmark splits) get the scan index as timestamp.
        times.append(scan.timestamp if math.isfinite(scan.timestamp) else float(i))
    elapsed = time.perf_counter() - start
    poses = odo.poses
    if poses.shape[0] == 0:
        return None
    stamps = np.asarray(times)
    unordered = int(np.sum(np.diff(stamps) <= 0))
    if unordered:  # repeated or unordered stamps: number the scans instead
        stamps = np.arange(len(times), dtype=np.float64)
        print(
            f"ndtgrid map: the log's times go back or repeat in {unordered} places, so "
            "trajectory.tum numbers the scans (0, 1, ...) instead (ndtgrid eval pairs them "
            "with an index CSV by --reference-time raw_scan for a full-rate log, gfs_scan "
            "for a corrected one)",
            file=sys.stderr,
        )
    write_tum(out / "trajectory.tum", stamps, poses)
    save_map(out / "map.ndtgrid", full)
    centres, _ = full.cells()
    image = occupancy_image(free, centres)
    write_ros_map(out / "map.yaml", image)
    write_png(out / "map.png", image, trajectory=poses, title=title)
    print(
        f"{poses.shape[0]} scans in {elapsed:.1f} s ({1e3 * elapsed / poses.shape[0]:.2f} ms "
        f"per scan), {odo.insertions} added to the map, {len(full)} cells; wrote "
        f"map.png, map.pgm, map.yaml, trajectory.tum, map.ndtgrid to {out}"
    )
    return odo, elapsed


def run_map(args: argparse.Namespace) -> int:
    """``ndtgrid map``: see :func:`build_parser`."""
    import itertools

    from ndtgrid.io import read_log

    scans: Iterable[Scan] = read_log(args.log, format=args.format)
    if args.max_scans is not None:
        scans = itertools.islice(scans, args.max_scans)
    done = map_scans(
        scans,
        Path(args.out),
        cell_size=args.cell_size,
        resolution=args.resolution,
        quiet=args.quiet,
        title=Path(args.log).name,
    )
    if done is None:
        print(f"ndtgrid map: {args.log}: no scans", file=sys.stderr)
        return 1
    return 0


def run_demo(args: argparse.Namespace) -> int:
    """``ndtgrid demo``: see :func:`build_parser`."""
    from ndtgrid import sim
    from ndtgrid.evaluation import anchored_errors

    room = sim.sticks_room()
    truth = sim.trajectory(room.tour, step=0.05)
    odom = sim.odometry(truth, drift=0.02, seed=args.seed)
    stream = sim.scan_ranges(room, sim.URG04LX, truth, seed=args.seed)
    ranges = list(progress(stream, args.quiet, "simulating", total=len(truth)))
    angles = sim.URG04LX.angles
    scans = [
        Scan(
            timestamp=0.1 * k,
            ranges=r,
            angles=angles,
            odom=o,
            max_range=sim.URG04LX.max_range,
            source="sim",
            line=k + 1,
        )
        for k, (r, o) in enumerate(zip(ranges, odom))
    ]
    done = map_scans(
        scans,
        Path(args.out),
        cell_size=0.02,
        resolution=0.02,
        quiet=args.quiet,
        title="simulated sticks room (URG-04LX)",
    )
    if done is None:
        return 1
    odo, _ = done
    # Both trajectories start at the first pose (the odometry's frame is the first
    # odometry reading); compare in that frame.
    err = anchored_errors(odo.poses, truth)
    odo_err = anchored_errors(odom, truth)
    objects = odo.mapper.small_objects()
    print(
        f"pose error against the truth: {100 * np.sqrt(np.mean(err**2)):.2f} cm RMS, "
        f"{100 * err.max():.2f} cm max (odometry alone: {100 * odo_err.max():.1f} cm max); "
        f"{len(objects)} small objects found, {len(room.sticks)} sticks in the room"
    )
    return 0


def run_bench(args: argparse.Namespace) -> int:
    """``ndtgrid bench``: see :func:`build_parser`."""
    from ndtgrid import bench

    def bars(items: Iterable[T], label: str, total: int) -> Iterator[T]:
        return progress(items, args.quiet, label, total=total)

    try:
        report = bench.run_bench(args.scans, seed=args.seed, repeats=args.repeats, progress=bars)
    except ValueError as err:
        print(f"ndtgrid bench: {err}", file=sys.stderr)
        return 2
    except RuntimeError as err:  # a thread could not be pinned to its CPU
        print(f"ndtgrid bench: {err}", file=sys.stderr)
        return 1
    print(json.dumps(report.as_dict()) if args.json else report.table())
    return 0


def run_eval(args: argparse.Namespace) -> int:
    """``ndtgrid eval``: see :func:`build_parser`."""
    from ndtgrid.evaluation import associate, relation_errors
    from ndtgrid.export import read_tum
    from ndtgrid.io import read_benchmark_index

    times, poses = read_tum(args.estimate)
    if args.reference.endswith(".csv"):
        index = read_benchmark_index(args.reference)
        column = args.reference_time
        if column == "auto":
            column = "raw_scan" if np.all(times == np.round(times)) else "ipc_ts"
        columns = {"raw_scan": index.raw_scan, "gfs_scan": index.corrected_scan}
        ref_times = columns.get(column, index.timestamp).astype(np.float64)
        ref_poses = index.corrected
    else:
        ref_times, ref_poses = read_tum(args.reference)
    match = associate(times, ref_times, max_dt=args.max_dt)
    ok = match >= 0
    if ok.sum() < 2:
        print(
            f"ndtgrid eval: only {int(ok.sum())} reference poses have an estimate within "
            f"{args.max_dt} (check --reference-time / --max-dt)",
            file=sys.stderr,
        )
        return 1
    summary = relation_errors(poses[match[ok]], ref_poses[ok]).summary()
    if args.json:
        print(json.dumps(summary.__dict__))
    else:
        print(f"relations: {summary}")
        skipped = int((~ok).sum())
        if skipped:
            print(f"({skipped} reference poses without an estimate within {args.max_dt})")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` when omitted.

    Returns
    -------
    int
        Exit status.
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    commands = {"map": run_map, "eval": run_eval, "demo": run_demo, "bench": run_bench}
    run = commands.get(args.command)
    if run is None:
        parser.print_help()
        return 0
    try:
        return run(args)
    except (OSError, EOFError, ValueError) as err:
        # A file that is missing, unreadable, truncated or not a log, or a bad
        # value: the readers' and the core's messages name it, without a traceback.
        print(f"ndtgrid {args.command}: {err}", file=sys.stderr)
        return 1
