"""Scan-to-map odometry on the Freiburg benchmark logs: ndtgrid vs raw odometry vs small_gicp.

For each log of ``../shared/data/real/benchmark-scans-split`` (Intel, ACES, FR079, MIT
CSAIL, MIT Killian: every raw scan with its raw odometry pose), run over the whole log

- ``ndtgrid.Odometry`` with its defaults (2 cm cells), and
- the peer: small_gicp VGICP scan-to-map against its incremental ``GaussianVoxelMap``
  (LRU), with the set-up PEERS.md calls fair for 2D (scans extruded to three layers
  z = -5, 0, +5 cm; result projected to SE(2)) and the same loop around it: the same
  motion prior (odometry increment; the constant-velocity prior when the match from it
  fails), the same acceptance rule (>= 30 % of the points matched), the same insertion
  policy and range limit as ``ndtgrid.OdometryConfig``;

then score both, and the raw odometry, with the relation metric of Kümmerle et al. (2009)
on consecutive SLAM-corrected scans (linked to raw scans by the index CSVs): the error of
the estimated motion between two corrected scans against the corrected motion.

Run from the repository root (prints progress, then a markdown table)::

    python benches/datasets.py                       # all five logs, with the peer
    python benches/datasets.py --datasets intel --no-peer
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import platform
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

import ndtgrid
from ndtgrid import se2
from ndtgrid.bench import kernels_name, processor_name
from ndtgrid.evaluation import RelationSummary, relation_errors
from ndtgrid.io import Scan, read_benchmark_index, read_benchmark_split

F64 = npt.NDArray[np.float64]
# The repository (git is asked about its commit here, wherever the script runs from).
REPO = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "real" / "benchmark-scans-split"
#: name -> (index CSV stem, label, published sequential scan matching [m], Kümmerle 2009).
DATASETS = {
    "intel": ("intel__intel-corrected", "Intel", "0.220 ± 0.296"),
    "aces": ("aces__aces-corrected", "ACES", "0.173 ± 0.614"),
    "fr079": ("fr079__freiburg-079-corrected", "FR079", "0.258 ± 0.427"),
    "mit_csail": ("mit_csail__csail-corrected", "MIT CSAIL", "0.106 ± 0.325"),
    "mit_killian": ("mit_killian__infinite-corridor-corrected", "MIT Killian", "1.651 ± 4.138"),
}
PROGRESS_EVERY = 2000


@dataclass
class Run:
    """Poses of one method over a log, its time, and (ours) the scans whose match ran the
    rotational multi-start (``OdometryStep.multi_start``), the scans added to the loop's
    map (``Odometry.insertions``) and those its matching grid took
    (``Odometry.grid_insertions``)."""

    poses: F64
    seconds: float
    multi_starts: int = 0
    insertions: int = 0
    grid_insertions: int = 0


def progress(label: str, k: int, n: int, start: float) -> None:
    if k % PROGRESS_EVERY == 0 or k == n:
        rate = k / max(time.perf_counter() - start, 1e-9)
        print(f"  {label}: {k}/{n} scans ({rate:.0f} scans/s)", file=sys.stderr, flush=True)


def run_ndtgrid(scans: list[Scan], config: ndtgrid.OdometryConfig | None = None) -> Run:
    """``ndtgrid.Odometry`` (2 cm; its defaults unless ``config``) over the scans. The
    time ends with a read of ``odo.mapper``, which waits for the mapper's helper thread
    to take in the last scans."""
    odo = ndtgrid.Odometry(cell_size=0.02, config=config)
    multi_starts = 0
    start = time.perf_counter()
    for k, s in enumerate(scans, start=1):
        odo.step(s.ranges, s.angles, s.odom)
        step = odo.last_step
        multi_starts += step is not None and step.multi_start
        progress("ndtgrid", k, len(scans), start)
    _ = odo.mapper
    seconds = time.perf_counter() - start
    return Run(odo.poses, seconds, multi_starts, odo.insertions, odo.grid_insertions)


def matrix(p: F64) -> F64:
    c, s = math.cos(p[2]), math.sin(p[2])
    t = np.eye(4)
    t[:2, :2] = [[c, -s], [s, c]]
    t[:2, 3] = p[:2]
    return t


class GicpOdometry:
    """small_gicp VGICP scan-to-map odometry in the same loop as ``ndtgrid.Odometry``."""

    def __init__(
        self,
        voxels: tuple[float, ...],
        horizon: int,
        config: ndtgrid.OdometryConfig,
        downsample: float = 0.01,
    ):
        import small_gicp  # type: ignore[import-not-found]

        self.sg = small_gicp
        self.maps = [small_gicp.GaussianVoxelMap(v) for v in voxels]
        for m in self.maps:
            m.set_lru(horizon, 10)
        self.cfg = config
        self.downsample = downsample
        self.poses: list[F64] = []
        self.last_odom: F64 | None = None
        self.last_insert: F64 | None = None

    def _align(self, cloud: object, guess: F64) -> tuple[F64, bool]:
        t = matrix(guess)
        res = None
        for m in self.maps:  # coarse to fine
            res = self.sg.align(m, cloud, t, max_iterations=20)
            t = res.T_target_source
        assert res is not None
        pose = np.array([t[0, 3], t[1, 3], math.atan2(t[1, 0], t[0, 0])])
        ok = res.num_inliers >= self.cfg.min_match_ratio * cloud.size()  # type: ignore[attr-defined]
        return pose, bool(ok)

    def step(self, scan: Scan) -> F64:
        pts = scan.points(min_range=self.cfg.min_range, max_range=self.cfg.max_range)
        layers = np.vstack([np.c_[pts, np.full(len(pts), z)] for z in (-0.05, 0.0, 0.05)])
        cloud, _ = self.sg.preprocess_points(
            layers, downsampling_resolution=self.downsample, num_neighbors=10
        )
        cv = None
        if len(self.poses) >= 2:
            cv = se2.compose(self.poses[-1], se2.between(self.poses[-2], self.poses[-1]))
        elif self.poses:
            cv = self.poses[-1]
        # As ndtgrid.Odometry: the first pose is the odometry pose when given, else the origin.
        first = scan.odom if scan.odom is not None else np.zeros(3)
        pred: F64 = cv if cv is not None else first
        if self.poses and self.last_odom is not None and scan.odom is not None:
            pred = se2.compose(self.poses[-1], se2.between(self.last_odom, scan.odom))
        pose = pred
        if self.last_insert is not None and cloud.size() > 0:
            est, ok = self._align(cloud, pred)
            if not ok and cv is not None:
                est, ok = self._align(cloud, cv)
            if ok:
                pose = est
        d = None if self.last_insert is None else se2.between(self.last_insert, pose)
        if (
            d is None
            or math.hypot(d[0], d[1]) >= self.cfg.insert_distance
            or abs(d[2]) >= (self.cfg.insert_angle)
        ):
            for m in self.maps:
                m.insert(cloud, matrix(pose))
            self.last_insert = pose
        self.poses.append(pose)
        self.last_odom = scan.odom
        return pose


def run_peer(scans: list[Scan], voxels: tuple[float, ...], horizon: int, ds: float) -> Run:
    peer = GicpOdometry(voxels, horizon, ndtgrid.OdometryConfig(), ds)
    start = time.perf_counter()
    for k, s in enumerate(scans, start=1):
        peer.step(s)
        progress("small_gicp", k, len(scans), start)
    return Run(np.array(peer.poses), time.perf_counter() - start)


@dataclass
class Row:
    """One log's results for the tables of :func:`main`."""

    label: str
    scans: int
    relations: int
    raw: RelationSummary
    ours: RelationSummary
    peer: RelationSummary | None
    ms_ours: float
    ms_peer: float
    rtf: float
    duration: float
    read_s: float
    published: str
    vs_raw: tuple[float, float, float]
    vs_peer: tuple[float, float, float] | None


