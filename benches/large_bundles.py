"""Two Python threads against one on large scans: bundles of consecutive Intel scans
merged into one scan, of any size.

``benches/speed.py``'s thread section times our matcher on bundles of 20 scans (about
3600 points) as its GIL-free control. This script times bundles of any number of scans,
so that scans past the matcher's bound on kept pairs (``KEPT_MAX_POINTS``, 4096 points;
a larger scan is streamed through a kept block of 256 points) are measured too, with
what tells a memory cause from a compute one: the process's CPU time and system time,
and the TLB shootdowns of the run (``benches/shootdowns.py``), which a thread giving its
working memory back to the kernel at each call would drive up (benches/SPEED_LOG.md,
sessions 68 and 69).

A case is a map of the first ``map`` of the 910 corrected Intel scans and bundles of
``size`` consecutive scans of that map (:func:`speed.bundle_scans`: each merged in the
frame of its middle scan, from a start ±5 cm, ±2° off), repeated to ``matches`` matches a
run. A round times one thread matching them all, then two threads started for the round
matching every other one each. A turn runs ``rounds`` rounds of every case, one case after
the other; ``turns`` turns, so that a spell of the machine falls on every case, and the
table gives each turn's medians side by side.

Run from the repository root (needs ``pip install -e ".[bench]"`` and
``../shared/data/real``; about a minute with the defaults on 2 shared cores)::

    python benches/large_bundles.py > out/large_bundles.md
    python benches/large_bundles.py --sizes 20 80 --maps 910 --turns 1
"""

from __future__ import annotations

import argparse
import functools
import os
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

sys.path.insert(0, str(Path(__file__).resolve().parent))

import datasets
import shootdowns
import speed

import ndtgrid

F64 = npt.NDArray[np.float64]
Job = tuple[F64, F64]


@dataclass(frozen=True)
class Run:
    """One timed run of a case's matches.

    Attributes
    ----------
    wall : float
        Seconds from the first match's start to the last one's end.
    cpu : float
        This process's CPU time (user and system, every thread's) over the run, in
        seconds (:func:`time.process_time`).
    system : float
        Its system time alone, in seconds (:func:`os.times`, in clock ticks: 10 ms at
        100 ticks a second).
    shootdowns : int or None
        TLB shootdowns over the run, every CPU's, or ``None`` where they cannot be read.
    """

    wall: float
    cpu: float
    system: float
    shootdowns: int | None


@dataclass(frozen=True)
class Turn:
    """The medians of one turn's rounds of a case.

    Attributes
    ----------
    ratio : float
        One thread's wall time over two threads'.
    cost : float
        Two threads' CPU time over one thread's.
    system : float
        System seconds in a two-thread run.
    shootdowns_two, shootdowns_one : float or None
        TLB shootdowns in a two-thread and a one-thread run, ``None`` where unread.
    """

    ratio: float
    cost: float
    system: float
    shootdowns_two: float | None
    shootdowns_one: float | None


def cases(sizes: Sequence[int], maps: Sequence[int], scans: int) -> list[tuple[int, int]]:
    """The ``(size, map)`` cases, bundle size first, leaving out maps smaller than a bundle.

    Raises
    ------
    ValueError
        If a size or map is below 1, a map holds more than ``scans`` scans, or no map
        holds a whole bundle.
    """
    if any(s < 1 for s in sizes) or any(m < 1 for m in maps):
        raise ValueError("bundle sizes and maps must be at least 1 scan")
    if any(m > scans for m in maps):
        raise ValueError(f"a map holds at most the log's {scans} scans")
    out = [(s, m) for s in sizes for m in maps if m >= s]
    if not out:
        raise ValueError("no map holds a whole bundle: make a map at least as large as a bundle")
    return out


def repeated(jobs: Sequence[Job], count: int) -> list[Job]:
    """``jobs`` over and over, ``count`` of them."""
    return [jobs[i % len(jobs)] for i in range(count)]


def match_all(grid: ndtgrid.NdtGrid, jobs: Sequence[Job]) -> None:
    """Match every ``(points, start)`` of ``jobs`` against ``grid``."""
    for points, start in jobs:
        grid.match(points, start)


def two_threads(grid: ndtgrid.NdtGrid, jobs: Sequence[Job]) -> None:
    """Match ``jobs`` on two threads started here, every other job each, and re-raise
    the first error either thread met."""
    errors: list[BaseException] = []

    def half(part: Sequence[Job]) -> None:
        try:
            match_all(grid, part)
        except BaseException as e:  # handed to the caller below
            errors.append(e)

    threads = [threading.Thread(target=half, args=(part,)) for part in (jobs[0::2], jobs[1::2])]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if errors:
        raise errors[0]


def time_run(work: Callable[[], None]) -> Run:
    """``work()`` timed: wall, CPU and system time, and TLB shootdowns."""
    before = shootdowns.shootdowns()
    s0, c0, t0 = os.times().system, time.process_time(), time.perf_counter()
    work()
    wall, cpu, s1 = time.perf_counter() - t0, time.process_time() - c0, os.times().system
    after = shootdowns.shootdowns()
    return Run(
        wall=wall,
        cpu=cpu,
        system=s1 - s0,
        shootdowns=None if before is None or after is None else after - before,
    )


