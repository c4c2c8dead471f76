"""Speed of ndtgrid against its peers, in one run, on the same scans and the same machine.

Issue 7 ("Speed: ahead of every peer ... proven by benchmarks"). Sections, each printed
as a Markdown table to stdout as soon as it is measured (progress goes to stderr):

1. **Match**: our default ``NdtGrid.match`` on a 2 cm grid against every peer of
   ``benches/peers.py`` (small_gicp GICP / VGICP, Open3D ICP) from the same local starts
   (±5 cm, ±2°), on real scan pairs (Intel, ACES, FR079, MIT CSAIL; the URG-04LX log),
   and scan-to-map with maps of the previous 20 scans (real URG-04LX log, simulated
   683-beam URG-04LX). Success rate, time per align call (target built once per map,
   the peers' own preprocessing of the source scan timed), ratio peer / ours.
2. **Map update**: inserting one scan into a 2 cm ``NdtGrid`` that holds many scans and
   has its distributions built (a match ran before each insert, as in a SLAM loop)
   against ``small_gicp.GaussianVoxelMap.insert`` and KISS-ICP's ``VoxelHashMap.update``
   of the same scan.
3. **Odometry over the whole Intel log** (13,631 scans): ``ndtgrid.Odometry(cell_size=0.02)``
   (each run in a fresh child process, which also reports the run's peak resident memory;
   the default loop, the loop with its mapper in line and the loop with no map at all,
   ``build_map=False``, three times each, alternating, each judged on its median run)
   against the
   small_gicp voxel-map odometry of ``benches/datasets.py`` and KISS-ICP (when
   ``kiss-icp`` is installed), with the relation error of each. KISS-ICP at its default
   voxel, the fastest peer, runs right after each of our runs (with either prior) and is
   judged on its median run too, so the machine's drift falls on both sides alike.
4. **Sweeps**: match time against the number of scan points (simulated scans, 100-4000
   beams, one map) and against the map's size (real Intel maps of 1-880 scans, then far
   away copies of the whole map; within each, every start is matched on every size in
   turn); linear fits; a plot in ``docs/img/speed_sweeps.png`` when matplotlib is
   installed.
5. **Threads**: matches per second of two Python threads matching different scans
   against one grid, against one thread, twice: threads started for each run where the
   kernel puts them, and two long-lived worker threads pinned to the two cores
   (``benches/pinned.py``); the same scans in one ``NdtGrid.match_many`` call on one
   thread and on every core; last, threads that keep matching for a second a round,
   started where the kernel puts them (``benches/steady.py``), as a SLAM loop's threads
   live; two GIL-free controls in the same run (SHA-256, and our
   matcher on bundles of 20 scans merged into one, whose calls are long enough that the
   GIL hardly matters); in how many runs the kernel had both unpinned threads on one
   vCPU half-way through; each run's ratios and late starts in
   ``docs/img/speed_threads.png`` when matplotlib is installed.
6. **Memory**: bytes per occupied fine cell (RSS growth of a fresh child process divided by
   ``len(grid)``) before and after the distributions are built.

Sections 1-3 are then drawn in one picture, ``docs/img/speed_peers.png`` when matplotlib
is installed: every method's median match per case set with its success rate, every
map's update of one scan, every loop's time over the Intel log with its relation error.
A table of the issue's targets (their limits in ``benches/targets.py``) against this
run's numbers closes the output; ``benches/speed_runs.py`` tables many runs' ``--json``.

Run from the repository root (needs ``pip install -e ".[bench]"`` and
``../shared/data/real``; Open3D's wheel also needs the system's ``libusb-1.0``, on
Debian ``apt-get install libusb-1.0-0``, or its peers are skipped with the loader's
error; about 4 min on 2 shared cores, ``--quick`` under 1 min)::

    python benches/speed.py > out/speed.md
    python benches/speed.py --quick --sections match threads
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import functools
import gc
import hashlib
import importlib.metadata
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt

sys.path.insert(0, str(Path(__file__).resolve().parent))

import convergence
import datasets
import peers as peer_lib
import pinned
import speed_plots
import steady
import steal
import targets as tg

import ndtgrid
from ndtgrid import se2, sim
from ndtgrid.evaluation import RelationSummary, pose_error, relation_errors
from ndtgrid.io import Scan, read_benchmark_index, read_benchmark_split, read_carmen, read_mines

F64 = npt.NDArray[np.float64]
T = TypeVar("T")

ROOT = Path(__file__).resolve().parents[1]
REAL = Path(__file__).resolve().parents[2] / "shared" / "data" / "real"
URG_LOG = REAL / "breezyslam-mines-urg04lx" / "exp1.dat"
INTEL_SPLIT = REAL / "benchmark-scans-split" / "intel.tar.gz"
INTEL_INDEX = REAL / "benchmark-scans-split" / "intel__intel-corrected__index.csv"
INTEL_CORRECTED = REAL / "radish-gfs-corrected" / "intel-corrected.log.gz"
# Scans merged into one for the thread section's second control.
THREAD_BUNDLE = 20
# s: a two-thread run whose second thread's first match began this long after the clock
# counts as started late (benches/SPEED_LOG.md, session 46: such runs had a median
# ratio of 1.46 against 1.78).
LATE_START = 1e-3

SECTIONS = ("match", "insert", "odometry", "sweeps", "threads", "memory")
CELL = 0.02  # m: our grid, the paper's 2 cm
URG_RANGE = 4.0  # m: URG-04LX points used (as benches/convergence.py)
WINDOW = 20  # scans in a scan-to-map case's map
FAR = 1000.0  # m: offset of the far copies that only grow a map
NOTES: dict[str, str] = {}  # per case set, printed under its table


# ----------------------------------------------------------------------------- helpers


def log(msg: str) -> None:
    """Progress to stderr."""
    print(msg, file=sys.stderr, flush=True)


def progress(items: Iterable[T], desc: str, total: int | None = None) -> Iterator[T]:
    """``items`` with a progress bar on stderr (tqdm when importable)."""
    try:
        from tqdm import tqdm
    except ImportError:
        log(f"{desc} ...")
        yield from items
        return
    yield from tqdm(items, desc=desc, total=total, file=sys.stderr, mininterval=2.0, leave=False)


@contextlib.contextmanager
def no_gc() -> Iterator[None]:
    """Keep the cyclic collector out of the timed block (sections collect at their start)."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def out(lines: str | Sequence[str] = "") -> None:
    """Markdown to stdout, flushed (a section appears as soon as it is measured)."""
    print(lines if isinstance(lines, str) else "\n".join(lines), flush=True)


def plotted(path: Path | None) -> None:
    """Names a plot written at ``path`` in the output, or says that matplotlib is absent
    (``path`` ``None``)."""
    if path is None:
        out("\n(matplotlib absent: no plot.)")
        return
    shown = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
    out(f"\nPlot: `{shown}`.")


def ms(seconds: float) -> str:
    """Seconds as milliseconds with 3 significant-ish digits."""
    v = 1e3 * seconds
    return f"{v:.3f}" if v < 1 else f"{v:.2f}" if v < 100 else f"{v:.0f}"


def us(seconds: float) -> str:
    """Seconds as microseconds."""
    v = 1e6 * seconds
    return f"{v:.2f}" if v < 10 else f"{v:.1f}" if v < 1000 else f"{v:.0f}"


def ratio(a: float, b: float) -> str:
    """``a / b`` with a multiplication sign, e.g. ``2.50×`` (``-`` when undefined)."""  # noqa: RUF002
    if not (math.isfinite(a) and math.isfinite(b)) or b <= 0:
        return "-"
    return f"{a / b:.2f}×"