def log_duration(name: str, index: ndtgrid.io.BenchmarkIndex, n: int) -> float:
    """Seconds the whole log spans: from the corrected scans' timestamps (mean scan period
    times n - 1); for MIT CSAIL from its FLASER log (the index has %g-rounded times); NaN
    for MIT Killian (its timestamps are broken)."""
    if name == "mit_killian":
        return math.nan
    if name == "mit_csail":
        flaser = DATA.parent / "mit-csail-flaser" / "dataset.txt"
        if not flaser.exists():
            return math.nan
        stamps = [s.timestamp for s in ndtgrid.io.read_carmen(flaser)]
        return stamps[-1] - stamps[0]
    span = float(index.timestamp[-1] - index.timestamp[0])
    steps = int(index.raw_scan[-1] - index.raw_scan[0])
    return span / steps * (n - 1)


def fmt(s: RelationSummary) -> str:
    return f"{s.translation_mean:.4f} ± {s.translation_std:.3f} ({s.translation_max:.2f})"


def paired(a: F64, b: F64, draws: int = 2000) -> tuple[float, float, float]:
    """Mean of ``a - b`` over the same relations [m] with a 95 % bootstrap interval."""
    rng = np.random.default_rng(0)
    d = a - b
    means = d[rng.integers(0, d.size, (draws, d.size))].mean(axis=1)
    lo, hi = np.percentile(means, [2.5, 97.5])
    return float(d.mean()), float(lo), float(hi)


