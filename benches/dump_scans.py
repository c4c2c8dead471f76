"""Write a log's scans to a flat binary file for the Rust profiling harnesses.

``crates/ndt-core/examples/replay.rs`` reads it: ``odometry`` runs ``Odometry``
over every scan (the loop of ``benches/speed.py`` without Python), ``matchhash``
prints a hash of default matches against a map under inserts and removals (to
check that a change is bit-identical)::

    python benches/dump_scans.py ../shared/data/real/benchmark-scans-split/intel.tar.gz \
        /tmp/intel.bin
    cargo run --release -p ndt-core --example replay -- /tmp/intel.bin odometry 3
    cargo run --release -p ndt-core --example replay -- /tmp/intel.bin matchhash
    perf record -g target/release/examples/replay /tmp/intel.bin odometry 1

Per scan, little-endian: ``int64`` beam count ``B``, ``B`` ranges and ``B`` angles
(``float64``), then the odometry pose ``x, y, theta`` (``float64``; NaN when the
log has none).
"""

from __future__ import annotations

import argparse

import numpy as np

from ndtgrid.io import read_log


def main() -> int:
    """Parse the arguments and write the dump; prints the number of scans."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("log", help="any log ndtgrid.io.read_log reads")
    ap.add_argument("out", help="the binary file to write")
    args = ap.parse_args()
    n = 0
    with open(args.out, "wb") as f:
        for s in read_log(args.log):
            np.array([len(s.ranges)], dtype="<i8").tofile(f)
            np.asarray(s.ranges, dtype="<f8").tofile(f)
            np.asarray(s.angles, dtype="<f8").tofile(f)
            odom = np.full(3, np.nan) if s.odom is None else np.asarray(s.odom, dtype="<f8")
            odom.astype("<f8").tofile(f)
            n += 1
    print(n)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
