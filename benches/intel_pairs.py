"""Accuracy on 50 consecutive corrected scan pairs of the Intel log.

Map: the earlier scan alone, inserted at its corrected pose. Guess: that pose
composed with the raw odometry increment. Reference: the later scan's corrected
pose (GMapping, good to a few cm). Success: error < 5 cm and < 1 deg.

Run: ``python benches/intel_pairs.py [--pairs 50]``
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import ndtgrid
from ndtgrid.evaluation import corrected_pairs, pose_error
from ndtgrid.io import read_benchmark_index, read_carmen
from ndtgrid.presets import ORIGINAL_NDT, PAPER

REAL = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "real"

SETTINGS = {
    "2 cm, default match() (2–64 cm pyramid, rotation multi-start, frozen degenerate directions)": (
        0.02,
        {},
    ),
    "2 cm, paper (k=10, neighbours, fusion)": (0.02, PAPER),
    "2 cm, original NDT (k=1)": (0.02, ORIGINAL_NDT),
    "20 cm, paper": (0.2, PAPER),
    "20 cm, original NDT (k=1)": (0.2, ORIGINAL_NDT),
}


def main() -> None:
    """Print the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=50)
    args = parser.parse_args()
    scans = list(read_carmen(REAL / "radish-gfs-corrected/intel-corrected.log.gz"))
    index = read_benchmark_index(REAL / "benchmark-scans-split/intel__intel-corrected__index.csv")
    pairs = list(corrected_pairs(scans, index, max_range=40.0))[: args.pairs]
    guess = np.array([pose_error(p.guess, p.true_pose) for p in pairs])
    print(f"{len(pairs)} Intel pairs")
    print("| setting | success (5 cm / 1°) | median error [cm] | median error [°] | ms / match |")
    print("|---|---|---|---|---|")

    def row(name: str, err: np.ndarray, ms: str) -> None:
        ok = np.sum((err[:, 0] < 0.05) & (err[:, 1] < np.radians(1.0)))
        print(
            f"| {name} | {ok}/{len(err)} | {100 * np.median(err[:, 0]):.1f} | "
            f"{np.degrees(np.median(err[:, 1])):.2f} | {ms} |"
        )

    row("odometry guess", guess, "–")
    for name, (cell, options) in SETTINGS.items():
        errs, times = [], []
        for p in pairs:
            grid = ndtgrid.NdtGrid(cell)
            grid.insert(p.reference_points, p.reference_pose)
            grid.match(p.points, p.guess, **options)  # builds the distributions once
            t0 = time.perf_counter()
            res = grid.match(p.points, p.guess, **options)
            times.append(time.perf_counter() - t0)
            errs.append(pose_error(res.pose, p.true_pose))
        row(name, np.array(errs), f"{1e3 * np.median(times):.3f}")


if __name__ == "__main__":
    main()
