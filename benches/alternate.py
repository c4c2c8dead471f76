"""Alternate two commands and compare a number they print: A/B timing on a noisy VM.

Each pair runs both commands once, the order flipped from pair to pair, so that a drift
of the machine's speed falls on both alike. The first ``--number`` is compared: per pair
``b / a - 1``, then the median, the mean with two standard errors and the number of
pairs in which B was lower; any further numbers are reported as medians. This is how
benches/SPEED_LOG.md's sessions compare builds (session 27 ran the same method from
shell scripts).

Run, e.g. two builds of the ``replay`` example, or two builds of the extension in
``speed.py``'s Intel child (context switches from ``perf stat``)::

    python benches/alternate.py --pairs 20 --number 'scans ([0-9.]+) s' \\
        -- './replay_a intel.bin odometry 1' './replay_b intel.bin odometry 1'

    CHILD='perf stat -x, -e context-switches python benches/speed.py --intel-child \\
        --intel-scans 13631 --out /tmp/p.npy'
    python benches/alternate.py --pairs 12 --number '"seconds": ([0-9.]+)' \\
        --number '([0-9]+),,context-switches' \\
        -- "cp a.so python/ndtgrid/_core.abi3.so && $CHILD" \\
           "cp b.so python/ndtgrid/_core.abi3.so && $CHILD"
"""

from __future__ import annotations

import argparse
import math
import re
import statistics
import subprocess
from dataclasses import dataclass


@dataclass(frozen=True)
class Comparison:
    """B against A over the pairs.

    Attributes
    ----------
    pairs : int
        Pairs run.
    median : float
        Median of ``b / a - 1`` over the pairs.
    mean : float
        Mean of ``b / a - 1``.
    two_se : float
        Two standard errors of that mean (0 with one pair).
    lower : int
        Pairs in which B's number was below A's.
    """

    pairs: int
    median: float
    mean: float
    two_se: float
    lower: int


def compare(a: list[float], b: list[float]) -> Comparison:
    """Compare paired numbers ``a[i]``, ``b[i]``.

    Parameters
    ----------
    a, b : list of float
        The two commands' numbers, pair by pair (same length, A's all positive).

    Returns
    -------
    Comparison
        Median and mean of ``b / a - 1``, two standard errors, pairs with B lower.

    Raises
    ------
    ValueError
        If the lengths differ, there is no pair, or an A number is not positive.
    """
    if len(a) != len(b) or not a:
        raise ValueError(f"expected paired numbers, got {len(a)} and {len(b)}")
    if any(x <= 0.0 for x in a):
        raise ValueError("A's numbers must be positive")
    ratios = [y / x - 1.0 for x, y in zip(a, b)]
    two_se = 2.0 * statistics.stdev(ratios) / math.sqrt(len(ratios)) if len(ratios) > 1 else 0.0
    return Comparison(
        pairs=len(ratios),
        median=statistics.median(ratios),
        mean=statistics.fmean(ratios),
        two_se=two_se,
        lower=sum(y < x for x, y in zip(a, b)),
    )


def run(command: str, patterns: list[re.Pattern[str]]) -> list[float]:
    """Run ``command`` in a shell and read numbers from its output.

    Parameters
    ----------
    command : str
        A shell command line.
    patterns : list of re.Pattern
        Searched in its standard output and error, in that order.

    Returns
    -------
    list of float
        The first group of each pattern's first match.

    Raises
    ------
    RuntimeError
        If the command fails or a pattern does not match its output.
    """
    done = subprocess.run(command, shell=True, capture_output=True, text=True, check=False)
    text = done.stdout + done.stderr
    if done.returncode != 0:
        raise RuntimeError(f"{command!r} exited with {done.returncode}:\n{text[-2000:]}")
    found = []
    for p in patterns:
        m = p.search(text)
        if m is None:
            raise RuntimeError(f"{p.pattern!r} not found in the output of {command!r}")
        found.append(float(m.group(1)))
    return found


def main() -> None:
    """Run the pairs and print the comparison."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=16)
    parser.add_argument(
        "--number",
        action="append",
        required=True,
        help="regular expression whose first group is a number (repeatable; the first is compared)",
    )
    parser.add_argument("a", help="command A (a shell command line)")
    parser.add_argument("b", help="command B")
    args = parser.parse_args()
    if args.pairs < 1:
        parser.error("--pairs: expected at least 1")
    patterns = [re.compile(p) for p in args.number]
    got: dict[str, list[list[float]]] = {"A": [], "B": []}
    for i in range(args.pairs):
        order = [("A", args.a), ("B", args.b)] if i % 2 == 0 else [("B", args.b), ("A", args.a)]
        for name, command in order:
            try:
                numbers = run(command, patterns)
            except RuntimeError as e:
                parser.exit(1, f"alternate.py: {e}\n")
            got[name].append(numbers)
            print(f"{i + 1} {name} " + " ".join(f"{x:g}" for x in numbers), flush=True)
    c = compare([n[0] for n in got["A"]], [n[0] for n in got["B"]])
    print(
        f"{c.pairs} pairs, B against A: median {100 * c.median:+.1f} %, "
        f"mean {100 * c.mean:+.1f} ± {100 * c.two_se:.1f} %, B lower in {c.lower}"
    )
    for k, p in enumerate(patterns):
        med = [statistics.median(n[k] for n in got[name]) for name in ("A", "B")]
        print(f"  {p.pattern}: medians A {med[0]:g}, B {med[1]:g}")


if __name__ == "__main__":
    main()