def fmt_paired(p: tuple[float, float, float] | None) -> str:
    if p is None:
        return "-"
    return f"{1e3 * p[0]:+.1f} [{1e3 * p[1]:+.1f}, {1e3 * p[2]:+.1f}]"


def fmt_rot(s: RelationSummary) -> str:
    return f"{s.rotation_mean:.2f} ± {s.rotation_std:.2f} ({s.rotation_max:.1f})"


def git(*args: str) -> str | None:
    """The output of ``git args`` run in the repository, ``None`` when git cannot
    answer (not installed, not a clone)."""
    try:
        return subprocess.run(
            ["git", *args], capture_output=True, text=True, check=True, cwd=REPO
        ).stdout
    except (OSError, subprocess.CalledProcessError):
        return None


def machine() -> str:
    """Cores, processor and kernels (:func:`ndtgrid.bench.processor_name`,
    :func:`ndtgrid.bench.kernels_name`), Python and commit."""
    cpu = f"{processor_name()}, {kernels_name()}"
    commit = (git("rev-parse", "--short", "HEAD") or "unknown").strip()
    return f"{os.cpu_count()} cores of {cpu}, Python {platform.python_version()}, commit {commit}"


def write_whole(path: Path, text: str) -> None:
    """``text`` as the file ``path``, written to a file beside it and renamed over it,
    so a reader never sees half a document; if the write or the rename fails (a full
    disk, Ctrl-C), that file is removed and ``path`` keeps what it held."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".part")
    try:
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(path)
    except BaseException:
        with contextlib.suppress(OSError):  # the first error is the one to report
            tmp.unlink(missing_ok=True)
        raise


def dirty() -> str:
    """`` (+ uncommitted changes)`` when the work tree differs from HEAD, else ``""``."""
    st = git("status", "--porcelain", "--untracked-files=no") or ""
    return " (+ uncommitted changes)" if st.strip() else ""


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--datasets", nargs="+", default=list(DATASETS), choices=list(DATASETS))
    parser.add_argument("--no-peer", action="store_true", help="skip small_gicp")
    parser.add_argument("--peer-voxels", default="0.2", help="VGICP voxel sizes, coarse to fine")
    parser.add_argument("--peer-horizon", type=int, default=100, help="LRU horizon [insertions]")
    parser.add_argument(
        "--peer-downsample",
        type=float,
        default=0.01,
        help="small_gicp voxel downsampling of each scan [m] (0.01: merges only points "
        "closer than 1 cm, i.e. no downsampling, as for ndtgrid)",
    )
    parser.add_argument("--no-ours", action="store_true", help="skip ndtgrid (peer variants)")
    args = parser.parse_args()
    voxels = tuple(float(v) for v in args.peer_voxels.split(","))
    print(f"machine: {machine()}", file=sys.stderr)
    rows: list[Row] = []
    for name in args.datasets:
        stem, label, published = DATASETS[name]
        start = time.perf_counter()
        scans = list(read_benchmark_split(DATA / f"{name}.tar.gz"))
        read_s = time.perf_counter() - start
        print(f"{label}: {len(scans)} scans read in {read_s:.1f} s", file=sys.stderr)
        index = read_benchmark_index(DATA / f"{stem}__index.csv")
        ref = index.corrected
        raw = np.array([s.odom for s in scans])
        ours = run_ndtgrid(scans) if not args.no_ours else Run(raw.copy(), math.nan)
        peer = (
            None
            if args.no_peer
            else run_peer(scans, voxels, args.peer_horizon, args.peer_downsample)
        )
        r_raw = relation_errors(raw[index.raw_scan], ref)
        r_ours = relation_errors(ours.poses[index.raw_scan], ref)
        r_peer = None if peer is None else relation_errors(peer.poses[index.raw_scan], ref)
        e_raw, e_ours = r_raw.summary(), r_ours.summary()
        e_peer = None if r_peer is None else r_peer.summary()
        n = len(scans)
        duration = log_duration(name, index, n)
        row = Row(
            label=label,
            scans=n,
            relations=e_ours.n,
            raw=e_raw,
            ours=e_ours,
            peer=e_peer,
            ms_ours=1e3 * ours.seconds / n,
            ms_peer=math.nan if peer is None else 1e3 * peer.seconds / n,
            rtf=duration / (read_s + ours.seconds),
            duration=duration,
            read_s=read_s,
            published=published,
            vs_raw=paired(r_ours.translation, r_raw.translation),
            vs_peer=None if r_peer is None else paired(r_ours.translation, r_peer.translation),
        )
        rows.append(row)
        print(f"  raw odometry: {e_raw}\n  ndtgrid:      {e_ours}", file=sys.stderr)
        if e_peer is not None:
            print(f"  small_gicp:   {e_peer}", file=sys.stderr)
        span = "unknown (broken timestamps)" if math.isnan(duration) else f"~{duration:.0f} s"
        rtf = "" if math.isnan(row.rtf) else f" = {row.rtf:.0f}x real time"
        print(
            f"  {row.ms_ours:.2f} ms/scan; log spans {span}; read + odometry "
            f"{read_s + ours.seconds:.1f} s{rtf}",
            file=sys.stderr,
        )
    print(f"\nMachine: {machine()}\n")
    print(
        "| log | scans | relations | raw odometry [m] | ndtgrid [m] | small_gicp [m] "
        "| raw odometry [deg] | ndtgrid [deg] | small_gicp [deg] | ndtgrid ms/scan "
        "| small_gicp ms/scan | published seq. scan matching [m] |"
    )
    print("|---|---:|---:|---|---|---|---|---|---|---:|---:|---|")
    for r in rows:
        peer_t = "-" if r.peer is None else fmt(r.peer)
        peer_r = "-" if r.peer is None else fmt_rot(r.peer)
        print(
            f"| {r.label} | {r.scans} | {r.relations} | {fmt(r.raw)} "
            f"| {fmt(r.ours)} | {peer_t} | {fmt_rot(r.raw)} | {fmt_rot(r.ours)} "
            f"| {peer_r} | {r.ms_ours:.2f} | {r.ms_peer:.2f} | {r.published} |"
        )
    print(
        "\nPaired differences of the translational error on the same relations, mean and "
        "95 % bootstrap interval [mm] (negative: ndtgrid lower):\n"
    )
    print("| log | ndtgrid - raw odometry [mm] | ndtgrid - small_gicp [mm] |")
    print("|---|---|---|")
    for r in rows:
        print(f"| {r.label} | {fmt_paired(r.vs_raw)} | {fmt_paired(r.vs_peer)} |")
    print()
    for r in rows:
        span = "unknown (broken timestamps)" if math.isnan(r.duration) else f"~{r.duration:.0f} s"
        rtf = "" if math.isnan(r.duration) else f" = {r.rtf:.0f}x real time"
        print(
            f"- {r.label}: log spans {span}; reading {r.read_s:.1f} s + odometry "
            f"{r.ms_ours * r.scans / 1e3:.1f} s{rtf}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