def json_ready(value: Any) -> Any:
    """``value`` as what strict JSON holds: dicts with string keys, lists for tuples and
    arrays, Python numbers for NumPy's, ``None`` for NaN and infinities (``--json``)."""
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [json_ready(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(
    path: Path, machine: str, sections: dict[str, dict[str, Any]], complete: bool
) -> None:
    """The sections run so far as ``--json``'s document at ``path``: ``machine`` (the
    run's header names it), the command line, ``complete`` (false until every section
    asked for has run and the targets are judged) and the sections. Written to a file
    beside ``path`` and renamed over it, so a reader never sees half a document; if
    the write or the rename fails (a full disk, Ctrl-C), that file is removed and
    ``path`` keeps the last whole document."""
    doc = {
        "machine": machine,
        "argv": sys.argv[1:],
        "complete": complete,
        "sections": sections,
    }
    datasets.write_whole(path, json.dumps(json_ready(doc), indent=1, allow_nan=False) + "\n")


def rss_kib() -> tuple[int, int]:
    """(VmRSS, VmHWM) of this process [KiB] from ``/proc/self/status`` (0 if absent)."""
    now = peak = 0
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    now = int(line.split()[1])
                elif line.startswith("VmHWM:"):
                    peak = int(line.split()[1])
    except OSError:
        pass
    return now, peak


def apply(pose: npt.ArrayLike, pts: F64) -> F64:
    """Scan-frame points seen from ``pose`` in the map frame."""
    return convergence.apply(np.asarray(pose, dtype=float), pts)


def bundle_scans(
    pts: Sequence[F64], poses: F64, size: int, rng: np.random.Generator
) -> list[tuple[F64, F64]]:
    """Bundles of ``size`` consecutive scans, each merged into one scan in the frame of
    its middle scan (the ``size // 2``-th), as ``(points, start)`` pairs; each start is
    ±5 cm, ±2° off the middle scan's pose, drawn from ``rng`` bundle after bundle. The
    scans after the last whole bundle are left out. The thread section's GIL-free
    control (``THREAD_BUNDLE`` scans) and ``benches/large_bundles.py`` match them.

    Raises
    ------
    ValueError
        If ``size`` is below 1.
    """
    if size < 1:
        raise ValueError(f"a bundle holds at least 1 scan, not {size}")
    bundles = []
    for k in range(0, len(pts) - size + 1, size):
        ref = poses[k + size // 2]
        merged = np.vstack([apply(se2.between(ref, poses[j]), pts[j]) for j in range(k, k + size)])
        bundles.append((merged, ref + convergence.starts(rng, 1, 0.05, 2.0)[0]))
    return bundles


def linear_fit(x: npt.ArrayLike, y: npt.ArrayLike) -> tuple[float, float, float]:
    """Least-squares ``y = slope * x + intercept``; returns slope, intercept, R²."""
    xa, ya = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    slope, intercept = np.polyfit(xa, ya, 1)
    pred = slope * xa + intercept
    ss = float(np.sum((ya - ya.mean()) ** 2))
    r2 = 1.0 - float(np.sum((ya - pred) ** 2)) / ss if ss > 0 else 1.0
    return float(slope), float(intercept), r2


def open3d_inplane_peer() -> list[peer_lib.Peer]:
    """Open3D point-to-plane ICP (gates 1.0 → 0.25 → 0.1 m) with in-plane target normals.

    ``peers.py`` estimates the normals of the lifted target from its 10 nearest
    neighbours: fine on one scan, but on a map of many scans those neighbours all lie in
    one z layer along the wall and nearly every normal comes out along z (measured: 99 %
    of them on the simulated 20-scan maps), which leaves the solver unconstrained in the
    plane. Here each normal is the smallest eigenvector of the xy block of the same
    neighbourhood's covariance (z = 0): the wall normal. Everything else as ``peers.py``.
    """
    try:
        import open3d as o3d
    except ImportError:
        return []
    reg = o3d.pipelines.registration

    def prepare(target: F64) -> Any:
        pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(peer_lib.lift(target)))
        pc.estimate_covariances(o3d.geometry.KDTreeSearchParamKNN(10))
        _, vecs = np.linalg.eigh(np.asarray(pc.covariances)[:, :2, :2])
        normals = np.c_[vecs[:, :, 0], np.zeros(len(vecs))]
        pc.normals = o3d.utility.Vector3dVector(normals)
        return pc

    def align(state: Any, pts: F64, guess: F64) -> F64:
        src = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(peer_lib.lift(pts)))
        t = peer_lib.to_matrix(guess)
        for gate in (1.0, 0.25, 0.1):
            t = reg.registration_icp(
                src,
                state,
                gate,
                t,
                reg.TransformationEstimationPointToPlane(),
                reg.ICPConvergenceCriteria(max_iteration=30),
            ).transformation
        return peer_lib.to_pose(np.asarray(t))

    return [
        peer_lib.Peer("Open3D ICP point-to-plane, in-plane normals (1.0→0.1 m)", prepare, align)
    ]


def all_peers() -> list[peer_lib.Peer]:
    """``peers.all_peers()`` and the in-plane-normal Open3D variant."""
    return [*peer_lib.all_peers(), *open3d_inplane_peer()]


def our_matcher(cell: float = CELL) -> peer_lib.Peer:
    """Our default ``match()`` as a peer (``prepare`` builds the distributions once)."""
    return convergence.ours(f"ndtgrid {100 * cell:g} cm, default match()", cell)


def urg_scans() -> list[Scan]:
    """The scans of the real URG-04LX log (``exp1.dat``)."""
    return list(read_mines(URG_LOG))


_URG_POSES: F64 | None = None


def urg_poses(scans: list[Scan]) -> F64:
    """Laser poses of the URG log from ``ndtgrid.Odometry`` (defaults, 2 cm), cached."""
    global _URG_POSES
    if _URG_POSES is None or len(_URG_POSES) != len(scans):
        odo = ndtgrid.Odometry(cell_size=CELL)
        for s in progress(scans, "URG log through Odometry (poses for its maps)"):
            odo.step(s.ranges, s.angles, s.laser_pose)
        _URG_POSES = odo.poses
    return _URG_POSES


@functools.lru_cache(maxsize=4)
def sim_urg_scans(count: int, seed: int, beams: int = 683) -> tuple[list[F64], F64]:
    """``count`` simulated URG-04LX scans (``beams`` beams) along the sticks room's tour,
    5 cm apart: scan-frame points and true laser poses."""
    room = sim.sticks_room()
    poses = sim.trajectory(room.tour, step=0.05)[:count]
    laser = dataclasses.replace(sim.URG04LX, num_beams=beams)
    rng = np.random.default_rng(seed)
    pts = []
    for p in poses:
        r, a = laser.scan(room, p, rng=rng)
        pts.append(ndtgrid.ranges_to_points(r, a, max_range=laser.max_range))
    return pts, np.asarray(poses)


# ----------------------------------------------------------------------------- 1. match


@dataclass
class MethodRun:
    """Times and successes of one method over one case set."""

    name: str
    times: list[float] = field(default_factory=list)
    hits: int = 0

    @property
    def n(self) -> int:
        return len(self.times)

    @property
    def median(self) -> float:
        return float(np.median(self.times)) if self.times else math.nan

    def pct(self, q: float) -> float:
        return float(np.percentile(self.times, q)) if self.times else math.nan


def run_cases(
    cases: list[convergence.Pair],
    methods: list[peer_lib.Peer],
    starts: int,
    rng: np.random.Generator,
    desc: str,
) -> list[MethodRun]:
    """Every method from the same local starts (±5 cm, ±2°) on every case; time the
    align calls only (one untimed warm-up align per method and case first)."""
    deltas = [convergence.starts(rng, starts, 0.05, 2.0) for _ in cases]
    runs = [MethodRun(m.name) for m in methods]
    for case, delta in progress(list(zip(cases, deltas)), desc):
        for m, r in zip(methods, runs):
            state = m.prepare(case.target)
            m.align(state, case.source, case.truth + delta[0])  # warm-up, untimed
            with no_gc():
                for d in delta:
                    t0 = time.perf_counter()
                    pose = m.align(state, case.source, case.truth + d)
                    r.times.append(time.perf_counter() - t0)
                    et, er = pose_error(pose, case.truth)
                    r.hits += bool(et < case.tol[0] and er < case.tol[1])
    return runs


def match_table(title: str, cases: list[convergence.Pair], runs: list[MethodRun]) -> dict[str, Any]:
    """Print one match table; return our median and the fastest peers' for the targets."""
    npts = np.array([len(c.source) for c in cases])
    tol = cases[0].tol
    out(
        [
            f"\n### {title}\n",
            f"{len(cases)} cases ({', '.join(sorted({c.group for c in cases}))}), "
            f"{runs[0].n // max(len(cases), 1)} starts each; source scans "
            f"{npts.min()}–{npts.max()} points (median {np.median(npts):.0f}); success: "
            f"< {100 * tol[0]:g} cm and < {np.degrees(tol[1]):g}°.\n",
            "| method | success | median [ms] | p10 [ms] | p90 [ms] | µs / point "
            "| ratio (method / ours) |",
            "|---|---:|---:|---:|---:|---:|---:|",
        ]
    )
    ours = runs[0]
    for r in runs:
        out(
            f"| {r.name} | {100 * r.hits / r.n:.0f} % ({r.hits}/{r.n}) | {ms(r.median)} "
            f"| {ms(r.pct(10))} | {ms(r.pct(90))} | {1e6 * r.median / np.median(npts):.2f} "
            f"| {ratio(r.median, ours.median)} |"
        )
    peers = runs[1:]
    res: dict[str, Any] = {
        "ours": ours.median,
        "ours_success": ours.hits / ours.n,
        "methods": [(r.name, r.median, r.hits / r.n) for r in runs],
    }
    if peers:
        fastest = min(peers, key=lambda r: r.median)
        good = [r for r in peers if r.hits >= ours.hits]
        res["fastest"] = (fastest.name, fastest.median)
        line = (
            f"\nFastest peer: {fastest.name}, {ms(fastest.median)} ms = "
            f"{ratio(fastest.median, ours.median)} our median"
        )
        if good:
            fg = min(good, key=lambda r: r.median)
            res["fastest_good"] = (fg.name, fg.median)
            line += (
                f"; fastest peer with success ≥ ours: {fg.name}, {ratio(fg.median, ours.median)}"
            )
        else:
            line += "; no peer reached our success here"
        out(line + ".")
    return res


def urg_map_cases(scans: list[Scan], count: int) -> list[convergence.Pair]:
    """Scan-to-map cases of the real URG log: the map is the previous ``WINDOW`` scans at
    ``ndtgrid.Odometry``'s poses, the source the next scan. Reference: where small_gicp
    GICP and Open3D point-to-plane ICP with in-plane normals, started from our odometry
    pose, agree within 1 cm and 0.3° (their mean; cases where they disagree are dropped),
    as ``convergence.urg_pairs`` does for its pairs. Success: < 2 cm and < 0.5°."""
    poses = urg_poses(scans)
    pts = [s.points(max_range=URG_RANGE) for s in scans]
    candidates = 0
    judges = [
        p for p in all_peers() if p.name.startswith("small_gicp GICP") or "in-plane" in p.name
    ]
    cases = []
    for k in progress(
        np.linspace(WINDOW, len(scans) - 1, count).astype(int), "URG map cases (consensus)"
    ):
        target = np.vstack([apply(poses[j], pts[j]) for j in range(k - WINDOW, k)])
        if len(judges) < 2 or len(pts[k]) < 100:
            continue
        candidates += 1
        votes = [j.align(j.prepare(target), pts[k], poses[k]) for j in judges]
        dt, dr = pose_error(votes[0], votes[1])
        if dt < 0.01 and dr < np.radians(0.3):
            truth = np.mean(votes, axis=0)
            cases.append(
                convergence.Pair(
                    "URG-04LX exp1, map of 20 scans", target, pts[k], truth, (0.02, np.radians(0.5))
                )
            )
    NOTES["urg_map"] = (
        f"The two judges agreed on {len(cases)} of {candidates} candidate scans (the others "
        "are dropped: on this log the maps built at our odometry poses often leave them "
        "centimetres or more apart)."
    )
    return cases


def sim_map_cases(count: int, seed: int) -> list[convergence.Pair]:
    """Scan-to-map cases of the simulator: 683-beam URG-04LX scans of the sticks room,
    5 cm apart; the map is the previous ``WINDOW`` scans at their true poses. Success:
    < 2 cm and < 0.5° (the truth is exact)."""
    pts, poses = sim_urg_scans(10_000, seed)
    cases = []
    for k in np.linspace(WINDOW, len(pts) - 1, count).astype(int):
        target = np.vstack([apply(poses[j], pts[j]) for j in range(k - WINDOW, k)])
        cases.append(
            convergence.Pair(
                "sim URG-04LX 683 beams, map of 20 scans",
                target,
                pts[k],
                poses[k],
                (0.02, np.radians(0.5)),
            )
        )
    return cases


def urg_log_maps(
    seed: int, step: int = 1, min_points: int = 0
) -> Iterator[tuple[ndtgrid.NdtGrid, F64, F64]]:
    """The scan-to-map cases of :func:`urg_log_times`: for every ``step``-th scan of the
    real URG log with at least ``min_points`` points, a 2 cm map of the previous
    ``WINDOW`` scans at ``ndtgrid.Odometry``'s poses (distributions built), the scan's
    points and one local start around its pose. A start is drawn for every scan, kept or
    not, so a scan's start is the same whatever ``min_points``."""
    scans = urg_scans()
    poses = urg_poses(scans)
    pts = [s.points(max_range=URG_RANGE) for s in scans]
    rng = np.random.default_rng(seed)
    for k in progress(range(WINDOW, len(scans), step), "URG log: map of 20, every scan"):
        guess = poses[k] + convergence.starts(rng, 1, 0.05, 2.0)[0]
        if len(pts[k]) < min_points:
            continue
        grid = ndtgrid.NdtGrid(CELL)
        for j in range(k - WINDOW, k):
            grid.insert(pts[j], poses[j])
        grid.match(pts[k - 1], poses[k - 1])  # build the distributions
        yield grid, pts[k], guess


def urg_log_times(args: argparse.Namespace) -> dict[str, Any]:
    """Our match time over the whole real URG log, binned by the scan's points: each scan
    against a 2 cm map of the previous ``WINDOW`` scans (at ``ndtgrid.Odometry``'s poses),
    from one local start around its odometry pose. Time only (no reference needed)."""
    step = 4 if args.quick else 1
    npts, times = [], []
    for grid, points, guess in urg_log_maps(args.seed + 4, step):
        with no_gc():
            t0 = time.perf_counter()
            grid.match(points, guess)
            times.append(time.perf_counter() - t0)
        npts.append(len(points))
    n, t = np.array(npts), np.array(times)
    out(
        [
            "\n### Ours over the whole real URG-04LX log, by scan size\n",
            f"Every {'4th ' if step > 1 else ''}scan of `exp1.dat` ({len(n)} scans; 682 "
            f"beams, of which {n.min()}–{n.max()} give a point under {URG_RANGE:g} m) "
            f"against a 2 cm map of the previous {WINDOW} scans at our odometry's poses, "
            "one local start each; default `match()`; time only.\n",
            "| valid points | scans | median [ms] | p90 [ms] | µs / point |",
            "|---|---:|---:|---:|---:|",
        ]
    )
    res: dict[str, Any] = {}
    for lo, hi in ((0, 200), (200, 350), (350, 500), (500, 10_000)):
        sel = (n >= lo) & (n < hi)
        if sel.any():
            med = float(np.median(t[sel]))
            label = f"{lo}–{hi - 1}" if hi < 10_000 else f"≥ {lo}"
            out(
                f"| {label} | {int(sel.sum())} | {ms(med)} "
                f"| {ms(float(np.percentile(t[sel], 90)))} "
                f"| {1e6 * med / np.median(n[sel]):.2f} |"
            )
            res[label] = (med, float(np.median(n[sel])))
    out(f"| all | {len(n)} | {ms(float(np.median(t)))} | {ms(float(np.percentile(t, 90)))} | |")
    return res


def no_cases_reason(key: str, names: Sequence[str]) -> str:
    """Why the case set ``key`` came out empty: its log is absent, or (for the URG sets,
    whose reference is the consensus of small_gicp GICP and Open3D ICP) a judge is;
    ``names``: the methods that imported."""
    if key.startswith("urg") and URG_LOG.exists():
        missing = [
            judge
            for judge, prefix in (("small_gicp GICP", "small_gicp"), ("Open3D ICP", "Open3D"))
            if not any(n.startswith(prefix) for n in names)
        ]
        if missing:
            return (
                f"its reference needs two judges and {' and '.join(missing)} did not import: "
                "see the 'peer skipped' line above"
            )
        return "the judges agreed on no candidate"
    return "data absent"


def section_match(args: argparse.Namespace) -> dict[str, Any]:
    """Section 1."""
    out("\n## 1. Match: ours against the peers, same scans, same starts\n")
    out(
        "One thread; time of the align call only (our `match`, a peer's `align` including "
        "its preprocessing of the source scan); the target (map) is built once per case "
        "and not timed; one untimed warm-up align per method and case. Local starts: "
        "uniform in ±5 cm, ±2° around the reference, the same for every method. Peers set "
        "up as `benches/peers.py` documents (3-layer z-extrusion, coarse-to-fine gates, "
        "1 cm merge only), plus Open3D point-to-plane with in-plane target normals "
        "(`open3d_inplane_peer`: on a map of many scans the 10 nearest neighbours of a "
        "lifted point lie in one z layer, and `peers.py`'s normals point along z; on a "
        "single sparse scan the neighbours span the three layers and `peers.py`'s normals "
        "are the better ones). "
        "Ratio: the method's median time / ours."
    )
    methods = [our_matcher(), *all_peers()]
    rng = np.random.default_rng(args.seed)
    res: dict[str, Any] = {}
    sets: list[tuple[str, str, Callable[[], list[convergence.Pair]]]] = [
        (
            "sick",
            "Real SICK pairs (scan to scan), local starts",
            lambda: list(convergence.real_pairs(args.pairs)),
        ),
        (
            "urg_pairs",
            "Real URG-04LX pairs (scan to scan, `convergence.urg_pairs` peer-consensus "
            "reference), local starts",
            lambda: list(convergence.urg_pairs(args.urg_cases)),
        ),
        (
            "urg_map",
            "Real URG-04LX scan to a map of the previous 20 scans "
            "(peer-consensus reference), local starts",
            lambda: urg_map_cases(urg_scans(), args.urg_cases) if URG_LOG.exists() else [],
        ),
        (
            "sim_map",
            "Simulated 683-beam URG-04LX scan to a map of the previous 20 scans "
            "(exact truth), local starts",
            lambda: sim_map_cases(args.sim_cases, args.seed),
        ),
    ]
    for key, title, make in sets:
        cases = make()
        if not cases:
            out(f"\n{title}: no cases ({no_cases_reason(key, [m.name for m in methods])}).")
            continue
        runs = run_cases(cases, methods, args.starts, rng, key)
        res[key] = match_table(title, cases, runs)
        if key in NOTES:
            out("\n" + NOTES[key])
        res[key]["points"] = float(np.median([len(c.source) for c in cases]))
    if URG_LOG.exists():
        res["urg_log"] = urg_log_times(args)
    return res


# ----------------------------------------------------------------------------- 2. insert


#: Scans per ``insert_many`` call in section 2.
BATCH = 16


def insert_set(
    name: str, pts: list[F64], poses: F64, prefill: int, count: int
) -> tuple[list[tuple[str, list[float], list[float]]], int]:
    """Insert times of ours and the peers' maps: ``prefill`` scans first, then ``count``
    scans one by one, each timed. Returns the rows (method, per-scan times,
    preprocessing times) and the cells of our map at the end."""
    rows: list[tuple[str, list[float], list[float]]] = []
    n = min(len(pts), prefill + count)
    grid = ndtgrid.NdtGrid(CELL)
    for j in range(prefill):
        grid.insert(pts[j], poses[j])
    times: list[float] = []
    for j in progress(range(prefill, n), f"{name}: ndtgrid insert"):
        grid.match(pts[j], poses[j])  # the loop's match: distributions built, untimed
        with no_gc():
            t0 = time.perf_counter()
            grid.insert(pts[j], poses[j])
            times.append(time.perf_counter() - t0)
    rows.append(("ndtgrid `NdtGrid(0.02).insert`", times, []))
    # The same scans in batches of BATCH through insert_many, into a map of the same
    # prefill; each batch's first scan matched first (untimed), each batch's time
    # divided by its scans: one sample per batch.
    batched = ndtgrid.NdtGrid(CELL)
    for j in range(prefill):
        batched.insert(pts[j], poses[j])
    per_scan: list[float] = []
    starts = range(prefill, n - BATCH + 1, BATCH)
    for j in progress(starts, f"{name}: ndtgrid insert_many"):
        batched.match(pts[j], poses[j])
        with no_gc():
            t0 = time.perf_counter()
            batched.insert_many(pts[j : j + BATCH], poses[j : j + BATCH])
            per_scan.append((time.perf_counter() - t0) / BATCH)
    rows.append(
        (f"ndtgrid `NdtGrid(0.02).insert_many`, batches of {BATCH} (per scan)", per_scan, [])
    )
    try:
        import small_gicp
    except ImportError:
        log("small_gicp absent: its insert skipped")
    else:
        for voxel in (0.2, 0.02):
            vm = small_gicp.GaussianVoxelMap(voxel)
            for j in range(prefill):
                c, _ = small_gicp.preprocess_points(
                    peer_lib.lift(pts[j]), peer_lib.MERGE, num_neighbors=10
                )
                vm.insert(c, peer_lib.to_matrix(poses[j]))
            t_ins, t_pre = [], []
            for j in progress(range(prefill, n), f"{name}: small_gicp {voxel} m"):
                lifted = peer_lib.lift(pts[j])
                mat = peer_lib.to_matrix(poses[j])
                with no_gc():
                    t0 = time.perf_counter()
                    c, _ = small_gicp.preprocess_points(lifted, peer_lib.MERGE, num_neighbors=10)
                    t1 = time.perf_counter()
                    vm.insert(c, mat)
                    t2 = time.perf_counter()
                t_pre.append(t1 - t0)
                t_ins.append(t2 - t1)
            rows.append((f"small_gicp `GaussianVoxelMap({voxel}).insert` (3 layers)", t_ins, t_pre))
    try:
        from kiss_icp.mapping import VoxelHashMap
    except ImportError:
        log("kiss-icp absent: its map update skipped")
    else:
        for voxel in (0.3, 0.05):
            km = VoxelHashMap(voxel_size=voxel, max_distance=30.0, max_points_per_voxel=20)
            flat = [np.c_[p, np.zeros(len(p))] for p in pts[:n]]
            for j in range(prefill):
                km.update(flat[j], peer_lib.to_matrix(poses[j]))
            t_ins = []
            for j in progress(range(prefill, n), f"{name}: KISS-ICP {voxel} m"):
                mat = peer_lib.to_matrix(poses[j])
                with no_gc():
                    t0 = time.perf_counter()
                    km.update(flat[j], mat)
                    t_ins.append(time.perf_counter() - t0)
            rows.append((f"KISS-ICP `VoxelHashMap({voxel}).update` (z = 0)", t_ins, []))
    return rows, len(grid)


def section_insert(args: argparse.Namespace) -> dict[str, Any]:
    """Section 2."""
    out("\n## 2. Map update: one scan into a map that holds many scans\n")
    out(
        f"Each map first holds {args.prefill} scans; then each next scan is inserted and "
        "timed (one thread). Ours: before every insert the scan is matched (untimed), so "
        "the distributions are built, as in a SLAM loop; the insert keeps them up to date. "
        f"Our second row takes the same scans {BATCH} at a time through `insert_many` (the "
        "batch's first scan matched first, untimed), which brings the coarser levels and "
        "the distributions up to date once per batch: its time per scan, one sample per "
        f"batch; the issue's {tg.INSERT_TEXT} target is judged on the first row. "
        "small_gicp's `GaussianVoxelMap.insert` needs the scan as a `PointCloud` with "
        "per-point covariances: its `preprocess_points` (3-layer lift, 1 cm merge, "
        "10 neighbours) is timed separately and added in the last columns. KISS-ICP's "
        "voxel map stores points only (no covariance), z = 0. µs / point counts the 2D "
        "scan's points (the 3-layer lift triples what small_gicp stores)."
    )
    res: dict[str, Any] = {}
    sets: list[tuple[str, Callable[[], tuple[list[F64], F64]]]] = [
        ("sim URG-04LX 683 beams (true poses)", lambda: sim_urg_scans(10_000, args.seed)),
    ]
    if URG_LOG.exists():

        def urg() -> tuple[list[F64], F64]:
            scans = urg_scans()
            return [s.points(max_range=URG_RANGE) for s in scans], urg_poses(scans)

        sets.append(("real URG-04LX exp1 (poses from ndtgrid.Odometry)", urg))
    for title, make in sets:
        pts, poses = make()
        rows, cells = insert_set(title, pts, poses, args.prefill, args.inserts)
        npts = np.array([len(p) for p in pts[args.prefill : args.prefill + args.inserts]])
        out(
            [
                f"\n### {title}\n",
                f"{len(rows[0][1])} inserts of {npts.min()}–{npts.max()} points (median "
                f"{np.median(npts):.0f}); our map held {cells} cells at the end.\n",
                "| map | median insert [µs] | p90 [µs] | µs / point | ratio (map / ours) "
                "| + preprocessing, median [µs] | ratio (map / ours) |",
                "|---|---:|---:|---:|---:|---:|---:|",
            ]
        )
        # Each map's median insert, and with its preprocessing where it has one.
        methods = [
            (
                name,
                float(np.median(t_ins)),
                float(np.median(np.add(t_ins, t_pre))) if t_pre else math.nan,
            )
            for name, t_ins, t_pre in rows
        ]
        ours = methods[0][1]
        for (name, t_ins, t_pre), (_, med, full) in zip(rows, methods):
            out(
                f"| {name} | {us(med)} | {us(float(np.percentile(t_ins, 90)))} "
                f"| {1e6 * med / np.median(npts):.3f} | {ratio(med, ours)} "
                f"| {us(full) if t_pre else '-'} | {ratio(full, ours) if t_pre else '-'} |"
            )
        res[title] = {"ours": ours, "points": float(np.median(npts)), "methods": methods}
    return res


# ----------------------------------------------------------------------------- 3. odometry


def intel_child(limit: int, out_path: str, one_thread: bool, poses_only: bool) -> None:
    """``--intel-child``: ``ndtgrid.Odometry`` over the Intel log in this fresh process
    (with ``one_thread``, its mapper in line: ``background_mapper=False``; with
    ``poses_only``, no map at all: ``build_map=False``); poses to ``out_path`` (.npy), a
    JSON line of times and memory to stdout. The time ends with a read of
    ``odo.mapper`` (when there is one), which waits for the mapper to take in the last
    scans."""
    rss_base, _ = rss_kib()
    scans = read_benchmark_split(INTEL_SPLIT)
    config = ndtgrid.OdometryConfig(background_mapper=not one_thread, build_map=not poses_only)
    odo = ndtgrid.Odometry(cell_size=CELL, config=config)
    spent = 0.0
    wall = time.perf_counter()
    n = 0
    rss_read = 0
    for s in scans:
        if n == limit:
            break
        if n == 0:
            rss_read, _ = rss_kib()  # the reader has parsed the whole archive by now
        t0 = time.perf_counter()
        odo.step(s.ranges, s.angles, s.odom)
        spent += time.perf_counter() - t0
        n += 1
    t0 = time.perf_counter()
    mapper_cells = 0 if poses_only else len(odo.mapper.grid)
    spent += time.perf_counter() - t0
    wall = time.perf_counter() - wall
    np.save(out_path, odo.poses)
    rss_end, hwm = rss_kib()
    print(
        json.dumps(
            {
                "scans": n,
                "seconds": spent,
                "wall": wall,
                "rss_base_kib": rss_base,
                "rss_read_kib": rss_read,
                "rss_end_kib": rss_end,
                "vmhwm_kib": hwm,
                "ru_maxrss_kib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss,
                "cells": len(odo),
                "mapper_cells": mapper_cells,
                "insertions": odo.insertions,
            }
        )
    )


def child(argv: list[str]) -> dict[str, Any]:
    """Run this script with ``argv`` in a fresh Python process; its last stdout line
    (JSON) as a dict, plus the children's ``ru_maxrss`` seen from here."""
    cmd = [sys.executable, str(Path(__file__).resolve()), *argv]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(argv)} failed:\n{proc.stderr[-2000:]}")
    data: dict[str, Any] = json.loads(proc.stdout.strip().splitlines()[-1])
    data["children_maxrss_kib"] = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return data


