"""Pictures of ``benches/speed.py``: the match-time sweeps, the thread runs, and this
library against its peers (match, map update, odometry) in one run; and, for
``benches/speed_runs.py``, each target's numbers over many runs.

matplotlib is imported lazily; without it each ``plot_*`` returns ``None`` and draws
nothing (``speed.py`` says so in its output).
"""

from __future__ import annotations

import math
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import targets as tg


def pyplot() -> Any:
    """``matplotlib.pyplot`` with the Agg backend, or ``None`` when matplotlib is absent."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    return plt


def save_figure(fig: Any, title: str, path: Path) -> Path:
    """Titles, lays out, writes (creating the directory) and closes ``fig``; returns the
    file's resolved path."""
    import matplotlib.pyplot as plt

    fig.suptitle(title)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path.resolve()


def plot_sweeps(res: dict[str, Any], path: Path) -> Path | None:
    """The two sweeps as a PNG; its path, or ``None`` without matplotlib."""
    plt = pyplot()
    if plt is None:
        return None
    rows, slope, icpt, r2 = res["points"]
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    x = np.array([r["points"] for r in rows])
    a.plot(x, [1e3 * r["median"] for r in rows], "o", label="median of the matches")
    xs = np.linspace(0, x.max() * 1.05, 50)
    a.plot(xs, 1e3 * (slope * xs + icpt), "-", label=f"linear fit (R² = {r2:.3f})")
    a.set_xlabel("valid scan points")
    a.set_ylabel("time per match [ms]")
    a.set_title("Scan points (one 2 cm map, simulated URG-04LX)")
    a.set_xlim(left=0)
    a.set_ylim(bottom=0)
    a.legend()
    for kind, marker, label in (
        ("recent", "o-", "map of the last k Intel scans"),
        ("padded", "s-", "30 scans + far copies of the log"),
    ):
        sub = [r for r in res["map"] if r["kind"] == kind]
        if sub:
            b.plot([r["cells"] for r in sub], [1e3 * r["median"] for r in sub], marker, label=label)
    b.set_xscale("log")
    b.set_xlabel("occupied 2 cm cells in the map")
    b.set_ylabel("time per match [ms]")
    b.set_title("Map size (same Intel scans)")
    b.set_ylim(bottom=0)
    b.legend()
    return save_figure(
        fig, "ndtgrid default match() on a 2 cm grid, one thread (benches/speed.py)", path
    )


