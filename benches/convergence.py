"""Convergence study (paper §IV-A, Fig. 5) against peers, on real and simulated pairs.

For each scan pair (map = the earlier scan at its reference pose, source = the
later scan), every method starts from the same perturbed guesses around the
reference pose: a wide set (uniform in ±0.4 m, ±10°) and a local set (±5 cm,
±2°). Success: final error < 5 cm and < 1° on real pairs (their reference is a
SLAM result good to a few cm), < 2 cm and < 0.5° on simulated pairs.

Pairs of the real URG-04LX log (no reference poses) use as reference the pose on
which two independent peers agree (see :func:`urg_pairs`). Simulated pairs come
from ``ndtgrid.sim`` (the sticks room, URG-04LX and
SICK-like presets, with the simulator's noise and false detections).

Run: ``python benches/convergence.py [--pairs 12] [--starts 8] [--sim-pairs 8]
[--offset 0 0.5 ...]``; prints a Markdown table per pair set and start set.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import peers as peer_lib

import ndtgrid
from ndtgrid.evaluation import corrected_pairs, pose_error
from ndtgrid.io import read_benchmark_index, read_carmen
from ndtgrid.presets import ORIGINAL_NDT, PAPER

REAL = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "real"
LOGS = {
    "Intel": ("intel-corrected.log.gz", "intel__intel-corrected__index.csv"),
    "ACES": ("aces-corrected.log.gz", "aces__aces-corrected__index.csv"),
    "FR079": ("freiburg-079-corrected.log.gz", "fr079__freiburg-079-corrected__index.csv"),
    "MIT CSAIL": ("csail-corrected.log.gz", "mit_csail__csail-corrected__index.csv"),
}
MAX_RANGE = 40.0


@dataclass
class Pair:
    """Target points (map frame), source points (scan frame), reference pose."""

    group: str
    target: np.ndarray
    source: np.ndarray
    truth: np.ndarray
    tol: tuple[float, float] = (0.05, np.radians(1.0))  # success: error below [m, rad]
    subset: str = ""  # the offset set a real pair belongs to (per-set table)


def urg_pairs(count: int) -> Iterator[Pair]:
    """``count`` pairs of scans 3 apart (about 0.3 s) from the real URG-04LX log
    ``exp1.dat``. It has no reference poses: a pair's reference is where two
    independent peers (small_gicp GICP and Open3D point-to-plane ICP, started
    from the wheel-odometry increment) agree within 1 cm and 0.3°, their mean;
    pairs where they disagree are skipped. Success: < 2 cm and < 0.5°."""
    from ndtgrid import se2
    from ndtgrid.io import read_mines

    log = REAL / "breezyslam-mines-urg04lx" / "exp1.dat"
    if not log.exists():
        print("skipped the URG-04LX log: ../shared/data/real absent")
        return
    scans = list(read_mines(log))
    judges = [
        p for p in peer_lib.all_peers() if p.name.startswith("small_gicp GICP") or "plane" in p.name
    ]
    for k in np.linspace(0, len(scans) - 4, count).astype(int):
        a, b = scans[k], scans[k + 3]
        pa, pb = a.points(max_range=4.0), b.points(max_range=4.0)
        if a.odom is None or b.odom is None or len(pa) < 100 or len(pb) < 100:
            continue
        guess = se2.between(a.odom, b.odom)
        votes = [j.align(j.prepare(pa), pb, guess) for j in judges]
        if len(votes) < 2:
            continue
        dt, dr = pose_error(votes[0], votes[1])
        if dt < 0.01 and dr < np.radians(0.3):
            truth = np.mean(votes, axis=0)
            yield Pair("URG-04LX exp1", pa, pb, truth, (0.02, np.radians(0.5)))


def sim_pairs(count: int, seed: int = 0) -> Iterator[Pair]:
    """``count`` pairs per laser preset from ``ndtgrid.sim``: the sticks room,
    scans 0.3 m apart along its tour, the simulator's noise and false detections.
    Success: < 2 cm and < 0.5° (the truth is exact)."""
    from ndtgrid import sim

    room = sim.sticks_room()
    poses = sim.trajectory(room.tour, step=0.05)
    rng = np.random.default_rng(seed)
    for laser in (sim.URG04LX, sim.SICK_LMS):
        for i in np.linspace(0, len(poses) - 7, count).astype(int):
            a, b = poses[i], poses[i + 6]
            ra, aa = laser.scan(room, a, rng=rng)
            rb, ab = laser.scan(room, b, rng=rng)
            pa = ndtgrid.ranges_to_points(ra, aa, max_range=laser.max_range)
            pb = ndtgrid.ranges_to_points(rb, ab, max_range=laser.max_range)
            yield Pair(f"sim {laser.name}", apply(a, pa), pb, b, (0.02, np.radians(0.5)))


def real_pairs(per_log: int, offset: float = 0.0) -> Iterator[Pair]:
    """``per_log`` consecutive corrected pairs spread evenly over each log; with an
    ``offset`` in (0, 1), the pairs that far between those (0.5: the held-out set)."""
    for name, (log, csv) in LOGS.items():
        if not (REAL / "radish-gfs-corrected" / log).exists():
            print(f"skipped {name}: ../shared/data/real absent")
            continue
        scans = list(read_carmen(REAL / "radish-gfs-corrected" / log))
        index = read_benchmark_index(REAL / "benchmark-scans-split" / csv)
        pairs = list(corrected_pairs(scans, index, max_range=MAX_RANGE))
        at = np.linspace(0, len(pairs) - 1, per_log + (offset > 0))
        if offset > 0:
            at = at[:-1] + offset * (at[1:] - at[:-1])
        for k in at.astype(int):
            p = pairs[k]
            target = apply(p.reference_pose, p.reference_points)
            yield Pair(name, target, p.points, p.true_pose, subset=f"{offset:g}")


def apply(pose: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """Scan-frame points seen from ``pose`` in the map frame."""
    c, s = np.cos(pose[2]), np.sin(pose[2])
    return pts @ np.array([[c, s], [-s, c]]) + pose[:2]


def ours(name: str, cell: float, **options: Any) -> peer_lib.Peer:
    """An NdtGrid matcher as a peer."""

    def prepare(target: np.ndarray) -> ndtgrid.NdtGrid:
        grid = ndtgrid.NdtGrid(cell, levels=6)
        grid.insert(target, np.zeros(3))
        grid.match(target[:1], np.zeros(3), **options)  # build distributions once
        return grid

    def align(grid: ndtgrid.NdtGrid, pts: np.ndarray, guess: np.ndarray) -> np.ndarray:
        return grid.match(pts, guess, **options).pose

    return peer_lib.Peer(name, prepare, align)


def methods() -> list[peer_lib.Peer]:
    """Our settings and the peers."""
    out = [
        ours("NDT 2 cm original (k=1)", 0.02, **ORIGINAL_NDT),
        ours("NDT 20 cm original (k=1)", 0.2, **ORIGINAL_NDT),
        ours("2 cm + expansion k=10 only", 0.02, **{**ORIGINAL_NDT, "expansion": 10.0}),
        ours("2 cm + neighbour search only", 0.02, **{**ORIGINAL_NDT, "neighbor_search": True}),
        ours("2 cm + fusion only", 0.02, **{**ORIGINAL_NDT, "fuse_minority": True}),
        ours("2 cm paper (all three fixes)", 0.02, **PAPER),
        ours(
            "2 cm paper, phased k = 100, 10, 1", 0.02, **PAPER, expansion_phases=[100.0, 10.0, 1.0]
        ),
        ours("2 cm paper + pyramid (2–64 cm)", 0.02, **{**PAPER, "levels": None}),
        ours(
            "  + rotational multi-start ±0.15 rad",
            0.02,
            **{**PAPER, "levels": None, "rotation_search": 0.15},
        ),
        ours("  + frozen unconstrained directions, r=1, σ floor 2 cm", 0.02, shape_cell=0.0),
        ours("  + fine cells shaped by their 32 cm ancestor = default match()", 0.02),
        ours("default + 3×3 pairing", 0.02, pair_neighbors=True),
        ours("16 cm grid, default match() (not 2 cm)", 0.16),
    ]
    return out + peer_lib.all_peers()


def starts(rng: np.random.Generator, n: int, trans: float, rot_deg: float) -> np.ndarray:
    """(n, 3) perturbations, uniform in ±trans, ±rot."""
    return np.c_[rng.uniform(-trans, trans, (n, 2)), np.radians(rng.uniform(-rot_deg, rot_deg, n))]


def run(
    pairs: list[Pair], ms: list[peer_lib.Peer], perturb: Callable[[int], np.ndarray], title: str
) -> None:
    """Print one table: success, median error, median time per method; with pairs
    from several offset sets, a second table of success per set."""
    print(f"\n### {title}\n")
    subsets = sorted({p.subset for p in pairs}, key=float) if pairs[0].subset else []
    per_set: list[str] = []
    print("| method | success | median error [cm / °] | median time [ms] |")
    print("|---|---|---|---|")
    deltas = [perturb(i) for i in range(len(pairs))]
    for m in ms:
        ok, errs, times = 0, [], []
        by_set = dict.fromkeys(subsets, 0)
        for pair, delta in zip(pairs, deltas):
            state = m.prepare(pair.target)
            for d in delta:
                t0 = time.perf_counter()
                pose = m.align(state, pair.source, pair.truth + d)
                times.append(time.perf_counter() - t0)
                et, er = pose_error(pose, pair.truth)
                errs.append((et, er))
                hit = et < pair.tol[0] and er < pair.tol[1]
                ok += hit
                if subsets:
                    by_set[pair.subset] += hit
        e = np.array(errs)
        print(
            f"| {m.name} | {100 * ok / len(e):.0f} % ({ok}/{len(e)}) | "
            f"{100 * np.median(e[:, 0]):.1f} / "
            f"{np.degrees(np.median(e[:, 1])):.2f} | {1e3 * np.median(times):.2f} |",
            flush=True,
        )
        starts_per_set = len(e) // max(len(subsets), 1)
        per_set.append(
            f"| {m.name} | " + " | ".join(f"{by_set[k]}/{starts_per_set}" for k in subsets) + " |"
        )
    if len(subsets) > 1:
        print(f"\nSuccess per offset set ({title}):\n")
        print("| method | " + " | ".join(f"offset {k}" for k in subsets) + " |")
        print("|---|" + "---|" * len(subsets))
        print("\n".join(per_set), flush=True)


def main() -> None:
    """Run the study."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=12, help="pairs per real log")
    ap.add_argument("--starts", type=int, default=10, help="starts per pair and set")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--sim-pairs", type=int, default=8, help="pairs per simulated laser")
    ap.add_argument("--urg-pairs", type=int, default=40, help="candidate pairs of the URG log")
    ap.add_argument(
        "--offset",
        type=float,
        nargs="+",
        default=[0.0],
        help="real pairs this far (0-1) between the default ones (0.5: the held-out set); "
        "several offsets pool their pairs",
    )
    args = ap.parse_args()
    ms = methods()
    sets = [
        (
            "Real pairs"
            if args.offset == [0.0]
            else f"Real pairs at offsets {', '.join(f'{o:g}' for o in args.offset)}",
            [p for o in args.offset for p in real_pairs(args.pairs, o)],
        ),
        ("Real URG-04LX pairs (peer-consensus reference)", list(urg_pairs(args.urg_pairs))),
        ("Simulated pairs", list(sim_pairs(args.sim_pairs, args.seed))),
    ]
    for title, pairs in sets:
        if not pairs:
            continue
        groups = sorted({p.group for p in pairs})
        print(f"\n{title}: {len(pairs)} pairs ({', '.join(groups)}), {args.starts} starts each")
        rng = np.random.default_rng(args.seed)
        wide = [starts(rng, args.starts, 0.4, 10.0) for _ in pairs]
        local = [starts(rng, args.starts, 0.05, 2.0) for _ in pairs]
        run(pairs, ms, lambda i, s=local: s[i], f"{title}, local starts (±5 cm, ±2°)")
        run(pairs, ms, lambda i, s=wide: s[i], f"{title}, wide starts (±0.4 m, ±10°)")


if __name__ == "__main__":
    main()
