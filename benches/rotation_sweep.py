"""The sweeps behind ``OdometryConfig.coarse_rotation_search`` and ``coarse_rotation_gate``.

The loop's matcher solves from the prediction and, on its coarsest level, from the
prediction turned by ± ``coarse_rotation_search`` (on run centroids first). Those turned
starts are about a sixth of the Intel loop's time, and ``coarse_rotation_gate`` runs them
only for scans whose match without them looks poor (``inf``: on every scan). This runs
``ndtgrid.Odometry`` (defaults, 2 cm) over each benchmark log once per setting and prints
the time of the loop (the mapper read at the end included), the scans whose kept match ran
the multi-start, and the relation error of ``benches/datasets.py``; with ``--no-odometry``
the logs' odometry is dropped (constant-velocity prior only), where the turned starts
matter more. Results are in benches/SPEED_LOG.md, sessions 8-12.

Run from the repository root::

    python benches/rotation_sweep.py                      # five logs, 4 searches, gate off
    python benches/rotation_sweep.py --gates 0.7 0.8 0.9 inf --values 0.15 [--no-odometry]
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from datasets import DATASETS, Run
from odometry_sweep import begin, error_cells, parser
from odometry_sweep import run as run_setting

from ndtgrid.evaluation import RelationSummary

VALUES = (0.15, 0.10, 0.08, 0.05)


def run(name: str, search: float, gate: float, odometry: bool) -> tuple[Run, RelationSummary]:
    """The loop over log ``name`` with these settings, and its relation error."""
    setting = {"coarse_rotation_search": search, "coarse_rotation_gate": gate}
    return run_setting(name, setting, odometry)


def main() -> None:
    """Parse the options, run the sweep, print a Markdown table."""
    ap = parser(__doc__.split("\n")[0])
    ap.add_argument("--values", nargs="+", type=float, default=list(VALUES))
    ap.add_argument("--gates", nargs="+", type=float, default=[math.inf])
    args = ap.parse_args()
    columns = ["log", "search [rad]", "gate", "loop [s]", "multi-starts"]
    begin(args, columns, ["---", "---:", "---:", "---:", "---:"])
    for name in args.datasets:
        for value in args.values:
            for gate in args.gates:
                ours, e = run(name, value, gate, not args.no_odometry)
                print(
                    f"| {DATASETS[name][1]} | {value:g} | {gate:g} | {ours.seconds:.2f} "
                    f"| {ours.multi_starts} of {len(ours.poses)} | {error_cells(e)} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
