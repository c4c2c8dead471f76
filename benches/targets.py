"""Issue 7's speed targets: the one place their limits, and which cases they judge, are
written.

``speed.py`` judges one run against them, ``speed_runs.py`` many runs' JSON and
``criterion_table.py`` the cases criterion times; ``speed_plots.py`` draws the threads'
line. Times are in seconds.
"""

from __future__ import annotations

# Median match of a 683-point scan on a 2 cm map, one core: at most this.
MATCH_S = 2e-4
# Insert of a 683-point scan into a 2 cm map: at most this ...
INSERT_S = 50e-6
# ... judged on scans of at least this many points (a median) only.
INSERT_MIN_POINTS = 500
# Our match, and our odometry, at least this many times faster than the fastest peer's.
PEER_RATIO = 3.0
# The whole Intel log through `Odometry`: at most this ...
INTEL_S = 3.0
# ... judged only on the whole log, this many scans.
INTEL_SCANS = 13631
# Time per match linear in scan points: a straight line's R² at least this.
LINEAR_R2 = 0.95
# Time per match flat in map size: the largest map's median over the smallest's at most this.
FLAT_GROWTH = 1.2
# Two threads matching different scans: at least this many times one thread's throughput.
THREADS_RATIO = 1.7

# The limits as the tables and labels write them (one source with the numbers above).
MATCH_TEXT = f"{MATCH_S * 1e3:g} ms"
INSERT_TEXT = f"{INSERT_S * 1e6:g} µs"
PEER_TEXT = f"{PEER_RATIO:g}×"
INTEL_TEXT = f"{INTEL_S:g} s"
THREADS_TEXT = f"{THREADS_RATIO:g}×"


def insert_judged(points: float) -> bool:
    """Whether an insert case of ``points`` points (its median scan) is judged against
    ``INSERT_S``: the target is for a 683-beam scan, not for sparse ones."""
    return points >= INSERT_MIN_POINTS


def intel_judged(scans: int) -> bool:
    """Whether an odometry run over ``scans`` scans is judged against ``INTEL_S``: only the
    whole Intel log is."""
    return scans >= INTEL_SCANS