@dataclass
class OdoRun:
    """One odometry method over the log."""

    name: str
    poses: F64
    seconds: float
    note: str = ""
    library_seconds: float = math.nan


class _Clock:
    """Accumulated seconds."""

    def __init__(self) -> None:
        self.seconds = 0.0


class _TimedMap:
    """A small_gicp voxel map whose ``insert`` is timed."""

    def __init__(self, inner: Any, clock: _Clock) -> None:
        self.inner, self.clock = inner, clock

    def insert(self, *a: Any, **k: Any) -> Any:
        t0 = time.perf_counter()
        r = self.inner.insert(*a, **k)
        self.clock.seconds += time.perf_counter() - t0
        return r


class _TimedSmallGicp:
    """The small_gicp calls of ``datasets.GicpOdometry``, timed (library time only)."""

    def __init__(self, module: Any, clock: _Clock) -> None:
        self.module, self.clock = module, clock

    def align(self, target: Any, *a: Any, **k: Any) -> Any:
        t0 = time.perf_counter()
        r = self.module.align(getattr(target, "inner", target), *a, **k)
        self.clock.seconds += time.perf_counter() - t0
        return r

    def preprocess_points(self, *a: Any, **k: Any) -> Any:
        t0 = time.perf_counter()
        r = self.module.preprocess_points(*a, **k)
        self.clock.seconds += time.perf_counter() - t0
        return r