def plot_threads(
    runs: dict[str, list[float]], path: Path, late_start: float | None = None
) -> Path | None:
    """The thread section's runs as a PNG (skipped without matplotlib): each run's
    ratio (one thread's time over two threads' right after it) for the unpinned threads
    (ringed where both were on one vCPU at their first matches, dotted where they were
    half-way through; ``nan`` elsewhere in those two lists) and the pinned ones,
    ``match_many``, threads that keep matching (``steady``: two threads' rate over one's,
    per round) and the two GIL-free controls; when the later thread began, with a
    line at ``late_start`` (s), where the section splits its runs into late and not.
    Its path, or ``None`` without matplotlib."""
    plt = pyplot()
    if plt is None:
        return None
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.8))
    ring = {"color": "k", "mfc": "none", "ms": 11, "mew": 1.2}  # keeps the colour cycle
    for key, marker, label, style in (
        ("unpinned", "o", "two threads started per run", {}),
        ("unpinned_first_one_cpu", "o", "… on one vCPU at their first matches", ring),
        ("unpinned_one_cpu", "k.", "… on one vCPU half-way through", {}),
        ("pinned", "s", "two pinned workers", {}),
        ("sha", "x", "control: SHA-256 (GIL released)", {}),
        ("bundles", "+", "control: 20-scan bundles", {}),
        ("many", "D", "match_many, every core / one thread", {}),
        ("steady", "^", "two threads that keep matching (rounds)", {}),
    ):
        ys = runs.get(key, [])
        if ys:
            a.plot(np.arange(1, len(ys) + 1), ys, marker, label=label, alpha=0.85, **style)
    a.axhline(tg.THREADS_RATIO, color="k", lw=0.8, ls="--", label=f"target {tg.THREADS_TEXT}")
    a.axhline(2.0, color="0.6", lw=0.8)
    a.set_xlabel("run (one- and two-thread runs alternate)")
    a.set_ylabel("one thread's time / two threads' time")
    a.set_title("Speed-up per run")
    a.xaxis.get_major_locator().set_params(integer=True)
    a.legend(fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    for key, marker, label in (
        ("late_unpinned", "o", "started per run (after the clock)"),
        ("late_pinned", "s", "pinned (after the first worker)"),
    ):
        ys = runs.get(key, [])
        if ys:
            b.plot(np.arange(1, len(ys) + 1), 1e3 * np.maximum(ys, 1e-6), marker, label=label)
    b.axhline(4.0, color="k", lw=0.8, ls="--", label="scheduler tick (HZ = 250)")
    if late_start is not None:
        b.axhline(
            1e3 * late_start, color="0.5", lw=0.8, ls=":", label="late start (speed.py's split)"
        )
    b.set_yscale("log")
    b.set_xlabel("run")
    b.set_ylabel("later thread's first match began [ms]")
    b.set_title("Late starts")
    b.xaxis.get_major_locator().set_params(integer=True)
    b.legend(fontsize=7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    return save_figure(
        fig,
        "Matching different scans on two cores against one 2 cm map (benches/speed.py)",
        path,
    )


# The libraries of speed.py's rows, by the start of a row's name, and their colours.
LIBRARIES = (
    ("ndtgrid", "tab:blue"),
    ("small_gicp", "tab:orange"),
    ("Open3D", "tab:green"),
    ("KISS-ICP", "tab:red"),
)
# speed.py's match case sets, in its order, with the names the picture gives them.
MATCH_SETS = (
    ("sick", "real SICK pairs"),
    ("urg_pairs", "real URG-04LX pairs"),
    ("urg_map", "real URG-04LX\nscan to map"),
    ("sim_map", "simulated URG-04LX\nscan to map"),
)


@dataclass(frozen=True)
class Bar:
    """One row of a ``speed.py`` table as the peers' picture draws it.

    ``group``: the case set (match, map update) or ``""`` (odometry); ``method``: the
    row's name without Markdown; ``seconds``: the median time (odometry: the whole
    run); ``extra``: the map update with the peer's preprocessing of the scan (``nan``
    where there is none); ``note``: the match's success rate or the odometry's relation
    error.
    """

    group: str
    method: str
    seconds: float
    extra: float = math.nan
    note: str = ""

    @property
    def library(self) -> str:
        """One of :data:`LIBRARIES`, by the start of the method's name (or ``"other"``)."""
        return library_of(self.method)


def library_of(name: str) -> str:
    """The library a ``speed.py`` row's name starts with (``"other"`` if none)."""
    return next((lib for lib, _ in LIBRARIES if name.startswith(lib)), "other")


def plain(name: str) -> str:
    """A row's name without Markdown code marks."""
    return name.replace("`", "")


def peer_bars(res: dict[str, dict[str, Any]]) -> dict[str, list[Bar]]:
    """The rows of ``speed.py``'s match, map update and odometry sections (its results
    ``res``, by section) as bars: ``{"match": …, "insert": …, "odometry": …}``, each in
    the tables' order; a section that did not run gives an empty list."""
    match = [
        Bar(title, plain(name), median, note=f"{100 * success:.0f} %")
        for key, title in MATCH_SETS
        for name, median, success in res.get("match", {}).get(key, {}).get("methods", [])
    ]
    insert = [
        Bar(re.sub(r" \(.*\)$", "", title), plain(name), median, extra)
        for title, rows in res.get("insert", {}).items()
        for name, median, extra in rows.get("methods", [])
    ]
    odometry = [
        Bar("", plain(name), seconds, note=f"{error:.3f} m")
        for name, seconds, error in res.get("odometry", {}).get("methods", [])
    ]
    return {"match": match, "insert": insert, "odometry": odometry}


def _colours(bars: list[Bar]) -> dict[str, Any]:
    """A colour per method: its library's hue, lighter for each further method of it."""
    from matplotlib.colors import to_rgb

    hue = dict(LIBRARIES)
    seen: dict[str, int] = {}
    out: dict[str, Any] = {}
    for b in bars:
        if b.method in out:
            continue
        k = seen.get(b.library, 0)
        seen[b.library] = k + 1
        base = np.array(to_rgb(hue.get(b.library, "tab:gray")))
        out[b.method] = tuple(base + (1 - base) * min(0.22 * k, 0.66))
    return out


def _number(v: float) -> str:
    """Three significant digits, without an exponent from 100 up."""
    return f"{v:.0f}" if v >= 100 else f"{v:.3g}"


def _grouped(ax: Any, bars: list[Bar], scale: float, unit: str) -> None:
    """Vertical bars per group (log scale), one per method, labelled with their value
    (times ``scale``, in ``unit``) and note; a method's preprocessing, where it has one,
    as a hatched bar behind, labelled with the sum."""
    groups = list(dict.fromkeys(b.group for b in bars))
    methods = list(dict.fromkeys(b.method for b in bars))
    colour = _colours(bars)
    width = 0.84 / len(methods)
    heights: list[float] = []

    def label(x: float, y: float, text: str) -> None:
        ax.annotate(
            text,
            (x, y),
            xytext=(0, 2),
            textcoords="offset points",
            ha="center",
            va="bottom",
            fontsize=6,
        )

    by_key = {(b.group, b.method): b for b in bars}
    for i, g in enumerate(groups):
        for j, m in enumerate(methods):
            b = by_key.get((g, m))
            if b is None or not math.isfinite(b.seconds):
                continue
            x = i - 0.42 + width * (j + 0.5)
            y = b.seconds * scale
            if math.isfinite(b.extra):
                total = b.extra * scale
                ax.bar(x, total, width, color="none", edgecolor=colour[m], hatch="///")
                label(x, total, _number(total))
                heights.append(total)
            ax.bar(x, y, width, color=colour[m], label=m if i == 0 else None)
            label(x, y, _number(y) + (f"\n{b.note}" if b.note else ""))
            heights.append(y)
    ax.set_yscale("log")
    if heights:
        ax.set_ylim(min(heights) / 4, max(heights) * 12)
    ax.set_xticks(range(len(groups)), groups)
    ax.set_ylabel(f"median [{unit}], log scale")


def plot_peers(res: dict[str, dict[str, Any]], path: Path, machine: str) -> Path | None:
    """ndtgrid against its peers in one ``speed.py`` run (results ``res``, by section) as
    a PNG: each method's median match per case set with its success rate, each map's
    median update of one scan (hatched: with the peer's preprocessing of the scan), and
    each loop's time over the Intel log with its relation error. Its path, or ``None``
    without matplotlib or when none of the three sections ran."""
    bars = peer_bars(res)
    plt = pyplot()
    if plt is None or not any(bars.values()):
        return None
    import textwrap

    fig = plt.figure(figsize=(13, 10))
    grid = fig.add_gridspec(2, 2, height_ratios=(1.15, 1))
    a = fig.add_subplot(grid[0, :])
    b = fig.add_subplot(grid[1, 0])
    c = fig.add_subplot(grid[1, 1])
    if bars["match"]:
        _grouped(a, bars["match"], 1e3, "ms")
        a.set_title("Match: time per scan from the same local starts (label: median, success)")
        a.legend(fontsize=7, ncol=3, loc="upper left")
    if bars["insert"]:
        _grouped(b, bars["insert"], 1e6, "µs")
        b.set_title("Map update: one scan into a map of many (hatched: + preprocessing)")
        b.legend(fontsize=6, loc="upper left")
    odo = bars["odometry"]
    if odo:
        colour = _colours(odo)
        y = np.arange(len(odo))[::-1]
        c.barh(y, [r.seconds for r in odo], color=[colour[r.method] for r in odo])
        c.set_yticks(y, [textwrap.fill(r.method, 38) for r in odo], fontsize=6)
        for yi, r in zip(y, odo):
            c.annotate(
                f" {r.seconds:.2f} s, {r.note}",
                (r.seconds, yi),
                va="center",
                fontsize=7,
            )
        c.set_xlabel("whole run [s] (label: time, mean relation error)")
        c.set_title("Odometry over the Intel log")
        c.margins(x=0.3)
    for ax, key in ((a, "match"), (b, "insert"), (c, "odometry")):
        if not bars[key]:
            ax.set_axis_off()
            ax.text(0.5, 0.5, f"section {key} not run", ha="center", transform=ax.transAxes)
    return save_figure(
        fig,
        "ndtgrid and its peers in one run of benches/speed.py, one thread each unless "
        f"named\n{machine}",
        path,
    )


@dataclass(frozen=True)
class RunSeries:
    """One judged number over many runs: its legend's label, its value in each run and
    whether the value met its limit (both ``None`` where the run did not measure or
    judge it)."""

    label: str
    values: tuple[float | None, ...]
    met: tuple[bool | None, ...]

    def legend(self) -> str:
        """The label with the count of runs that met the limit, of those judged."""
        judged = [m for m in self.met if m is not None]
        return f"{self.label} ({sum(judged)} of {len(judged)})"


@dataclass(frozen=True)
class TargetPanel:
    """One target's picture over many runs: its title, its limit and its numbers."""

    title: str
    limit: float
    series: tuple[RunSeries, ...]


def _run_by_run(
    ax: Any, names: Sequence[str], values: Any, miss: Any, label: str, ringed: str | None = None
) -> None:
    """``values`` (one per run, in the order of ``names``) as a line on ``ax``, the runs
    flagged in ``miss`` ringed in red (``ringed``: the rings' legend label), the runs'
    names on the x axis (about a dozen of them)."""
    x = np.arange(len(names))
    ax.plot(x, values, "o-", ms=3.5, lw=0.8, label=label)
    ax.plot(x[miss], values[miss], "o", ms=9, mfc="none", mec="red", mew=1.3, label=ringed)
    step = max(1, math.ceil(len(names) / 12))
    ax.set_xticks(x[::step], list(names[::step]), fontsize=7)
    ax.tick_params(axis="y", labelsize=7)
    ax.set_xlabel("run", fontsize=8)


def plot_runs(
    names: Sequence[str], panels: Sequence[TargetPanel], title: str, path: Path
) -> Path | None:
    """Each target's numbers run by run as a PNG, a panel per target: the limit dashed,
    each miss ringed in red, each series' count of runs that met the limit in its
    label. ``names`` are the runs' names, in order. Its path, or ``None`` without
    matplotlib."""
    plt = pyplot()
    if plt is None:
        return None
    cols = 2
    rows = max(1, math.ceil(len(panels) / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(12, 3.3 * rows + 0.6), squeeze=False)
    for ax, panel in zip(axes.flat, panels):
        for s in panel.series:
            v = np.array([np.nan if y is None else y for y in s.values], dtype=float)
            miss = np.array([m is False for m in s.met], dtype=bool)
            _run_by_run(ax, names, v, miss, s.legend())
        ax.axhline(panel.limit, color="k", lw=0.8, ls="--")
        ax.set_title(panel.title, fontsize=9)
        ax.legend(fontsize=7, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.2))
    for ax in axes.flat[len(panels) :]:
        ax.set_visible(False)
    return save_figure(fig, title, path)


@dataclass(frozen=True)
class PaceRun:
    """One run's thread rounds for the pace picture: its name, each round's two-thread
    ratio (one thread's time over two threads') of the GIL-free bundles and of the two
    pinned workers, timed one after the other in the round, and whether the run's pinned
    workers missed their target (by the run's own ratio)."""

    name: str
    bundles: tuple[float, ...]
    pinned: tuple[float, ...]
    missed: bool

    def median_quotient(self) -> float:
        """The median over the rounds of the pinned workers' ratio over the bundles'."""
        return float(np.median(np.divide(self.pinned, self.bundles)))


def plot_pace(runs: Sequence[PaceRun], limit: float, title: str, path: Path) -> Path | None:
    """The pinned workers against the GIL-free bundles as a PNG, in two panels: each
    round's pinned ratio against the same round's bundles' (the rounds of the runs whose
    pinned workers missed in red, the limit dashed on both axes, equal pace dotted); and
    run by run the median of the rounds' quotient (the runs whose pinned workers missed
    ringed in red). ``runs`` in order, each with at least one round. Its path, or
    ``None`` without matplotlib."""
    plt = pyplot()
    if plt is None:
        return None
    fig, (rounds, by_run) = plt.subplots(1, 2, figsize=(12, 5.2))
    for missed, colour, what in ((False, "tab:blue", "met"), (True, "red", "missed")):
        these = [r for r in runs if r.missed is missed]
        b = [x for r in these for x in r.bundles]
        p = [y for r in these for y in r.pinned]
        rounds.plot(
            b,
            p,
            "o",
            ms=3,
            alpha=0.4 if missed is False else 0.8,
            color=colour,
            label=f"runs whose pinned workers {what} ({len(these)} runs, {len(b)} rounds)",
        )
    every = [v for r in runs for v in (*r.bundles, *r.pinned)]
    lo, hi = min(every), max(every)
    rounds.plot([lo, hi], [lo, hi], "k:", lw=0.9, label="equal pace")
    rounds.axhline(limit, color="k", lw=0.8, ls="--")
    rounds.axvline(limit, color="k", lw=0.8, ls="--")
    rounds.set_xlabel("GIL-free bundles: one thread's time / two threads'", fontsize=8)
    rounds.set_ylabel("two pinned workers: one worker's time / two workers'", fontsize=8)
    rounds.set_title("each round: the pinned workers against the bundles", fontsize=9)
    rounds.tick_params(labelsize=7)
    rounds.legend(fontsize=7, loc="upper left")
    miss = np.array([r.missed for r in runs], dtype=bool)
    _run_by_run(
        by_run,
        [r.name for r in runs],
        np.array([r.median_quotient() for r in runs]),
        miss,
        "median over the run's rounds",
        f"pinned workers missed ({int(miss.sum())} of {len(runs)})",
    )
    by_run.axhline(1.0, color="k", lw=0.8, ls=":")
    by_run.set_title(
        "run by run: the pinned workers' ratio / the bundles', round by round", fontsize=9
    )
    by_run.legend(fontsize=7, loc="upper left")
    return save_figure(fig, title, path)
