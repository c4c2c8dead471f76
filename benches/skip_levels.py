"""The sweep behind the default ``skip_levels`` of ``NdtGrid.match`` (BENCHMARK.md, "Speed").

For each set of skipped pyramid levels this prints the successes of the 2 cm ``match``
on the sets of ``benches/sigma_floor.py`` (960 real SICK pairs, 960 held-out SICK pairs,
the URG-04LX pairs with their peer-consensus reference, the simulated pairs; local and
wide starts drawn as ``benches/convergence.py`` draws them), and the median time of the
scan-to-map match of ``benches/speed.py`` over the real URG-04LX log for scans of at
least 500 points, every variant on the same cases.

Run from the repository root::

    python benches/skip_levels.py                   # (), (1,), (2,), (1, 3)
    python benches/skip_levels.py --pairs 10
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from sigma_floor import parse_with_sets, successes, urg_medians

# Skipped levels (1 = 4 cm, 2 = 8 cm, 3 = 16 cm on 2 cm cells); () matches every level.
VARIANTS: tuple[tuple[int, ...], ...] = ((), (1,), (2,), (1, 3))


def main() -> None:
    """Run the sweep, print a Markdown table."""
    args, sets, starts = parse_with_sets(
        argparse.ArgumentParser(description=__doc__.splitlines()[0])
    )
    names = list(sets)
    medians = urg_medians({v: {"skip_levels": v} for v in VARIANTS}, args.seed + 4)
    print(
        "Successes from local / wide starts (of "
        + ", ".join(f"{n} {len(sets[n]) * args.starts}" for n in names)
        + "); median match of URG-04LX scans of >= 500 points.\n"
    )
    print("| skip_levels | " + " | ".join(names) + " | URG ≥ 500 points [ms] |")
    print("|---|" + "---|" * len(names) + "---:|")
    for v in VARIANTS:
        cells = [
            f"{successes(sets[n], starts[n][0], skip_levels=v)} / "
            f"{successes(sets[n], starts[n][1], skip_levels=v)}"
            for n in names
        ]
        print(f"| {v} | " + " | ".join(cells) + f" | {1e3 * medians[v]:.3f} |", flush=True)


if __name__ == "__main__":
    main()