def run_small_gicp_odometry(scans: list[Scan]) -> OdoRun:
    """The voxel-map odometry peer of ``benches/datasets.py`` (VGICP 0.2 m, LRU 100, 1 cm
    merge, the same loop as ours), with the time spent inside small_gicp counted apart."""
    peer = datasets.GicpOdometry((0.2,), 100, ndtgrid.OdometryConfig(), 0.01)
    clock = _Clock()
    peer.sg = _TimedSmallGicp(peer.sg, clock)
    peer.maps = [_TimedMap(m, clock) for m in peer.maps]
    start = time.perf_counter()
    for s in progress(scans, "small_gicp odometry"):
        peer.step(s)
    seconds = time.perf_counter() - start
    return OdoRun(
        "small_gicp VGICP voxel-map odometry (0.2 m, `benches/datasets.py`)",
        np.array(peer.poses),
        seconds,
        "Python loop around small_gicp (as datasets.py)",
        clock.seconds,
    )


def run_kiss(scans: list[Scan], voxel: float | None, odom_prior: bool) -> OdoRun:
    """KISS-ICP 1.x (``KissICP.register_frame``) on the 2D points with z = 0; one thread,
    no deskewing, ``max_range`` 30 m as ours; voxel size ``voxel`` (``None``: its default,
    ``max_range / 100``). With ``odom_prior`` its constant-velocity prediction is replaced
    by the wheel-odometry increment (the prior our loop uses). Time: ``register_frame``."""
    from kiss_icp.config.config import DataConfig, MappingConfig, RegistrationConfig
    from kiss_icp.config.parser import KISSConfig
    from kiss_icp.kiss_icp import KissICP

    cfg = KISSConfig(
        data=DataConfig(max_range=30.0, min_range=0.0, deskew=False),
        mapping=MappingConfig(voxel_size=voxel if voxel is not None else 30.0 / 100.0),
        registration=RegistrationConfig(max_num_threads=1),
    )
    kiss = KissICP(cfg)
    poses = np.empty((len(scans), 3))
    spent = 0.0
    last: F64 | None = None
    for k, s in enumerate(progress(scans, f"KISS-ICP voxel {cfg.mapping.voxel_size} m")):
        pts = s.points(max_range=30.0)
        frame = np.c_[pts, np.zeros(len(pts))]
        stamps = np.zeros(len(frame))
        t0 = time.perf_counter()
        if odom_prior and last is not None and s.odom is not None:
            kiss.last_delta = peer_lib.to_matrix(se2.between(last, s.odom))
        kiss.register_frame(frame, stamps)
        spent += time.perf_counter() - t0
        poses[k] = peer_lib.to_pose(kiss.last_pose)
        last = s.odom
    prior = "wheel-odometry prior" if odom_prior else "constant velocity (its own)"
    dflt = " (its default for 30 m)" if voxel is None else ""
    return OdoRun(
        f"KISS-ICP, voxel {cfg.mapping.voxel_size:g} m{dflt}, {prior}",
        poses,
        spent,
        "C++ core, Python `KissICP` pipeline",
    )


def fmt_rel(s: RelationSummary) -> tuple[str, str]:
    """Translation [m] and rotation [°] of a relation summary."""
    return (
        f"{s.translation_mean:.4f} ± {s.translation_std:.3f}",
        f"{s.rotation_mean:.2f} ± {s.rotation_std:.2f}",
    )


