"""The sigma-floor sweep behind ``MatchOptions::sigma_floor`` (BENCHMARK.md, convergence study).

Success of the default 2 cm ``match`` with each floor on the sets of
``benches/convergence.py``: its 960 real SICK pairs (offsets 0, 0.125, ..., 0.875), 960
further pairs between those (offsets 0.0625, 0.1875, ..., 0.9375: the held-out set of
session 3's choice), the URG-04LX pairs (peer-consensus reference) and the simulated
pairs, each with its own starts drawn as that benchmark draws them (``--seed``).

Run: ``python benches/sigma_floor.py [--pairs 30] [--starts 8]``; prints a Markdown table.
"""

from __future__ import annotations

import argparse
import gc
import sys
import time
from collections.abc import Hashable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import convergence as cv

import ndtgrid
from ndtgrid.evaluation import pose_error

FLOORS = (0.005, 0.01, 0.015, 0.02, 0.025, 0.03)
BENCH_OFFSETS = tuple(k / 8 for k in range(8))
HELD_OUT_OFFSETS = tuple(k / 8 + 1 / 16 for k in range(8))


def successes(pairs: list[cv.Pair], starts: list[np.ndarray], **options: Any) -> int:
    """Starts that end within their pair's tolerance, matched with ``options``."""
    ok = 0
    for pair, deltas in zip(pairs, starts):
        grid = ndtgrid.NdtGrid(0.02, levels=6)
        grid.insert(pair.target, np.zeros(3))
        for d in deltas:
            pose = grid.match(pair.source, pair.truth + d, **options).pose
            et, er = pose_error(pose, pair.truth)
            ok += et < pair.tol[0] and er < pair.tol[1]
    return ok


def urg_medians(
    variants: dict[Hashable, dict[str, Any]], seed: int, min_points: int = 500
) -> dict[Hashable, float]:
    """Median match time [s] per variant (its ``match`` options) over the real URG-04LX
    log's scans of at least ``min_points`` points: the cases of ``speed.urg_log_maps``
    (the maps and starts of ``benches/speed.py``), every variant on the same cases, each
    scan's matches in an order turned by one variant from scan to scan."""
    import speed

    names = list(variants)
    times: dict[Hashable, list[float]] = {v: [] for v in names}
    for k, (grid, points, guess) in enumerate(speed.urg_log_maps(seed, min_points=min_points)):
        for i in range(len(names)):
            v = names[(i + k) % len(names)]
            gc.disable()
            t0 = time.perf_counter()
            grid.match(points, guess, **variants[v])
            times[v].append(time.perf_counter() - t0)
            gc.enable()
    return {v: float(np.median(t)) for v, t in times.items()}


def success(pairs: list[cv.Pair], starts: list[np.ndarray], floor: float) -> float:
    """Percentage of starts that end within the pair's tolerance."""
    ok = successes(pairs, starts, sigma_floor=floor)
    return 100.0 * ok / max(1, sum(len(s) for s in starts))


Sets = dict[str, list[cv.Pair]]
Starts = dict[str, tuple[list[np.ndarray], list[np.ndarray]]]


def success_sets(pairs: int, starts: int, seed: int) -> tuple[Sets, Starts]:
    """The four sets (``pairs`` per real log and offset) and their local and wide starts
    (``starts`` per pair, drawn per set as ``benches/convergence.py`` draws them)."""
    sets = {
        "SICK pairs": [p for o in BENCH_OFFSETS for p in cv.real_pairs(pairs, o)],
        "held-out SICK pairs": [p for o in HELD_OUT_OFFSETS for p in cv.real_pairs(pairs, o)],
        "URG-04LX pairs": list(cv.urg_pairs(40)),
        "simulated pairs": list(cv.sim_pairs(8, seed)),
    }
    drawn = {}
    for name, set_pairs in sets.items():
        rng = np.random.default_rng(seed)  # as convergence.py draws them
        wide = [cv.starts(rng, starts, 0.4, 10.0) for _ in set_pairs]
        local = [cv.starts(rng, starts, 0.05, 2.0) for _ in set_pairs]
        drawn[name] = (local, wide)
    return {n: p for n, p in sets.items() if p}, drawn


def parse_with_sets(ap: argparse.ArgumentParser) -> tuple[argparse.Namespace, Sets, Starts]:
    """``ap``'s arguments plus ``--pairs``, ``--starts`` and ``--seed``, parsed, and the
    :func:`success_sets` they select."""
    ap.add_argument("--pairs", type=int, default=30, help="pairs per real log and offset")
    ap.add_argument("--starts", type=int, default=8, help="starts per pair and set")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    sets, starts = success_sets(args.pairs, args.starts, args.seed)
    return args, sets, starts


def main() -> None:
    """Run the sweep."""
    _, sets, starts = parse_with_sets(argparse.ArgumentParser(description=__doc__.splitlines()[0]))
    names = list(sets)
    print("| σ floor | " + " | ".join(f"{n} ({len(sets[n])})" for n in names) + " |")
    print("|---|" + "---|" * len(names))
    for floor in FLOORS:
        cells = []
        for n in names:
            local, wide = starts[n]
            cells.append(
                f"{success(sets[n], local, floor):.1f} / {success(sets[n], wide, floor):.1f} %"
            )
        print(f"| {1e3 * floor:.0f} mm | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
