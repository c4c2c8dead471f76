"""The sweep behind ``MatchOptions::rotation_gate`` (benches/SPEED_LOG.md, sessions 9 and 11).

Over several pyramid levels the matcher's rotational multi-start runs only when the first
stage's solve from the guess scores below the gate per scan point. For each gate this
prints the successes of the default 2 cm ``match`` on the sets of
``benches/sigma_floor.py`` (960 real SICK pairs, 960 held-out SICK pairs, the URG-04LX
pairs with their peer-consensus reference, the simulated pairs; local and wide starts drawn
as ``benches/convergence.py`` draws them), and the median time of the scan-to-map match of
``benches/speed.py`` over the real URG-04LX log for scans of at least 500 points (the
issue's 0.2 ms target: its scans, maps and starts, ``speed.urg_log_maps``), every gate on
the same cases (in an order turned by one gate from scan to scan).

Run from the repository root::

    python benches/rotation_gate.py                 # gates inf, 0.95, 0.9, 0.85, 0.8
    python benches/rotation_gate.py --gates inf 0.9 --pairs 10
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from sigma_floor import parse_with_sets, successes, urg_medians

GATES = (float("inf"), 0.95, 0.9, 0.85, 0.8)
MIN_POINTS = 500  # the dense URG-04LX scans


def main() -> None:
    """Run the sweep, print a Markdown table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gates", nargs="+", type=float, default=list(GATES))
    args, sets, starts = parse_with_sets(ap)
    names = list(sets)
    medians = urg_medians({g: {"rotation_gate": g} for g in args.gates}, args.seed + 4, MIN_POINTS)
    print(
        "Successes from local / wide starts (of "
        + ", ".join(f"{n} {len(sets[n]) * args.starts}" for n in names)
        + f"); median match of URG-04LX scans of >= {MIN_POINTS} points.\n"
    )
    print("| gate | " + " | ".join(names) + f" | URG ≥ {MIN_POINTS} points [ms] |")
    print("|---:|" + "---|" * len(names) + "---:|")
    for gate in args.gates:
        cells = [
            f"{successes(sets[n], starts[n][0], rotation_gate=gate)} / "
            f"{successes(sets[n], starts[n][1], rotation_gate=gate)}"
            for n in names
        ]
        row = f"| {gate:g} | " + " | ".join(cells) + f" | {1e3 * medians[gate]:.3f} |"
        print(row, flush=True)


if __name__ == "__main__":
    main()
