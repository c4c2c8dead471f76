"""Write the scans of ``benches/speed.py``'s insert target to a binary file.

The issue's 50 µs insert is judged on ``speed.py``'s simulated URG-04LX scans
(``sim_urg_scans``); ``crates/ndt-core/examples/insert_case.rs`` replays the same
loop without Python (a map of the first 100 scans, then each next scan matched and
its insert timed), for instruction counts under callgrind::

    python benches/dump_insert_case.py /tmp/insert_case.bin
    cargo run --release -p ndt-core --example insert_case -- /tmp/insert_case.bin
    valgrind --tool=callgrind --toggle-collect='ndt_core::grid::NdtGrid::insert' \\
        target/release/examples/insert_case /tmp/insert_case.bin

Per scan, little-endian: ``int64`` point count ``N``, ``N`` scan-frame points
``x, y`` (``float64``), then the pose ``x, y, theta`` (``float64``).
"""

from __future__ import annotations

import argparse

import numpy as np
from speed import sim_urg_scans


def main() -> int:
    """Parse the arguments and write the scans; prints how many."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="the binary file to write")
    ap.add_argument("--scans", type=int, default=400, help="scans to write (default 400)")
    ap.add_argument("--seed", type=int, default=0, help="speed.py's --seed (default 0)")
    args = ap.parse_args()
    pts, poses = sim_urg_scans(10_000, args.seed)
    n = min(args.scans, len(pts))
    with open(args.out, "wb") as f:
        for p, q in zip(pts[:n], poses[:n]):
            p = np.ascontiguousarray(p, dtype="<f8")
            np.array([len(p)], dtype="<i8").tofile(f)
            p.tofile(f)
            np.asarray(q, dtype="<f8").tofile(f)
    print(n)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
