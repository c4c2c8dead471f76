"""The sweep behind the default ``skip_levels`` of ``NdtGrid.match``.

Results are in benches/SPEED_LOG.md, sessions 18 and 43.

For each variant (skipped pyramid levels, and the default's level count against 5 levels)
this prints the successes of the 2 cm ``match`` on the sets of ``benches/sigma_floor.py``
(960 real SICK pairs, 960 held-out SICK pairs, the URG-04LX pairs with their
peer-consensus reference, the simulated pairs; local and wide starts drawn as
``benches/convergence.py`` draws them) and the median time of the scan-to-map match of
``benches/speed.py`` over the real URG-04LX log for scans of at least 500 points, every
variant on the same cases; then the successes from wider starts (4 per pair, up to
±1.2 m and ±30°) on the SICK and simulated pairs, where the coarse levels set the basin.

Run from the repository root::

    python benches/skip_levels.py
    python benches/skip_levels.py --pairs 10
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import convergence as cv
from sigma_floor import parse_with_sets, successes, urg_medians

# `match` options per variant: skipped levels (1 = 4 cm, 2 = 8 cm, 3 = 16 cm on 2 cm
# cells; () matches every level), and the default skip with 5 levels (2-32 cm).
VARIANTS: dict[str, dict[str, Any]] = {
    "()": {"skip_levels": ()},
    "(1,) (default)": {},
    "(2,)": {"skip_levels": (2,)},
    "(1, 3)": {"skip_levels": (1, 3)},
    "(1,), levels=5": {"levels": 5},
}
# Wider starts: half-widths [m, degrees], 4 starts per pair.
WIDER = ((0.6, 15.0), (0.8, 20.0), (1.2, 30.0))


def main() -> None:
    """Run the sweep, print two Markdown tables."""
    args, sets, starts = parse_with_sets(
        argparse.ArgumentParser(description=__doc__.splitlines()[0])
    )
    names = list(sets)
    medians = urg_medians(VARIANTS, args.seed + 4)
    print(
        "Successes from local / wide starts (of "
        + ", ".join(f"{n} {len(sets[n]) * args.starts}" for n in names)
        + "); median match of URG-04LX scans of >= 500 points.\n"
    )
    print("| skip_levels | " + " | ".join(names) + " | URG ≥ 500 points [ms] |")
    print("|---|" + "---|" * len(names) + "---:|")
    for v, options in VARIANTS.items():
        cells = [
            f"{successes(sets[n], starts[n][0], **options)} / "
            f"{successes(sets[n], starts[n][1], **options)}"
            for n in names
        ]
        print(f"| {v} | " + " | ".join(cells) + f" | {1e3 * medians[v]:.3f} |", flush=True)
    wider = [n for n in ("SICK pairs", "simulated pairs") if n in sets]
    cols = [f"{n} ±{r:g} m, ±{a:g}°" for n in wider for r, a in WIDER]
    counts = [4 * len(sets[n]) for n in wider for _ in WIDER]
    print(f"\nSuccesses from wider starts (4 per pair, of {', '.join(map(str, counts))}).\n")
    print("| skip_levels | " + " | ".join(cols) + " |")
    print("|---|" + "---:|" * len(cols))
    for v, options in VARIANTS.items():
        cells = []
        for n in wider:
            for r, a in WIDER:
                rng = np.random.default_rng(args.seed + 1)
                drawn = [cv.starts(rng, 4, r, a) for _ in sets[n]]
                cells.append(str(successes(sets[n], drawn, **options)))
        print(f"| {v} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