def median_info(infos: list[dict[str, Any]]) -> dict[str, Any]:
    """The run of median ``seconds`` of the child runs ``infos`` (the upper one of an
    even count)."""
    order = sorted(range(len(infos)), key=lambda k: float(infos[k]["seconds"]))
    return infos[order[len(order) // 2]]


def section_odometry(args: argparse.Namespace) -> dict[str, Any]:
    """Section 3."""
    out("\n## 3. Odometry over the Intel log\n")
    if not INTEL_SPLIT.exists():
        out("Intel log absent: skipped.")
        return {}
    scans = [s for _, s in zip(range(args.intel_scans), read_benchmark_split(INTEL_SPLIT))]
    try:
        import kiss_icp  # noqa: F401
    except ImportError as exc:
        kiss_error: ImportError | None = exc
    else:
        kiss_error = None
    # KISS-ICP at its default voxel, the fastest peer in every run so far, with either
    # prior: each run of ours is followed by one of each, so that the machine's drift
    # (tens of per cent within minutes on this project's VMs) falls on both sides of
    # the ratio alike; each side is judged on its median run.
    kiss_fast: dict[bool, list[OdoRun]] = {False: [], True: []}
    kiss_note = ""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "poses.npy")
        argv = ["--intel-child", "--intel-scans", str(args.intel_scans), "--out", path]
        # Our default loop runs `intel_runs` times, each in a fresh process, and so do
        # the loop with its mapper in line (one thread) and the loop with no map,
        # alternating with it.
        infos, all_poses, infos_1, all_poses_1, infos_p, all_poses_p = [], [], [], [], [], []
        for k in range(args.intel_runs):
            log(f"Intel: ndtgrid.Odometry in a child process (run {k + 1}/{args.intel_runs}) ...")
            infos.append(child(argv))
            all_poses.append(np.load(path))
            log("Intel: the same with the mapper in line (one thread) ...")
            infos_1.append(child([*argv, "--one-thread"]))
            all_poses_1.append(np.load(path))
            log("Intel: the same with no map (`build_map=False`, poses only) ...")
            infos_p.append(child([*argv, "--poses-only"]))
            all_poses_p.append(np.load(path))
            if kiss_error is None:
                for prior in (False, True):
                    try:
                        kiss_fast[prior].append(run_kiss(scans, None, prior))
                    except Exception as exc:  # a peer's failure is reported, not fatal
                        kiss_note += f" KISS-ICP (prior {prior}) failed: {exc!r}."
        info = median_info(infos)
        info_1 = median_info(infos_1)
        info_p = median_info(infos_p)
        our_poses, poses_1 = all_poses[0], all_poses_1[0]
        repeatable = all(np.array_equal(our_poses, p) for p in all_poses)
        repeatable_1 = all(np.array_equal(poses_1, p) for p in all_poses_1)
    n = int(info["scans"])
    run_times = ", ".join(f"{float(i['seconds']):.2f}" for i in infos)
    run_times_1 = ", ".join(f"{float(i['seconds']):.2f}" for i in infos_1)
    run_times_p = ", ".join(f"{float(i['seconds']):.2f}" for i in infos_p)
    log(f"  ndtgrid: {info['seconds']:.2f} s for {n} scans ({info_1['seconds']:.2f} s one thread)")
    same = np.array_equal(our_poses, poses_1)
    same_p = all(np.array_equal(our_poses, p) for p in all_poses_p)
    runs = [
        OdoRun(
            "ndtgrid `Odometry(cell_size=0.02)` (defaults)",
            our_poses,
            float(info["seconds"]),
            "Rust loop (one `step` call per scan); the mapper (§V) on a helper thread; "
            f"median of {len(infos)} runs in fresh processes ({run_times} s), poses "
            f"{'identical' if repeatable else 'DIFFERENT'} in every run",
        ),
        OdoRun(
            "ndtgrid, `background_mapper=False` (one thread)",
            poses_1,
            float(info_1["seconds"]),
            f"the mapper in line; median of {len(infos_1)} runs in fresh processes, each "
            f"right after one of the default's ({run_times_1} s); poses "
            f"{'identical' if same and repeatable_1 else 'DIFFERENT'} to the default's",
        ),
        OdoRun(
            "ndtgrid, `build_map=False` (poses only, one thread)",
            all_poses_p[0],
            float(info_p["seconds"]),
            "no map (no §V elimination, no helper): what a scan-to-map odometry like "
            f"KISS-ICP gives; median of {len(infos_p)} runs in fresh processes, each right "
            f"after one of the default's ({run_times_p} s); poses "
            f"{'identical' if same_p else 'DIFFERENT'} to the default's",
        ),
    ]
    n_ours = len(runs)
    try:
        runs.append(run_small_gicp_odometry(scans))
    except ImportError:
        out("small_gicp absent: its odometry skipped.")
    if kiss_error is not None:
        kiss_note = f"KISS-ICP skipped: {kiss_error} (`pip install kiss-icp`)."
    else:
        for prior in (False, True):
            done = sorted(kiss_fast[prior], key=lambda r: r.seconds)
            if done:
                mid = done[len(done) // 2]
                times = ", ".join(f"{r.seconds:.2f}" for r in kiss_fast[prior])
                runs.append(
                    dataclasses.replace(
                        mid,
                        note=f"{mid.note}; median of {len(done)} runs ({times} s), each "
                        "right after one of ours",
                    )
                )
        try:
            runs.append(run_kiss(scans, 0.1, True))
        except Exception as exc:  # a peer's failure is reported, not fatal
            kiss_note += f" KISS-ICP voxel 0.1 failed: {exc!r}."
    index = read_benchmark_index(INTEL_INDEX)
    sel = index.raw_scan < n
    ref = index.corrected[sel]
    out(
        [
            f"{n} scans (raw odometry as each loop's prior unless stated), one thread each "
            "except ndtgrid's default, whose mapper (the §V elimination, a by-product the "
            "poses do not depend on) runs on a second thread; time of the per-scan calls "
            "only (reading the log excluded; ours ends with a read of `odo.mapper`). "
            "Relation error "
            f"(Kümmerle et al. 2009) on the {int(sel.sum()) - 1} relations between "
            "consecutive SLAM-corrected scans, mean ± std. KISS-ICP config: "
            "`KISSConfig(data=DataConfig(max_range=30, min_range=0, deskew=False), "
            "mapping=MappingConfig(voxel_size=v), registration=RegistrationConfig("
            "max_num_threads=1))`, points (x, y, 0), timestamps 0; 'wheel-odometry prior' "
            "sets `last_delta` to the odometry increment before each `register_frame`.\n",
            "| method | total [s] | ms / scan | ratio (method / ours) | in the peer's library "
            "[ms / scan] | relation error [m] | [°] | notes |",
            "|---|---:|---:|---:|---:|---|---|---|",
        ]
    )
    ours_s = runs[0].seconds
    errors = {}
    for r in runs:
        summ = relation_errors(r.poses[index.raw_scan[sel]], ref).summary()
        errors[r.name] = summ.translation_mean
        et, er = fmt_rel(summ)
        lib = "-" if math.isnan(r.library_seconds) else f"{1e3 * r.library_seconds / n:.3f}"
        out(
            f"| {r.name} | {r.seconds:.2f} | {1e3 * r.seconds / n:.3f} "
            f"| {ratio(r.seconds, ours_s)} | {lib} | {et} | {er} | {r.note} |"
        )
    if kiss_note:
        out("\n" + kiss_note.strip())
    mib = 1 / 1024
    out(
        [
            "",
            f"Peak resident memory of the child process that ran ndtgrid's Intel run: "
            f"**{info['vmhwm_kib'] * mib:.1f} MiB** (VmHWM of `/proc/self/status`; the "
            f"child's own `ru_maxrss`, {info['ru_maxrss_kib'] * mib:.1f} MiB, also counts "
            "the image of this process it was forked from, which Linux keeps across exec). "
            f"Of it: {info['rss_base_kib'] * mib:.1f}"
            f" MiB after the imports (Python, numpy, ndtgrid), "
            f"{info['rss_read_kib'] * mib:.1f} MiB once the reader had parsed the archive "
            f"(it holds every scan's ranges), {info['rss_end_kib'] * mib:.1f} MiB at the end "
            f"with {info['cells']} cells in the loop's map ({info['insertions']} scans "
            f"inserted, `map_window` {ndtgrid.OdometryConfig().map_window}).",
        ]
    )
    peers = runs[n_ours:]
    res: dict[str, Any] = {
        "scans": n,
        "ours": ours_s,
        "ours_runs": [float(i["seconds"]) for i in infos],
        "ours_one_thread": runs[1].seconds,
        "ours_poses_only": runs[2].seconds,
        "vmhwm_mib": info["vmhwm_kib"] * mib,
        "methods": [(r.name, r.seconds, errors[r.name]) for r in runs],
    }
    if peers:
        fastest = min(peers, key=lambda r: r.seconds)
        res["fastest"] = (fastest.name, fastest.seconds)
        good = [r for r in peers if errors[r.name] <= errors[runs[0].name]]
        if good:
            fg = min(good, key=lambda r: r.seconds)
            res["fastest_good"] = (fg.name, fg.seconds)
    return res


# ----------------------------------------------------------------------------- 4. sweeps


def points_sweep(args: argparse.Namespace) -> list[dict[str, float]]:
    """Match time against scan points: one map (20 simulated 683-beam scans), the test
    scans simulated with ``beams`` beams at the poses after the map's, local starts.

    Every scan and start is drawn first, in the order of the beam counts; the matches
    are then timed with the beam counts in turn (for each map and start, each count once),
    so that a spell of the machine slows every count alike instead of the one timed
    during it (benches/SPEED_LOG.md, session 47)."""
    pts, poses = sim_urg_scans(10_000, args.seed)
    room = sim.sticks_room()
    rng = np.random.default_rng(args.seed + 1)
    centres = np.linspace(WINDOW, len(pts) - 1, args.sweep_maps).astype(int)
    maps = []
    for k in centres:
        grid = ndtgrid.NdtGrid(CELL)
        for j in range(k - WINDOW, k):
            grid.insert(pts[j], poses[j])
        grid.match(pts[k - 1], poses[k - 1])  # build the distributions
        maps.append(grid)
    # cases[b][m]: the scan of beam count b at map m, and its starts.
    cases: list[list[tuple[F64, F64]]] = []
    for beams in args.sweep_points:
        laser = dataclasses.replace(sim.URG04LX, num_beams=int(beams))
        row = []
        for k in centres:
            r, a = laser.scan(room, poses[k], rng=rng)
            src = ndtgrid.ranges_to_points(r, a, max_range=laser.max_range)
            row.append((src, poses[k] + convergence.starts(rng, args.starts, 0.05, 2.0)))
        cases.append(row)
    times: list[list[float]] = [[] for _ in cases]
    iters: list[list[int]] = [[] for _ in cases]
    for m in progress(range(len(maps)), "sweep: scan points"):
        grid = maps[m]
        for row in cases:
            grid.match(row[m][0], poses[centres[m]])  # warm-up
        with no_gc():
            for s in range(args.starts):
                for b, row in enumerate(cases):
                    src, guesses = row[m]
                    t0 = time.perf_counter()
                    res = grid.match(src, guesses[s])
                    times[b].append(time.perf_counter() - t0)
                    iters[b].append(res.iterations)
    return [
        {
            "beams": float(beams),
            "points": float(np.mean([len(src) for src, _ in row])),
            "median": float(np.median(t)),
            "iterations": float(np.median(it)),
        }
        for beams, row, t, it in zip(args.sweep_points, cases, times, iters)
    ]


def intel_corrected() -> tuple[list[F64], F64]:
    """Points (max range 40 m) and corrected laser poses of the 910 Intel scans."""
    scans = list(read_carmen(INTEL_CORRECTED))
    pts = [s.points(max_range=40.0) for s in scans]
    poses = np.array([s.laser_pose if s.laser_pose is not None else s.odom for s in scans])
    return pts, poses


def map_sweep(args: argparse.Namespace) -> list[dict[str, Any]]:
    """Match time against map size: the last ``tests`` Intel scans matched against maps of
    the ``k`` scans before each, then against a map of the 30 scans before plus ``c`` far
    copies (1 km apart) of the whole log's map (only the size grows).

    Within each sweep the sizes are interleaved: every test scan's maps of all sizes are
    built first, then each start is matched on each of them in an order turned from start
    to start, so a change in the machine's speed during the sweep (this project's VMs
    drift by tens of per cent within minutes) falls on every size alike instead of
    looking like a trend in map size."""
    pts, poses = intel_corrected()
    n = len(pts)
    tests = list(range(n - args.sweep_tests, n))
    rng = np.random.default_rng(args.seed + 2)
    deltas = {t: convergence.starts(rng, args.starts, 0.05, 2.0) for t in tests}
    rows: list[dict[str, Any]] = []

    def measure(
        kind: str, labels: list[str], builds: list[Callable[[int], ndtgrid.NdtGrid]]
    ) -> None:
        times: list[list[float]] = [[] for _ in builds]
        cells: list[list[int]] = [[] for _ in builds]
        iters: list[list[int]] = [[] for _ in builds]
        for t in progress(tests, f"sweep: {kind} maps, test scans"):
            grids = [build(t) for build in builds]
            for g, c in zip(grids, cells):
                g.match(pts[t], poses[t])  # build the distributions, warm up
                c.append(len(g))
            with no_gc():
                for j, d in enumerate(deltas[t]):
                    for k in range(len(grids)):
                        i = (k + j + t) % len(grids)
                        t0 = time.perf_counter()
                        m = grids[i].match(pts[t], poses[t] + d)
                        times[i].append(time.perf_counter() - t0)
                        iters[i].append(m.iterations)
            del grids
        for i, label in enumerate(labels):
            rows.append(
                {
                    "label": label,
                    "kind": kind,
                    "cells": float(np.mean(cells[i])),
                    "median": float(np.median(times[i])),
                    "iterations": float(np.median(iters[i])),
                }
            )

    def recent(k: int) -> Callable[[int], ndtgrid.NdtGrid]:
        def build(t: int) -> ndtgrid.NdtGrid:
            grid = ndtgrid.NdtGrid(CELL)
            for j in range(max(0, t - k), t):
                grid.insert(pts[j], poses[j])
            return grid

        return build

    scans = [min(k, n - args.sweep_tests) for k in args.sweep_scans]
    measure("recent", [f"last {k} scans" for k in args.sweep_scans], [recent(k) for k in scans])

    def padded(copies: int) -> Callable[[int], ndtgrid.NdtGrid]:
        far = ndtgrid.NdtGrid(CELL)  # built once per size, copied per test scan
        for c in range(1, copies + 1):
            for p, q in zip(pts, poses):
                far.insert(p, np.add(q, [FAR * c, 0.0, 0.0]))
        blob = far.to_bytes()

        def build(t: int) -> ndtgrid.NdtGrid:
            grid = ndtgrid.NdtGrid.from_bytes(blob)
            for j in range(max(0, t - 30), t):
                grid.insert(pts[j], poses[j])
            return grid

        return build

    labels = [
        f"last 30 scans + {c} far copies of the log" if c else "last 30 scans"
        for c in args.sweep_copies
    ]
    measure("padded", labels, [padded(c) for c in progress(args.sweep_copies, "sweep: far maps")])
    return rows


def section_sweeps(args: argparse.Namespace) -> dict[str, Any]:
    """Section 4."""
    out("\n## 4. Sweeps: time per match against scan points and map size\n")
    res: dict[str, Any] = {}
    pts_rows = points_sweep(args)
    slope, icpt, r2 = linear_fit([r["points"] for r in pts_rows], [r["median"] for r in pts_rows])
    res["points"] = (pts_rows, slope, icpt, r2)
    out(
        [
            "### Scan points (one map, same poses)\n",
            f"Maps: {WINDOW} simulated 683-beam URG-04LX scans of the sticks room (2 cm), "
            f"{args.sweep_maps} places; the "
            "matched scan is simulated with more or fewer beams over the same 240° at the "
            f"next pose; {args.starts} local starts each, timed with the beam counts in turn "
            "(for each map and start, every count once); default `match()`.\n",
            "| beams | valid points | median [ms] | µs / point | median iterations |",
            "|---:|---:|---:|---:|---:|",
        ]
    )
    for r in pts_rows:
        out(
            f"| {r['beams']:.0f} | {r['points']:.0f} | {ms(r['median'])} "
            f"| {1e6 * r['median'] / r['points']:.3f} | {r['iterations']:.0f} |"
        )
    out(
        f"\nLinear fit of the medians: time = {1e6 * icpt:.1f} µs + {1e6 * slope:.3f} µs × "
        f"points (R² = {r2:.3f})."
    )
    map_rows = map_sweep(args)
    res["map"] = map_rows
    out(
        [
            "\n### Map size (same scans)\n",
            f"The last {args.sweep_tests} scans of the corrected Intel log (180 beams, 1°) "
            "matched against 2 cm maps of the k scans before each (the area grows with k), "
            "then against the 30 scans before each plus far copies of the whole log's map "
            f"({FAR:g} m apart: only the map's size grows); {args.starts} local starts per "
            "scan; default `match()`. Within each sweep every start is matched on every "
            "size in turn (the order turned from start to start), so the machine's drift "
            "falls on all sizes alike.\n",
            "| map | occupied cells | median [ms] | median iterations |",
            "|---|---:|---:|---:|",
        ]
    )
    for r in map_rows:
        out(f"| {r['label']} | {r['cells']:.0f} | {ms(r['median'])} | {r['iterations']:.0f} |")
    for kind, what in (("recent", "maps of the last k scans"), ("padded", "padded maps")):
        sub = [r for r in map_rows if r["kind"] == kind]
        if len(sub) >= 2:
            s, i, r2 = linear_fit([r["cells"] for r in sub], [r["median"] for r in sub])
            res[f"map_{kind}"] = (s, i, r2, sub)
            out(
                f"\nLinear fit over the {what}: time = {1e3 * i:.3f} ms "
                f"{1e11 * s:+.2f} µs per 100k cells (R² = {r2:.2f}); largest / smallest "
                f"map: {sub[-1]['cells'] / sub[0]['cells']:.0f}× the cells, "
                f"{ratio(sub[-1]['median'], sub[0]['median'])} the time."
            )
    if args.plot:
        plotted(speed_plots.plot_sweeps(res, Path(args.plot)))
    return res


# ----------------------------------------------------------------------------- 5. threads


def section_threads(args: argparse.Namespace) -> dict[str, Any]:
    """Section 5."""
    out("\n## 5. Threads: two Python threads matching different scans on one grid\n")
    pts, poses = intel_corrected()
    grid = ndtgrid.NdtGrid(CELL)
    for p, q in zip(pts, poses):
        grid.insert(p, q)
    rng = np.random.default_rng(args.seed + 3)
    picks = np.linspace(0, len(pts) - 1, args.thread_matches).astype(int)
    jobs = [(pts[k], poses[k] + convergence.starts(rng, 1, 0.05, 2.0)[0]) for k in picks]
    grid.match(jobs[0][0], jobs[0][1])  # build the distributions

    # A second control: the same matcher on bundles of THREAD_BUNDLE consecutive scans
    # merged into one scan in the frame of the middle one (about 3600 points, one call
    # about a millisecond), so that the GIL is held for a fraction of a per cent of the
    # time: what two threads gain on this very code, with the GIL out of the way, in the
    # same run and on the same cores.
    bundles = bundle_scans(pts, poses, THREAD_BUNDLE, rng)

    def work(
        part: Sequence[tuple[F64, F64]],
        sink: list[F64],
        span: list[float] | None = None,
        mid: list[int | None] | None = None,
    ) -> None:
        """Matches ``part`` into ``sink``; its start and end into ``span``, and the CPU
        the thread is on at its first match and half-way through into ``mid``
        (``pinned.current_cpu``: glibc's ``sched_getcpu``, about 0.1 µs, the GIL kept).
        A read of /proc at the first match instead, about 14 µs, lowered the ratio itself
        (benches/SPEED_LOG.md, session 44)."""
        reads = (0, len(part) // 2) if mid is not None else ()
        start = time.perf_counter()
        for i, (p, g) in enumerate(part):
            if i in reads and mid is not None:
                mid.append(pinned.current_cpu())
            sink.append(grid.match(p, g).pose)
        if span is not None:
            span += [start, time.perf_counter()]

    def one(jobs: Sequence[tuple[F64, F64]] = jobs) -> tuple[float, float, list[F64]]:
        sink: list[F64] = []
        with no_gc():
            c0, t0 = time.process_time(), time.perf_counter()
            work(jobs, sink)
            return time.perf_counter() - t0, time.process_time() - c0, sink

    def in_job_order(halves: Sequence[list[F64]]) -> list[F64]:
        """The poses of the two threads' halves (``jobs[0::2]``, ``jobs[1::2]``) back
        in job order."""
        merged: list[F64] = [np.empty(0)] * (len(halves[0]) + len(halves[1]))
        merged[0::2], merged[1::2] = halves[0], halves[1]
        return merged

    def two(
        jobs: Sequence[tuple[F64, F64]] = jobs, read_cpu: bool = True
    ) -> tuple[float, float, list[F64], float, float, bool | None, bool | None]:
        """Wall and CPU time, the poses in job order, the second thread's start after
        the clock's (s), the share of the wall time both threads were matching, and
        whether the two threads were on one CPU half-way through their halves and at
        their first matches (``None`` where the CPU cannot be read, or with
        ``read_cpu`` false)."""
        sinks: list[list[F64]] = [[], []]
        spans: list[list[float]] = [[], []]
        mids: list[list[int | None]] = [[], []]
        halves = [jobs[0::2], jobs[1::2]]
        ts = [
            threading.Thread(target=work, args=(h, s, sp, m if read_cpu else None))
            for h, s, sp, m in zip(halves, sinks, spans, mids)
        ]
        with no_gc():
            c0, t0 = time.process_time(), time.perf_counter()
            for t in ts:
                t.start()
            for t in ts:
                t.join()
            dt, cpu = time.perf_counter() - t0, time.process_time() - c0
        late = max(sp[0] for sp in spans)
        both = max(0.0, min(sp[1] for sp in spans) - late)

        def on_one_cpu(k: int) -> bool | None:
            at = [m[k] if len(m) > k else None for m in mids]
            return None if None in at else at[0] == at[1]

        return dt, cpu, in_job_order(sinks), late - t0, both / dt, on_one_cpu(1), on_one_cpu(0)

    # Control: the same one-vs-two-thread test on hashlib, which releases the GIL on large
    # buffers; it tells what parallelism the machine had free, whatever ndtgrid does.
    blob = os.urandom(1 << 20)

    def hash_work(reps: int) -> None:
        for _ in range(reps):
            hashlib.sha256(blob).digest()

    def control() -> float:
        reps = 64
        t0 = time.perf_counter()
        hash_work(2 * reps)
        one_t = time.perf_counter() - t0
        hs = [threading.Thread(target=hash_work, args=(reps,)) for _ in range(2)]
        t0 = time.perf_counter()
        for h in hs:
            h.start()
        for h in hs:
            h.join()
        return one_t / (time.perf_counter() - t0)

    # The same runs on two long-lived worker threads, each pinned to its own core
    # (benches/pinned.py): one worker alone, then both. Timed from the first worker's
    # first match to the last one's end, so the barrier's hand-out is not counted, but
    # a worker that begins late is.
    cpus = pinned.two_cpus()
    workers = pinned.PinnedWorkers(cpus) if cpus is not None else None
    pin_sinks: list[list[F64]] = [[], []]
    pin_spans: list[list[float]] = [[], []]

    def pinned_run(
        parts: Sequence[Sequence[tuple[F64, F64]] | None],
    ) -> tuple[float, float, float]:
        """Wall time of one pinned round (``parts[i]``: worker i's scans, ``None``: it
        sits out), the later worker's start after the first's (s), and the workers'
        CPU time (``time.thread_time``) over the wall time."""
        assert workers is not None
        cpu: list[float] = []

        def task(part: Sequence[tuple[F64, F64]], sink: list[F64], span: list[float]) -> None:
            c0 = time.thread_time()
            work(part, sink, span)
            cpu.append(time.thread_time() - c0)

        for sink, span in zip(pin_sinks, pin_spans):
            sink.clear()
            span.clear()
        tasks = [
            None if part is None else functools.partial(task, part, sink, span)
            for part, sink, span in zip(parts, pin_sinks, pin_spans)
        ]
        with no_gc():
            workers.run(tasks)
        spans = [sp for sp in pin_spans if sp]
        t0 = min(sp[0] for sp in spans)
        wall = max(sp[1] for sp in spans) - t0
        return wall, max(sp[0] for sp in spans) - t0, sum(cpu) / wall

    # The same scans in one `match_many` call: on the calling thread alone, then on
    # every core (the calling thread and a helper started for the batch); the GIL
    # released once for the batch.
    many_scans = [p for p, _ in jobs]
    many_guesses = np.array([g for _, g in jobs])

    def many(threads: int | None) -> tuple[float, float, list[F64]]:
        """Wall time, this process's CPU time over it, and the poses."""
        with no_gc():
            c0, t0 = time.process_time(), time.perf_counter()
            res = grid.match_many(many_scans, many_guesses, threads=threads)
            dt = time.perf_counter() - t0
            return dt, (time.process_time() - c0) / dt, [r.pose for r in res]

    load = os.getloadavg()
    controls = []
    singles, doubles, cpu1, cpu2 = [], [], [], []
    lates, overlaps = [], []
    shared: list[bool | None] = []
    shared_first: list[bool | None] = []
    bundle_1, bundle_2 = [], []
    # The bundles' rounds, apart: the two threads' CPU time over the wall time, their CPU
    # time over one thread's for the same work, and the seconds stolen from the guest
    # during the two-thread run (benches/steal.py; None where it cannot be read).
    bundle_share, bundle_cost = [], []
    bundle_steal: list[float | None] = []
    pin_cost: list[float] = []
    pin_1, pin_2, pin_lates, pin_cpu1, pin_cpu2 = [], [], [], [], []
    many_1, many_2, many_cpu = [], [], []
    steady_1: list[steady.SteadyRun] = []
    steady_2: list[steady.SteadyRun] = []

    def match_job(i: int) -> None:
        p, g = jobs[i % len(jobs)]
        grid.match(p, g)

    same = True
    try:
        for rep in progress(range(args.thread_reps), "threads"):
            t1, c1, r1 = one()
            base = r1
            t2, c2, r2, late, overlap, one_cpu, one_cpu_first = two()
            singles.append(t1)
            doubles.append(t2)
            cpu1.append(c1 / t1)
            cpu2.append(c2 / t2)
            lates.append(late)
            overlaps.append(overlap)
            shared.append(one_cpu)
            shared_first.append(one_cpu_first)
            same &= all(np.array_equal(a, b) for a, b in zip(r1, r2))
            controls.append(control())
            t1, c1, r1 = one(bundles)
            before = steal.steal_seconds()
            t2, c2, r2, *_ = two(bundles, read_cpu=False)
            bundle_steal.append(steal.stolen(before, steal.steal_seconds()))
            bundle_1.append(t1)
            bundle_2.append(t2)
            bundle_share.append(c2 / t2)
            bundle_cost.append(c2 / c1)
            same &= all(np.array_equal(a, b) for a, b in zip(r1, r2))
            if workers is not None:
                # One worker alone, on the two cores in turn (one may be slower).
                alone = rep % 2
                t1, _, c1 = pinned_run([None, jobs] if alone else [jobs, None])
                r1 = list(pin_sinks[alone])
                t2, late, c2 = pinned_run([jobs[0::2], jobs[1::2]])
                pin_cpu1.append(c1)
                pin_cpu2.append(c2)
                pin_cost.append(c2 * t2 / (c1 * t1))
                r2 = in_job_order(pin_sinks)
                pin_1.append(t1)
                pin_2.append(t2)
                pin_lates.append(late)
                same &= all(np.array_equal(a, b) for a, b in zip(r1, r2))
        # `match_many` in rounds of its own, after the others: run between the rounds
        # above, its work on the calling thread lowered the next unpinned two-thread
        # run's ratio by about 0.3 with the controls unchanged (8 alternated pairs;
        # benches/SPEED_LOG.md, session 32), so the Python threads are timed as they
        # were before `match_many` joined the section.
        for _ in progress(range(args.thread_reps), "match_many"):
            t1, c1, r1 = many(1)
            t2, c2, r2 = many(None)
            many_1.append(t1)
            many_2.append(t2)
            many_cpu.append(c2)
            same &= all(np.array_equal(a, b) for a, b in zip(base + base, r1 + r2))
        # Threads that keep matching the same scans (round and round) for
        # args.steady_seconds, one thread then two, started where the kernel puts them
        # (benches/steady.py): a SLAM loop's threads live for the whole run, so where the
        # kernel starts them weighs little. Last, so the runs above are timed as before.
        for _ in progress(range(args.steady_reps), "threads that keep matching"):
            with no_gc():
                steady_1.append(steady.keep_matching(match_job, 1, args.steady_seconds))
                steady_2.append(steady.keep_matching(match_job, 2, args.steady_seconds))
    finally:
        if workers is not None:
            workers.close()
    n = len(jobs)
    s1, s2 = n / np.median(singles), n / np.median(doubles)
    b1, b2 = n / min(singles), n / min(doubles)
    bundle_ratio = float(np.median(bundle_1) / np.median(bundle_2))
    # Each run's ratio: one thread's time over the two threads' right after it.
    per_run = {
        "unpinned": list(np.divide(singles, doubles)),
        "pinned": list(np.divide(pin_1, pin_2)),
        "bundles": list(np.divide(bundle_1, bundle_2)),
        "many": list(np.divide(many_1, many_2)),
        "steady": [b.rate / a.rate for a, b in zip(steady_1, steady_2)],
        # Each round's ratio = share / cost, times the one-thread run's wall over its
        # CPU: below 2.0 from time the two did not compute (share) or from computing
        # slower than one thread alone (cost).
        "bundles_share": bundle_share,
        "bundles_cost": bundle_cost,
        "pinned_share": pin_cpu2,
        "pinned_cost": pin_cost,
    }

    def split_by(flags: list[bool | None]) -> tuple[list[float], list[float], int, list[float]]:
        """The unpinned runs' ratios where ``flags`` is true (the two threads on one
        vCPU, or the second one late) and where it is false, how many runs have a flag
        (``None``: not read), and the ratios for the picture (``nan`` where the flag is
        false or ``None``)."""
        pairs = list(zip(per_run["unpinned"], flags))
        return (
            [r for r, sh in pairs if sh],
            [r for r, sh in pairs if sh is False],
            sum(sh is not None for _, sh in pairs),
            [r if sh else math.nan for r, sh in pairs],
        )

    # The unpinned runs by where the kernel had the two threads half-way through ...
    together, apart, known, per_run["unpinned_one_cpu"] = split_by(shared)
    # ... and at their first matches: the kernel places a thread when it starts it.
    first_together, first_apart, first, per_run["unpinned_first_one_cpu"] = split_by(shared_first)
    # ... and by when the second thread's first match began.
    late_runs, early_runs, *_ = split_by([x >= LATE_START for x in lates])

    def median_or_dash(xs: list[float]) -> str:
        return f"{float(np.median(xs)):.2f}×" if xs else "–"

    cpu_text = (
        "At its first match and half-way through its half of each two-thread run, each "
        "thread read the CPU it was on (`current_cpu` in `benches/pinned.py`: glibc's "
        "`sched_getcpu`, inside the timed run): the two were on one vCPU at "
        f"their first matches in {len(first_together)} of {first} runs (median ratio "
        f"{median_or_dash(first_together)} in those, {median_or_dash(first_apart)} in the "
        f"others), and half-way through in {len(together)} of {known} runs (median "
        f"ratio {median_or_dash(together)} in those, {median_or_dash(apart)} in the others)."
        if known
        else "Where the threads ran could not be read (neither `sched_getcpu` nor `/proc`)."
    )
    # match_many against the faster one-thread baseline too (its own, and the loop's).
    mm1, mm2 = n / np.median(many_1), n / np.median(many_2)
    mb1, mb2 = n / min(many_1), n / min(many_2)
    many_ratio, many_best = mm2 / max(mm1, s1), mb2 / max(mb1, b1)
    # Threads that keep matching, against the faster one-thread row too.
    st1 = float(np.median([r.rate for r in steady_1])) if steady_1 else math.nan
    st2 = float(np.median([r.rate for r in steady_2])) if steady_2 else math.nan
    sb1 = max((r.rate for r in steady_1), default=math.nan)
    sb2 = max((r.rate for r in steady_2), default=math.nan)
    steady_ratio, steady_best = st2 / max(st1, s1), sb2 / max(sb1, b1)
    if steady_1:
        steady_rows = [
            f"| 1, keeps matching for {args.steady_seconds:g} s | {st1:.0f} | {sb1:.0f} "
            f"| {np.median([r.cpu_over_wall for r in steady_1]):.2f} |",
            f"| 2, keep matching for {args.steady_seconds:g} s | {st2:.0f} | {sb2:.0f} "
            f"| {np.median([r.cpu_over_wall for r in steady_2]):.2f} |",
            f"| ratio, threads that keep matching (against the faster one-thread row) "
            f"| {steady_ratio:.2f}× | {steady_best:.2f}× | |",
        ]
        steady_text = [
            "",
            f"Threads that keep matching: {args.steady_reps} rounds after the rest, each "
            "one thread and then two, started where the kernel puts them (not pinned), "
            f"matching the same {n} scans round and round for {args.steady_seconds:g} s "
            "(`benches/steady.py`; each thread ends with the match it is in when the time "
            "is up; rate: the matches over the time from the start to the last thread's "
            "end). A SLAM loop's threads live for the whole run, so where the kernel "
            "starts them weighs little here, unlike in the runs above, of "
            f"{n // 2} matches a thread. The ratio is taken against the faster of this "
            "row's one thread and the first row. Per round (two threads' rate over one's "
            "right before it): "
            f"{', '.join(f'{r:.2f}' for r in per_run['steady'])}; matches per thread "
            f"with two: {', '.join('/'.join(map(str, r.calls)) for r in steady_2)}.",
        ]
    else:
        steady_rows, steady_text = [], []
    if pin_1 and cpus is not None:
        # Judged against the faster of the two one-thread baselines (pinned, cores in
        # turn; unpinned, where the kernel put it), so that a slow core alone cannot
        # flatter the pinned ratio.
        p1, p2 = max(n / np.median(pin_1), s1), n / np.median(pin_2)
        pb1, pb2 = max(n / min(pin_1), b1), n / min(pin_2)
        pin_rows = [
            f"| 1, pinned worker (cores in turn) | {n / np.median(pin_1):.0f} "
            f"| {n / min(pin_1):.0f} | {np.median(pin_cpu1):.2f} |",
            f"| 2, pinned workers | {p2:.0f} | {pb2:.0f} | {np.median(pin_cpu2):.2f} |",
            f"| ratio, pinned (against the faster one-thread row) | {p2 / p1:.2f}× "
            f"| {pb2 / pb1:.2f}× | |",
        ]
        pin_text = [
            "",
            "Pinned: the same scans on two long-lived worker threads, each pinned to its "
            f"own core (CPUs {cpus[0]} and {cpus[1]}, `os.sched_setaffinity(0, {{cpu}})` "
            "in the worker; `benches/pinned.py`), let go together from a barrier: one "
            "worker alone (on the two cores in turn), then both, right after each pair "
            "of runs above; timed from the first worker's first match to the last one's "
            "end. The ratio is taken against the faster of the two one-thread rows. "
            "Per run (one pinned worker's time over the two's right after it): "
            f"{', '.join(f'{r:.2f}' for r in per_run['pinned'])}; median "
            f"{float(np.median(per_run['pinned'])):.2f}×; the two workers' CPU / "
            f"wall per run: {', '.join(f'{c:.2f}' for c in pin_cpu2)}; their CPU time "
            "over one worker's for the same scans: "
            f"{', '.join(f'{c:.2f}' for c in pin_cost)}. The later worker's first "
            "match began "
            f"{', '.join(f'{1e6 * x:.0f}' for x in pin_lates)} µs after the first's. "
            "Unpinned, this VM's kernel may wake a thread on the vCPU of the busy thread "
            "that woke it, with the other vCPU idle; it then waits there for the "
            "scheduler's tick or shares that vCPU (benches/SPEED_LOG.md, session 29).",
        ]
    else:
        pin_rows, pin_text = [], ["", "Pinned workers: not measured (no two CPUs to pin to)."]
    bundle_points = int(np.median([len(p) for p, _ in bundles]))
    stolen_s = [x for x in bundle_steal if x is not None]
    # The bundles' share and cost per round (see per_run above for what they tell).
    bundle_text = (
        "Per run, the two threads' CPU / wall: "
        f"{', '.join(f'{c:.2f}' for c in bundle_share)}; their CPU time over one "
        "thread's for the same bundles (1.00: each computed as fast as one thread alone): "
        f"{', '.join(f'{c:.2f}' for c in bundle_cost)}. "
        + (
            f"Time stolen from the VM's vCPUs (`/proc/stat`'s steal, `benches/steal.py`) "
            f"during the two-thread runs: {1e3 * sum(stolen_s):.0f} ms in all, in "
            f"{sum(x > 0 for x in stolen_s)} of {len(stolen_s)} runs."
            if stolen_s
            else "Time stolen from the VM's vCPUs: not read (no `/proc/stat`)."
        )
    )
    out(
        [
            f"Map: the 910 corrected Intel scans (2 cm, {len(grid)} cells, distributions "
            f"built); {n} different scans from local starts per run, split alternately "
            f"between the threads; {args.thread_reps} runs, alternating one and two threads. "
            f"`os.cpu_count()` = {os.cpu_count()}; load average before: "
            f"{load[0]:.2f} / {load[1]:.2f} / {load[2]:.2f} (other processes share the "
            "cores, so the two-thread run is limited by what the second core had free). "
            "CPU / wall: this process's CPU time over the wall time of the run (2.0 = both "
            "threads computing all the time; about 1.0 with two threads = they did not "
            "run in parallel, from the GIL or from busy cores). "
            f"Poses of the two-thread runs identical to the one-thread runs: {same}.\n",
            "| threads | matches / s (median run) | matches / s (best run) | CPU / wall (median) |",
            "|---:|---:|---:|---:|",
            f"| 1 | {s1:.0f} | {b1:.0f} | {np.median(cpu1):.2f} |",
            f"| 2 | {s2:.0f} | {b2:.0f} | {np.median(cpu2):.2f} |",
            f"| ratio | {s2 / s1:.2f}× | {b2 / b1:.2f}× | |",
            *pin_rows,
            f"| `match_many`, one thread (`threads=1`) | {mm1:.0f} | {mb1:.0f} | |",
            f"| `match_many`, every core (`threads=None`) | {mm2:.0f} | {mb2:.0f} "
            f"| {np.median(many_cpu):.2f} |",
            f"| ratio, `match_many` (against the faster one-thread row) | {many_ratio:.2f}× "
            f"| {many_best:.2f}× | |",
            *steady_rows,
            "",
            "Per run (one thread's time over the two threads' time right after it): "
            f"{', '.join(f'{r:.2f}' for r in per_run['unpinned'])}; median "
            f"{float(np.median(per_run['unpinned'])):.2f}×. Two threads' CPU / wall "
            f"per run: {', '.join(f'{c:.2f}' for c in cpu2)}. The second thread's first "
            "match began "
            f"{', '.join(f'{1e3 * x:.1f}' for x in lates)} ms after the clock started (a "
            "new thread needs the GIL, and the busy first thread that hands it over may "
            "get it woken on its own vCPU: see the pinned rows); both threads were matching during "
            f"{', '.join(f'{100 * x:.0f}' for x in overlaps)} % of the run (the rest: one "
            "thread started late or finished early). The second thread began "
            f"{1e3 * LATE_START:.0f} ms or more after the clock in {len(late_runs)} of "
            f"{len(lates)} runs (median ratio {median_or_dash(late_runs)} in those, "
            f"{median_or_dash(early_runs)} in the others). " + cpu_text,
            "",
            "Control, run after each pair of runs: SHA-256 of a 1 MiB buffer (`hashlib` "
            "releases the GIL), 128 hashes on one thread against 64 on each of two: "
            f"speed-up {np.median(controls):.2f}× (median; runs "
            f"{', '.join(f'{c:.2f}' for c in controls)}). A control near 1× means the "
            "second core was busy with other work, and the ratio above says nothing about "
            "the GIL; a control near 2× with a ratio near 1× would mean matches do not run "
            "in parallel.",
            "",
            f"Control on our own code, run after it: the {len(bundles)} bundles of "
            f"{THREAD_BUNDLE} consecutive scans merged into one scan ({bundle_points} points "
            f"median, {1e3 * float(np.median(bundle_1)) / len(bundles):.2f} ms a match on one "
            "thread, so the GIL is held for a fraction of a per cent of the time), all on "
            "one thread against half on each of two: speed-up "
            f"{bundle_ratio:.2f}× (median; runs "
            f"{', '.join(f'{r:.2f}' for r in per_run['bundles'])}). The ratio "
            "the two threads of single scans can reach on these cores in this run; below "
            "it, the cost is the GIL's (held for the argument conversion, the result and "
            "the Python loop, a few µs per match) and that of waking a thread that waits "
            "for it. " + bundle_text,
            *pin_text,
            "",
            f"`match_many`: the same {n} scans and guesses in one `NdtGrid.match_many` call "
            "(the GIL released once for the batch; the calling thread and a helper started for "
            "the batch each take the next scan not yet taken), on the calling thread alone and "
            f"then on every core, in {args.thread_reps} rounds of its own after the runs above "
            "(between them it lowered the unpinned ratio: benches/SPEED_LOG.md, session "
            "32); the ratio is taken against the faster of its own "
            "one-thread row and the first row. Per run (one thread's time over every core's "
            "right after it): "
            f"{', '.join(f'{r:.2f}' for r in per_run['many'])}; median "
            f"{float(np.median(per_run['many'])):.2f}×.",
            *steady_text,
        ]
    )
    if args.plot_threads:
        plotted(
            speed_plots.plot_threads(
                {
                    **per_run,
                    "sha": controls,
                    "late_unpinned": lates,
                    "late_pinned": pin_lates,
                },
                Path(args.plot_threads),
                late_start=LATE_START,
            )
        )
    return {
        "ratio": s2 / s1,
        "ratio_best": b2 / b1,
        "pinned_ratio": p2 / p1 if pin_1 else math.nan,
        "pinned_ratio_best": pb2 / pb1 if pin_1 else math.nan,
        "load": load[0],
        "control": float(np.median(controls)),
        "bundle_ratio": bundle_ratio,
        "many_ratio": many_ratio,
        "many_ratio_best": many_best,
        "steady_ratio": steady_ratio,
        "steady_ratio_best": steady_best,
        "steady_seconds": args.steady_seconds,
        "one_cpu_runs": len(together) if known else None,
        "one_cpu_first_runs": len(first_together) if first else None,
        "cpu_read_runs": known,
        "late_runs": len(late_runs),
        # Each two-thread run, in order, for --json: the ratios (per_run; the picture's
        # lists of them by place are left out, the flags below give them), the second
        # thread's start after the clock (s), and whether the two threads were on one
        # vCPU at their first matches and half-way through (None: not read).
        "per_run": {
            k: per_run[k]
            for k in (
                "unpinned",
                "pinned",
                "bundles",
                "many",
                "steady",
                "bundles_share",
                "bundles_cost",
                "pinned_share",
                "pinned_cost",
            )
        },
        # The seconds stolen from the guest during each bundles' two-thread run.
        "bundles_steal_s": bundle_steal,
        "late_s": lates,
        "one_cpu_first": shared_first,
        "one_cpu_half": shared,
    }


# ----------------------------------------------------------------------------- 6. memory


def memory_child(copies: int) -> None:
    """``--memory-child``: the Intel map (``copies`` copies 1 km apart) in this fresh
    process; RSS before and after the inserts and after matches; JSON to stdout."""
    pts, poses = intel_corrected()
    jobs = [(p, np.add(q, [FAR * c, 0.0, 0.0])) for c in range(copies) for p, q in zip(pts, poses)]
    gc.collect()
    rss0, _ = rss_kib()
    grid = ndtgrid.NdtGrid(CELL)
    for p, q in jobs:
        grid.insert(p, q)
    rss1, _ = rss_kib()
    for c in range(copies):  # one match per copy: every part's distributions are built
        grid.match(pts[-1], poses[-1] + [FAR * c, 0.0, 0.0])
    rss2, _ = rss_kib()
    grid.match(pts[0], poses[0])
    rss3, _ = rss_kib()
    print(
        json.dumps(
            {
                "copies": copies,
                "cells": len(grid),
                "file_bytes": len(grid.to_bytes()),
                "rss0": rss0,
                "rss_inserted": rss1,
                "rss_matched": rss2,
                "rss_matched_again": rss3,
            }
        )
    )


def section_memory(args: argparse.Namespace) -> dict[str, Any]:
    """Section 6."""
    out("\n## 6. Memory: bytes per occupied cell\n")
    rows = []
    for c in progress(args.memory_copies, "memory children"):
        rows.append(child(["--memory-child", str(c)]))
    out(
        [
            "Each size in a fresh child process: the 910 corrected Intel scans (and far "
            "copies of them, 1 km apart) are read first, then inserted into one 2 cm "
            "`NdtGrid` (6 pyramid levels); RSS (VmRSS) growth over the inserts, then after "
            "one `match` per copy (the distributions, part of the look-up structure, are "
            "built), divided by `len(grid)` (occupied fine cells; the coarse levels' cells "
            "are included in the bytes). A second match did not change the RSS by more "
            "than the figure in the last column. File: `to_bytes()` per cell (the state "
            "itself).\n",
            "| map | occupied cells | bytes / cell, cells only | bytes / cell, with "
            "distributions | file bytes / cell | RSS after, MiB | 2nd match ΔRSS [KiB] |",
            "|---|---:|---:|---:|---:|---:|---:|",
        ]
    )
    for r in rows:
        cells = r["cells"]
        out(
            f"| Intel × {r['copies']} | {cells} "
            f"| {1024 * (r['rss_inserted'] - r['rss0']) / cells:.0f} "
            f"| {1024 * (r['rss_matched'] - r['rss0']) / cells:.0f} "
            f"| {r['file_bytes'] / cells:.0f} | {r['rss_matched'] / 1024:.1f} "
            f"| {r['rss_matched_again'] - r['rss_matched']} |"
        )
    if len(rows) >= 2:
        a, b = rows[0], rows[-1]
        dc = b["cells"] - a["cells"]
        d_ins = 1024 * ((b["rss_inserted"] - b["rss0"]) - (a["rss_inserted"] - a["rss0"])) / dc
        d_all = 1024 * ((b["rss_matched"] - b["rss0"]) - (a["rss_matched"] - a["rss0"])) / dc
        out(
            f"\nMarginal, between the smallest and the largest map: {d_ins:.0f} bytes per "
            f"added cell without distributions, {d_all:.0f} with. RSS grows in steps (hash "
            "tables double), so single sizes scatter around it."
        )
    last = rows[-1] if rows else None
    return {
        "bytes_per_cell": (
            1024 * (last["rss_matched"] - last["rss0"]) / last["cells"] if last else math.nan
        )
    }


# ----------------------------------------------------------------------------- summary


def targets(res: dict[str, dict[str, Any]]) -> None:
    """The issue's targets against this run."""
    out("\n## Targets of issue 7 against this run\n")
    out("| target | this run | met |\n|---|---|---|")

    def row(target: str, value: str, ok: bool | None) -> None:
        out(f"| {target} | {value} | {'-' if ok is None else 'yes' if ok else 'no'} |")

    m = res.get("match", {})
    for key, label in (
        ("sim_map", "simulated 683-beam"),
        ("urg_map", "real URG-04LX"),
    ):
        if key in m:
            v = m[key]["ours"]
            row(
                f"median match ≤ {tg.MATCH_TEXT} ({label} scan, {m[key]['points']:.0f} points "
                "median, 2 cm map of 20 scans)",
                f"{ms(v)} ms",
                v <= tg.MATCH_S,
            )
    if "≥ 500" in m.get("urg_log", {}):
        v, npts = m["urg_log"]["≥ 500"]
        row(
            f"median match ≤ {tg.MATCH_TEXT} (real URG-04LX scans with ≥ 500 points, {npts:.0f} "
            "median, 2 cm map of 20 scans)",
            f"{ms(v)} ms",
            v <= tg.MATCH_S,
        )
    for key, label in (
        ("sick", "real SICK pairs"),
        ("urg_pairs", "real URG pairs"),
        ("urg_map", "real URG map"),
        ("sim_map", "sim 683-beam map"),
    ):
        if key in m and "fastest" in m[key]:
            name, t = m[key]["fastest"]
            r = t / m[key]["ours"]
            value = f"{r:.2f}× ({name})"
            if "fastest_good" in m[key]:
                gname, gt = m[key]["fastest_good"]
                value += f"; at ≥ our success: {gt / m[key]['ours']:.2f}× ({gname})"
            else:
                value += "; no peer at ≥ our success"
            row(
                f"≥ {tg.PEER_TEXT} faster than the fastest peer ({label})",
                value,
                r >= tg.PEER_RATIO,
            )
    ins = res.get("insert", {})
    for title, v in ins.items():
        row(
            f"insert ≤ {tg.INSERT_TEXT} ({title}, {v['points']:.0f} points)",
            f"{us(v['ours'])} µs",
            v["ours"] <= tg.INSERT_S if tg.insert_judged(v["points"]) else None,
        )
    o = res.get("odometry", {})
    if o:
        full = tg.intel_judged(o["scans"])
        row(
            f"Intel log through `Odometry` ≤ {tg.INTEL_TEXT} ({o['scans']} scans)",
            f"{o['ours']:.2f} s ({1e3 * o['ours'] / o['scans']:.3f} ms / scan), median of "
            f"{len(o['ours_runs'])} runs: {', '.join(f'{t:.2f}' for t in o['ours_runs'])} s; "
            f"one thread {o['ours_one_thread']:.2f} s; poses only {o['ours_poses_only']:.2f} s",
            o["ours"] <= tg.INTEL_S if full else None,
        )
        for key, label in (
            ("fastest", f"odometry ≥ {tg.PEER_TEXT} faster than the fastest peer"),
            (
                "fastest_good",
                f"odometry ≥ {tg.PEER_TEXT} faster than the fastest peer at ≤ our relation error",
            ),
        ):
            if key in o:
                name, t = o[key]
                one = t / o["ours_one_thread"]
                bare = t / o["ours_poses_only"]
                row(
                    label,
                    f"{t / o['ours']:.2f}× ({name}); one thread {one:.2f}×; poses only "
                    f"(`build_map=False`) {bare:.2f}×",
                    t / o["ours"] >= tg.PEER_RATIO,
                )
        if "fastest_good" not in o and "fastest" in o:
            row(
                f"odometry ≥ {tg.PEER_TEXT} faster than the fastest peer at ≤ our relation error",
                "no peer reached our relation error",
                None,
            )
        row("peak RSS of the Intel run", f"{o['vmhwm_mib']:.1f} MiB", None)
    s = res.get("sweeps", {})
    if "points" in s:
        _, slope, _, r2 = s["points"]
        row(
            "time linear in scan points",
            f"R² = {r2:.3f}, {1e6 * slope:.3f} µs / point",
            r2 >= tg.LINEAR_R2,
        )
    for kind in ("map_recent", "map_padded"):
        if kind in s:
            _, _, _, sub = s[kind]
            g = sub[-1]["median"] / sub[0]["median"]
            row(
                f"time does not grow with map size ({kind[4:]} maps, "
                f"{sub[0]['cells']:.0f} → {sub[-1]['cells']:.0f} cells)",
                f"{g:.2f}× the time",
                g <= tg.FLAT_GROWTH,
            )
    t = res.get("threads", {})
    if t:
        row(
            f"two threads ≥ {tg.THREADS_TEXT} one (threads started for each run, placed by the "
            "kernel)",
            f"{t['ratio']:.2f}× (best runs {t['ratio_best']:.2f}×; GIL-free controls: "
            f"SHA-256 {t['control']:.2f}×, our matcher on {THREAD_BUNDLE}-scan bundles "
            f"{t['bundle_ratio']:.2f}×"
            + (
                ""
                if t.get("one_cpu_runs") is None
                else "; both threads on one vCPU at their first matches in "
                f"{t['one_cpu_first_runs']} and half-way through in {t['one_cpu_runs']} "
                f"of {t['cpu_read_runs']} runs"
            )
            + f"; the second thread {1e3 * LATE_START:.0f} ms or more late in "
            f"{t['late_runs']} of {len(t['late_s'])} runs)",
            t["ratio"] >= tg.THREADS_RATIO,
        )
        pr = t.get("pinned_ratio", math.nan)
        row(
            f"two threads ≥ {tg.THREADS_TEXT} one, the threads pinned to the two cores",
            "not measured"
            if math.isnan(pr)
            else f"{pr:.2f}× (best runs {t['pinned_ratio_best']:.2f}×)",
            None if math.isnan(pr) else pr >= tg.THREADS_RATIO,
        )
        sr = t.get("steady_ratio", math.nan)
        row(
            f"two threads ≥ {tg.THREADS_TEXT} one, threads that keep matching "
            f"({t.get('steady_seconds', math.nan):g} s rounds, placed by the kernel)",
            "not measured"
            if math.isnan(sr)
            else f"{sr:.2f}× (best rounds {t['steady_ratio_best']:.2f}×)",
            None if math.isnan(sr) else sr >= tg.THREADS_RATIO,
        )
        row(
            f"one `match_many` call on every core ≥ {tg.THREADS_TEXT} one thread (the "
            "library's own threads, not Python's)",
            f"{t['many_ratio']:.2f}× (best runs {t['many_ratio_best']:.2f}×)",
            t["many_ratio"] >= tg.THREADS_RATIO,
        )
    mem = res.get("memory", {})
    if mem:
        row("bytes per occupied cell (with distributions)", f"{mem['bytes_per_cell']:.0f}", None)


def main() -> int:
    """Parse the options and run the sections."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer cases and scans (< 1 min)")
    ap.add_argument("--sections", nargs="+", choices=SECTIONS, default=list(SECTIONS))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--pairs", type=int, help="real SICK pairs per log (default 30)")
    ap.add_argument("--urg-cases", type=int, help="candidate URG cases per set (default 40)")
    ap.add_argument("--sim-cases", type=int, help="simulated scan-to-map cases (default 20)")
    ap.add_argument("--starts", type=int, help="local starts per case (default 8)")
    ap.add_argument("--prefill", type=int, default=100, help="scans in a map before inserts")
    ap.add_argument("--inserts", type=int, help="timed inserts per set (default 300)")
    ap.add_argument("--intel-scans", type=int, help="Intel scans for odometry (default all)")
    ap.add_argument(
        "--intel-runs", type=int, help="runs of our Intel loop; the median is judged (default 3)"
    )
    ap.add_argument(
        "--plot",
        help="sweep plot path (default docs/img/speed_sweeps.png; none with --quick unless given)",
    )
    ap.add_argument(
        "--plot-threads",
        help="thread plot path (default docs/img/speed_threads.png; none with --quick unless "
        "given)",
    )
    ap.add_argument(
        "--plot-peers",
        help="picture of sections 1-3, ours against the peers (default "
        "docs/img/speed_peers.png; none with --quick unless given)",
    )
    ap.add_argument(
        "--json",
        help="also write every section's results (the thread section's run by run) as "
        'JSON to this path, after each section ("complete": true once all have run)',
    )
    ap.add_argument("--intel-child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--one-thread", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--poses-only", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--memory-child", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    args = ap.parse_args()
    q = args.quick
    defaults = {
        "pairs": 4 if q else 30,
        "urg_cases": 8 if q else 40,
        "sim_cases": 6 if q else 20,
        "starts": 3 if q else 8,
        "inserts": 60 if q else 300,
        "intel_scans": 2000 if q else 10**9,
        "intel_runs": 1 if q else 3,
    }
    for k, v in defaults.items():
        if getattr(args, k) is None:
            setattr(args, k, v)
    if args.plot is None and not q:
        args.plot = str(ROOT / "docs" / "img" / "speed_sweeps.png")
    if args.plot_threads is None and not q:
        args.plot_threads = str(ROOT / "docs" / "img" / "speed_threads.png")
    if args.plot_peers is None and not q:
        args.plot_peers = str(ROOT / "docs" / "img" / "speed_peers.png")
    args.sweep_points = [100, 683, 2000] if q else [100, 200, 400, 683, 1000, 2000, 4000]
    args.sweep_maps = 3 if q else 8
    args.sweep_tests = 5 if q else 20
    args.sweep_scans = [1, 30, 300] if q else [1, 3, 10, 30, 100, 300, 880]
    args.sweep_copies = [0, 2] if q else [0, 1, 4, 16]
    args.thread_matches = 100 if q else 600
    args.thread_reps = 3 if q else 21
    args.steady_reps = 2 if q else 5
    args.steady_seconds = 0.2 if q else 1.0
    args.memory_copies = [1, 2] if q else [1, 2, 4, 8]

    if args.intel_child:
        intel_child(args.intel_scans, args.out, args.one_thread, args.poses_only)
        return 0
    if args.memory_child is not None:
        memory_child(args.memory_child)
        return 0

    start = time.perf_counter()
    machine = datasets.machine()
    stamp = machine + datasets.dirty()  # the machine and the work tree's commit and state
    out("# ndtgrid speed (`benches/speed.py`)\n")
    out(
        f"Machine: {stamp}; ndtgrid {ndtgrid.__version__}; numpy "
        f"{np.__version__}; load average at start {os.getloadavg()[0]:.2f}; command "
        f"`{' '.join(['python benches/speed.py', *sys.argv[1:]])}`."
    )
    versions = []
    for dist in ("small_gicp", "open3d-cpu", "open3d", "kiss-icp"):
        with contextlib.suppress(importlib.metadata.PackageNotFoundError):
            versions.append(f"{dist} {importlib.metadata.version(dist)}")
    out("Peers installed: " + (", ".join(versions) or "none") + ".")
    runners: dict[str, Callable[[argparse.Namespace], dict[str, Any]]] = {
        "match": section_match,
        "insert": section_insert,
        "odometry": section_odometry,
        "sweeps": section_sweeps,
        "threads": section_threads,
        "memory": section_memory,
    }
    res: dict[str, dict[str, Any]] = {}
    json_path = Path(args.json) if args.json else None
    for name in SECTIONS:
        if name in args.sections:
            t0 = time.perf_counter()
            gc.collect()
            res[name] = runners[name](args)
            log(f"section {name}: {time.perf_counter() - t0:.0f} s")
            if json_path is not None:
                # After each section, so a run stopped part-way keeps what it measured.
                write_json(json_path, stamp, res, complete=False)
    if args.plot_peers and res.keys() & {"match", "insert", "odometry"}:
        out("\n## Ours against the peers, in one picture")
        plotted(speed_plots.plot_peers(res, Path(args.plot_peers), machine))
    targets(res)
    if json_path is not None:
        write_json(json_path, stamp, res, complete=True)
        out(f"\nResults as JSON: `{json_path}`.")
    total = time.perf_counter() - start
    out(f"\nWhole run: {total / 60:.1f} min; load average at the end {os.getloadavg()[0]:.2f}.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