def summarise(rounds: Sequence[tuple[Run, Run]]) -> Turn:
    """The medians of a turn's rounds, each ``(one thread's run, two threads' run)``.

    Raises
    ------
    ValueError
        If there is no round, or a run took no time.
    """
    if not rounds:
        raise ValueError("a turn needs at least one round")
    if any(r.wall <= 0.0 or r.cpu <= 0.0 for pair in rounds for r in pair):
        raise ValueError("a run took no wall or CPU time: give it more matches")

    def counts(runs: list[Run]) -> float | None:
        seen = [r.shootdowns for r in runs]
        return None if None in seen else float(np.median([s for s in seen if s is not None]))

    ones, twos = [one for one, _ in rounds], [two for _, two in rounds]
    return Turn(
        ratio=float(np.median([a.wall / b.wall for a, b in rounds])),
        cost=float(np.median([b.cpu / a.cpu for a, b in rounds])),
        system=float(np.median([b.system for b in twos])),
        shootdowns_two=counts(twos),
        shootdowns_one=counts(ones),
    )


def row(size: int, scans: int, points: float, turns: Sequence[Turn]) -> str:
    """One case's Markdown row: each turn's medians, in turn order."""

    def each(values: Sequence[float | None], fmt: str) -> str:
        return ", ".join("–" if v is None else format(v, fmt) for v in values)

    return (
        f"| map of {scans} scans, bundles of {size} scans (about {points:.0f} points) "
        f"| {each([t.ratio for t in turns], '.2f')}× "
        f"| {each([t.cost for t in turns], '.2f')} "
        f"| {each([t.system for t in turns], '.3f')} "
        f"| {each([t.shootdowns_two for t in turns], '.0f')} "
        f"| {each([t.shootdowns_one for t in turns], '.0f')} |"
    )


HEADER = (
    "| case | ratio, two threads over one | CPU time over one thread's "
    "| system s a two-thread run | TLB shootdowns a two-thread run | a one-thread run |",
    "|---|---|---|---|---|---|",
)


def parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    """The command line."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sizes", type=int, nargs="+", default=[20, 40, 80], help="scans a bundle")
    p.add_argument("--maps", type=int, nargs="+", default=[60, 910], help="scans a map")
    p.add_argument("--turns", type=int, default=3, help="turns over every case")
    p.add_argument("--rounds", type=int, default=4, help="rounds of a case a turn")
    p.add_argument("--matches", type=int, default=360, help="matches a run")
    p.add_argument("--seed", type=int, default=3, help="seed of the starts")
    args = p.parse_args(argv)
    for name in ("turns", "rounds", "matches"):
        if getattr(args, name) < 1:
            p.error(f"--{name} must be at least 1")
    return args


def main(argv: Sequence[str] | None = None) -> None:
    """Time every case, turn after turn, and print the table."""
    args = parse_args(argv)
    if not speed.INTEL_CORRECTED.is_file():
        raise SystemExit(f"large_bundles.py: no Intel log at {speed.INTEL_CORRECTED}")
    pts, poses = speed.intel_corrected()
    try:
        todo = cases(args.sizes, args.maps, len(pts))
    except ValueError as e:
        raise SystemExit(f"large_bundles.py: {e}") from None
    grids: dict[int, ndtgrid.NdtGrid] = {}
    for m in sorted({m for _, m in todo}):
        grids[m] = ndtgrid.NdtGrid(speed.CELL)
        for p, q in zip(pts[:m], poses[:m]):
            grids[m].insert(p, q)
    jobs: dict[tuple[int, int], list[Job]] = {}
    points: dict[tuple[int, int], float] = {}
    for size, m in todo:
        rng = np.random.default_rng([args.seed, size, m])
        bundles = speed.bundle_scans(pts[:m], poses[:m], size, rng)
        points[size, m] = float(np.mean([len(p) for p, _ in bundles]))
        jobs[size, m] = repeated(bundles, args.matches)
        grids[m].match(*jobs[size, m][0])  # build the distributions
    results: dict[tuple[int, int], list[Turn]] = {case: [] for case in todo}
    for _, (size, m) in speed.progress(
        [(t, case) for t in range(args.turns) for case in todo], "turns", args.turns * len(todo)
    ):
        grid, case_jobs = grids[m], jobs[size, m]
        rounds = []
        for _ in range(args.rounds):
            with speed.no_gc():
                one = time_run(functools.partial(match_all, grid, case_jobs))
                two = time_run(functools.partial(two_threads, grid, case_jobs))
            rounds.append((one, two))
        results[size, m].append(summarise(rounds))
    speed.out(f"Machine: {datasets.machine() + datasets.dirty()}\n")
    speed.out(
        f"{args.matches} matches a run, {args.rounds} rounds a case a turn, {args.turns} "
        "turns; each turn's medians in turn order.\n"
    )
    speed.out(HEADER)
    for size, m in todo:
        speed.out(row(size, m, points[size, m], results[size, m]))


if __name__ == "__main__":
    main()
