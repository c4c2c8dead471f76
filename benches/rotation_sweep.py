"""The sweep behind ``OdometryConfig.coarse_rotation_search`` (BENCHMARK.md, "Speed").

The loop's matcher solves from the prediction and, on its coarsest level, from the
prediction turned by ± this angle (on run centroids first). The turned starts are about a
sixth of the Intel loop's time. This runs ``ndtgrid.Odometry`` (defaults, 2 cm) over each
benchmark log once per value and prints the time of the loop (the mapper read at the end
included) and the relation error of ``benches/datasets.py``, so the speed a smaller
search would buy can be weighed against what it costs in accuracy.

Run from the repository root::

    python benches/rotation_sweep.py                             # five logs, 4 values
    python benches/rotation_sweep.py --datasets intel --values 0.15 0
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from datasets import DATA, DATASETS, machine, run_ndtgrid

import ndtgrid
from ndtgrid.evaluation import RelationSummary, relation_errors
from ndtgrid.io import read_benchmark_index, read_benchmark_split

VALUES = (0.15, 0.10, 0.08, 0.05)


def run(name: str, value: float) -> tuple[float, RelationSummary]:
    """Seconds of the loop over log ``name`` with the search at ``value``, and its error."""
    stem = DATASETS[name][0]
    scans = list(read_benchmark_split(DATA / f"{name}.tar.gz"))
    index = read_benchmark_index(DATA / f"{stem}__index.csv")
    ours = run_ndtgrid(scans, ndtgrid.OdometryConfig(coarse_rotation_search=value))
    return ours.seconds, relation_errors(ours.poses[index.raw_scan], index.corrected).summary()


def main() -> None:
    """Parse the options, run the sweep, print a Markdown table."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--datasets", nargs="+", default=list(DATASETS), choices=list(DATASETS))
    ap.add_argument("--values", nargs="+", type=float, default=list(VALUES))
    args = ap.parse_args()
    if not DATA.is_dir():
        sys.exit(f"no benchmark logs at {DATA} (../shared/data/real beside the project)")
    print(f"Machine: {machine()}\n")
    print("| log | search [rad] | loop [s] | translation [m] | rotation [deg] |")
    print("|---|---:|---:|---|---|")
    for name in args.datasets:
        for value in args.values:
            seconds, e = run(name, value)
            print(
                f"| {DATASETS[name][1]} | {value:g} | {seconds:.2f} "
                f"| {e.translation_mean:.3f} ± {e.translation_std:.3f} (max "
                f"{e.translation_max:.3f}) | {e.rotation_mean:.2f} ± {e.rotation_std:.2f} "
                f"(max {e.rotation_max:.2f}) |",
                flush=True,
            )


if __name__ == "__main__":
    main()
