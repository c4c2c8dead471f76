"""Many ``benches/speed.py --json`` runs as BENCHMARK.md's per-run tables:
``python benches/speed_runs.py RUN.json [RUN.json ...]``.

Each run is a column, named by the first number in its file's name (``run539.json``:
539), else by the name, in the order of those numbers (``run999.json`` before
``run1000.json``, whatever order the shell's ``run*.json`` gave); each of issue 7's
targets is a row (``benches/targets.py`` holds the limits, the judging is
``speed.py``'s), with how many runs met it. A number that misses its target is in bold,
with one more digit when it rounds onto the limit (a ratio of 1.695 is no 1.70). Tables
of at most ``--columns`` runs; then, over all the runs, each row's range and count, and
the runs that met every target. A section a run did not time reads as a dash and is not
judged; such a run did not meet every target.
Runs that kept their thread rounds' CPU times (``speed.py`` since session 68) also
get a table of the GIL-free bundles' and the pinned workers' rounds under the threads'
limit and the others: the CPU time over the wall time, over one thread's, and the time
stolen from the VM's vCPUs. ``--plot PATH`` also draws each target's numbers run by
run, ``--plot-pace PATH`` the two pinned workers' ratio against the GIL-free bundles'
round by round (matplotlib).

Run from the repository root, e.g.::

    python benches/speed.py --json /tmp/run1.json   # as many times as wanted
    python benches/speed_runs.py /tmp/run*.json --plot /tmp/runs.png
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

import speed_plots
import targets as tg

Sections = dict[str, Any]


@dataclass(frozen=True)
class Part:
    """One number of a cell: ``value`` printed with ``digits`` decimals (``None``: not
    measured), judged against ``limit`` (``None``: not judged), which it must reach
    (``at_least``) or not exceed; a judged number is drawn as the series ``label`` in
    the picture ``panel``."""

    value: float | None
    digits: int
    limit: float | None = None
    at_least: bool = False
    label: str = ""
    panel: str = ""

    def met(self) -> bool | None:
        """Whether the number meets its limit; ``None`` where either is missing."""
        if self.value is None or self.limit is None:
            return None
        return self.value >= self.limit if self.at_least else self.value <= self.limit

    def text(self) -> str:
        """The number as printed (bold when it misses)."""
        if self.value is None:
            return "–"
        s = f"{self.value:.{self.digits}f}"
        if self.met() is False:
            if self.limit is not None and float(s) == self.limit:
                s = f"{self.value:.{self.digits + 1}f}"
            return f"**{s}**"
        return s


@dataclass(frozen=True)
class Cell:
    """A row's numbers for one run, ``{}`` in ``template`` standing for each part."""

    template: str
    parts: tuple[Part, ...]

    def met(self) -> bool | None:
        """Whether every judged part meets its limit; ``None`` when none is judged."""
        verdicts = [v for v in (p.met() for p in self.parts) if v is not None]
        return all(verdicts) if verdicts else None

    def text(self) -> str:
        """The cell as printed."""
        return self.template.format(*(p.text() for p in self.parts))


@dataclass(frozen=True)
class Row:
    """A row of the tables: a short ``key`` for code that looks a row up, its name,
    whether it is a target (else it only informs), and its cell for a run's sections
    (``None``: the run did not time it)."""

    key: str
    name: str
    target: bool
    cell: Callable[[Sections], Cell | None]


def _get(d: Any, *keys: str | int) -> Any:
    """``d[k0][k1]…``, or ``None`` where a key is missing or a value is null."""
    for k in keys:
        if isinstance(d, dict):
            d = d.get(k)
        elif isinstance(d, list) and isinstance(k, int) and -len(d) <= k < len(d):
            d = d[k]
        else:
            return None
        if d is None:
            return None
    return d


def _scaled(v: Any, scale: float) -> float | None:
    return None if v is None else float(v) * scale


def _ratio(num: Any, den: Any) -> float | None:
    return None if num is None or den is None else float(num) / float(den)


def _match(s: Sections) -> Cell | None:
    m = s.get("match")
    if not m:
        return None
    limit = tg.MATCH_S * 1e3
    times = (
        (_get(m, "sim_map", "ours"), "simulated URG-04LX"),
        (_get(m, "urg_map", "ours"), "real URG-04LX"),
        (_get(m, "urg_log", "≥ 500", 0), "real URG-04LX, ≥ 500 points"),
    )
    panel = f"median match ≤ {tg.MATCH_TEXT} [ms]"
    return Cell(
        "{} / {} / {}",
        tuple(Part(_scaled(t, 1e3), 3, limit, label=k, panel=panel) for t, k in times),
    )


PEER_CASES = {
    "sick": "real SICK pairs",
    "urg_pairs": "real URG pairs",
    "urg_map": "real URG map",
    "sim_map": "simulated map",
}


def _peers(s: Sections) -> Cell | None:
    m = s.get("match")
    if not m:
        return None
    panel = f"match: the fastest peer's time / ours ≥ {tg.PEER_TEXT}"
    return Cell(
        "{} / {} / {} / {}×",
        tuple(
            Part(
                _ratio(_get(m, k, "fastest", 1), _get(m, k, "ours")),
                2,
                tg.PEER_RATIO,
                True,
                label,
                panel,
            )
            for k, label in PEER_CASES.items()
        ),
    )


def _insert(s: Sections) -> Cell | None:
    judged = {
        k: v for k, v in (s.get("insert") or {}).items() if tg.insert_judged(v.get("points", 0))
    }
    if not judged:
        return None
    panel = f"insert of a scan of ≥ {tg.INSERT_MIN_POINTS} points ≤ {tg.INSERT_TEXT} [µs]"
    parts = tuple(
        Part(_scaled(v.get("ours"), 1e6), 1, tg.INSERT_S * 1e6, label=k, panel=panel)
        for k, v in judged.items()
    )
    return Cell(" / ".join("{}" for _ in parts), parts)


def _intel(s: Sections) -> Cell | None:
    o = s.get("odometry")
    if not o:
        return None
    full = tg.intel_judged(o.get("scans", 0))
    return Cell(
        "{} ({})",
        (
            Part(
                o.get("ours"),
                2,
                tg.INTEL_S if full else None,
                label="ndtgrid.Odometry",
                panel=f"the Intel log ({tg.INTEL_SCANS} scans) ≤ {tg.INTEL_TEXT} [s]",
            ),
            Part(o.get("ours_one_thread"), 2),
        ),
    )


def _odometry_peer(s: Sections) -> Cell | None:
    o = s.get("odometry")
    if not o or _get(o, "fastest") is None:
        return None
    panel = f"odometry: the fastest peer's time / ours ≥ {tg.PEER_TEXT}"
    parts = [
        Part(
            _ratio(_get(o, "fastest", 1), o.get("ours")),
            2,
            tg.PEER_RATIO,
            True,
            "the fastest peer",
            panel,
        ),
        Part(_get(o, "fastest", 1), 2),
    ]
    template = "{}× ({})"
    if _get(o, "fastest_good") is not None and o["fastest_good"] != o["fastest"]:
        parts.append(
            Part(
                _ratio(_get(o, "fastest_good", 1), o.get("ours")),
                2,
                tg.PEER_RATIO,
                True,
                "the fastest peer at ≤ our error",
                panel,
            )
        )
        template += "; {}× at ≤ our error"
    return Cell(template, tuple(parts))


def _no_map(s: Sections) -> Cell | None:
    o = s.get("odometry")
    if not o or o.get("ours_poses_only") is None:
        return None
    bare = o["ours_poses_only"]
    return Cell("{} ({}×)", (Part(bare, 2), Part(_ratio(_get(o, "fastest", 1), bare), 2)))


def _growth(s: Sections, kind: str) -> float | None:
    sub = _get(s, "sweeps", kind, 3)
    if not sub:
        return None
    return _ratio(_get(sub, -1, "median"), _get(sub, 0, "median"))


def _sweeps(s: Sections) -> Cell | None:
    if not s.get("sweeps"):
        return None
    flat = f"match time, largest map / smallest ≤ {tg.FLAT_GROWTH:g}"
    return Cell(
        "{} / {} / {}",
        (
            Part(
                _get(s, "sweeps", "points", 3),
                3,
                tg.LINEAR_R2,
                True,
                "R² of a line through time against points",
                f"match time linear in scan points: R² ≥ {tg.LINEAR_R2:g}",
            ),
            Part(_growth(s, "map_padded"), 2, tg.FLAT_GROWTH, label="padded maps", panel=flat),
            Part(_growth(s, "map_recent"), 2, tg.FLAT_GROWTH, label="recent maps", panel=flat),
        ),
    )


THREADS_PANEL = f"two threads' throughput / one thread's ≥ {tg.THREADS_TEXT}"


def _threads(s: Sections) -> Cell | None:
    t = s.get("threads")
    if not t:
        return None
    return Cell(
        "{}× ({}; {})",
        (
            Part(t.get("ratio"), 2, tg.THREADS_RATIO, True, "started for each run", THREADS_PANEL),
            Part(t.get("control"), 2),
            Part(t.get("bundle_ratio"), 2),
        ),
    )


def _thread_ratio(key: str, label: str) -> Callable[[Sections], Cell | None]:
    def cell(s: Sections) -> Cell | None:
        v = _get(s, "threads", key)
        if v is None:
            return None
        return Cell("{}×", (Part(v, 2, tg.THREADS_RATIO, True, label, THREADS_PANEL),))

    return cell


def _placement(s: Sections) -> Cell | None:
    t = s.get("threads")
    if not t or t.get("cpu_read_runs") is None:
        return None
    keys = ("one_cpu_first_runs", "one_cpu_runs", "late_runs")
    parts = (*(Part(t.get(k), 0) for k in keys), Part(len(t.get("late_s") or ()), 0))
    return Cell("{} / {}; {} of {}", parts)


def _memory(s: Sections) -> Cell | None:
    per_cell = _get(s, "memory", "bytes_per_cell")
    rss = _get(s, "odometry", "vmhwm_mib")
    if per_cell is None and rss is None:
        return None
    return Cell("{} B/cell, {} MiB", (Part(per_cell, 0), Part(rss, 1)))


ROWS = (
    Row("match", "match sim / URG / URG ≥ 500 [ms]", True, _match),
    Row(
        "peers",
        f"≥ {tg.PEER_TEXT} fastest peer (SICK / URG pairs / URG map / sim map)",
        True,
        _peers,
    ),
    Row("insert", f"insert ≤ {tg.INSERT_TEXT}", True, _insert),
    Row("intel", f"Intel ≤ {tg.INTEL_TEXT} (one thread)", True, _intel),
    Row("odometry_peer", f"≥ {tg.PEER_TEXT} fastest peer odometry (its s)", True, _odometry_peer),
    Row("no_map", "no map [s] (× fastest peer)", False, _no_map),
    Row("sweeps", "linear (R²) / flat (padded / recent maps)", True, _sweeps),
    Row(
        "threads",
        f"two threads ≥ {tg.THREADS_TEXT}, started for each run (SHA-256; bundles)",
        True,
        _threads,
    ),
    Row(
        "steady",
        f"two threads ≥ {tg.THREADS_TEXT}, keep matching",
        True,
        _thread_ratio("steady_ratio", "keep matching"),
    ),
    Row(
        "pinned",
        f"two pinned workers ≥ {tg.THREADS_TEXT}",
        True,
        _thread_ratio("pinned_ratio", "pinned workers"),
    ),
    Row(
        "many",
        f"one `match_many` call ≥ {tg.THREADS_TEXT}",
        True,
        _thread_ratio("many_ratio", "one match_many call"),
    ),
    Row(
        "placement",
        "unpinned: on one vCPU at the first match / half-way; second thread ≥ 1 ms late (runs)",
        False,
        _placement,
    ),
    Row("memory", "memory", False, _memory),
)
# Each row's place in ROWS, by its key (Run.cell).
ROW_INDEX = {row.key: i for i, row in enumerate(ROWS)}


@dataclass(frozen=True)
class Run:
    """One ``speed.py --json`` document: its column's name, machine and sections."""

    name: str
    machine: str
    sections: Sections

    @cached_property
    def cells(self) -> tuple[Cell | None, ...]:
        """Its cell in each of ``ROWS``, worked out once for the tables, the summary and
        the picture (``None`` where the run did not time the row)."""
        return tuple(row.cell(self.sections) for row in ROWS)

    def cell(self, key: str) -> Cell | None:
        """Its cell in the row of ``ROWS`` whose key is ``key``."""
        return self.cells[ROW_INDEX[key]]


def read_run(path: Path, partial: bool = False) -> Run:
    """The run in ``path``.

    Raises
    ------
    ValueError
        The file cannot be read, is not JSON, is not a ``speed.py --json`` document,
        or holds a run that stopped part-way (unless ``partial``); the message names
        the file.
    """
    try:
        doc = json.loads(path.read_text())
    except OSError as e:
        raise ValueError(f"{path}: {e.strerror}") from e
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not JSON ({e.msg}, line {e.lineno})") from e
    if not isinstance(doc, dict) or not isinstance(doc.get("sections"), dict):
        raise ValueError(f'{path}: not a `speed.py --json` document (no "sections")')
    if doc.get("complete") is not True and not partial:
        raise ValueError(f"{path}: the run stopped part-way; --partial tables what it measured")
    number = _number_in(path)
    return Run(
        path.stem if number is None else number, str(doc.get("machine", "?")), doc["sections"]
    )


def _number_in(path: Path) -> str | None:
    """The first number in ``path``'s file name, which names its run (``None``: none)."""
    number = re.search(r"\d+", path.stem)
    return None if number is None else number.group()


def in_run_order(paths: Sequence[Path]) -> list[Path]:
    """``paths`` ordered by the first number in each file's name, as the runs' columns
    are named (a shell's ``run*.json`` puts ``run1000.json`` before ``run999.json``);
    names without a number follow, in the order given."""

    def key(path: Path) -> tuple[int, int]:
        number = _number_in(path)
        return (1, 0) if number is None else (0, int(number))

    return sorted(paths, key=key)


def met_every_target(cells: Sequence[Cell | None]) -> bool:
    """Whether a run's cells meet every target row (a row not timed is no pass)."""
    return all(c is not None and c.met() is True for c, r in zip(cells, ROWS) if r.target)


def _tally(row: Row, cells: Sequence[Cell | None]) -> tuple[int, int] | None:
    """How many of ``cells`` met ``row``, of how many were judged (``None``: none was,
    or the row only informs)."""
    if not row.target:
        return None
    judged = [v for v in (c.met() for c in cells if c is not None) if v is not None]
    return (sum(judged), len(judged)) if judged else None


def _count(tally: tuple[int, int] | None) -> str:
    return "–" if tally is None else f"{tally[0]} of {tally[1]}"


def run_tables(runs: Sequence[Run], columns: int) -> list[str]:
    """The per-run tables, ``columns`` runs at most in each."""
    lines: list[str] = []
    for start in range(0, len(runs), columns):
        group = runs[start : start + columns]
        cells = [r.cells for r in group]
        if lines:
            lines.append("")
        lines.append("| target | " + " | ".join(r.name for r in group) + " | met |")
        lines.append("|---|" + "---|" * (len(group) + 1))
        for i, row in enumerate(ROWS):
            col = [c[i] for c in cells]
            shown = " | ".join("–" if c is None else c.text() for c in col)
            lines.append(f"| {row.name} | {shown} | {_count(_tally(row, col))} |")
    return lines


def _span(parts: Sequence[Part]) -> str:
    values = [p.value for p in parts if p.value is not None]
    if not values:
        return "–"
    d = parts[0].digits
    lo, hi = f"{min(values):.{d}f}", f"{max(values):.{d}f}"
    return lo if lo == hi else f"{lo}–{hi}"


@dataclass(frozen=True)
class Total:
    """A row over many runs: each part's range as printed (a dash where no run measured
    it), the whole cell as the summary prints it, and how many runs met the row of how
    many were judged (``None`` for a row that only informs, or that no run timed)."""

    row: Row
    spans: tuple[str, ...]
    text: str
    count: tuple[int, int] | None


def totals(runs: Sequence[Run]) -> list[Total]:
    """Each row's range and count over ``runs``, in the order of ``ROWS``."""
    cells = [r.cells for r in runs]
    out = []
    for i, row in enumerate(ROWS):
        col = [c[i] for c in cells]
        shaped = [c for c in col if c is not None]
        # Runs whose cell has another shape (another number of insert cases) are
        # left out of the ranges, not of the count.
        same = [c for c in shaped if c.template == shaped[0].template] if shaped else []
        spans = (
            tuple(_span([c.parts[k] for c in same]) for k in range(len(same[0].parts)))
            if same
            else ()
        )
        text = same[0].template.format(*spans) if same else "–"
        out.append(Total(row, spans, text, _tally(row, col)))
    return out


def summary(runs: Sequence[Run]) -> list[str]:
    """Each row's range and count over ``runs``, and the runs that met every target."""
    lines = [
        f"| target | {len(runs)} runs | met |",
        "|---|---|---|",
        *(f"| {t.row.name} | {t.text} | {_count(t.count)} |" for t in totals(runs)),
    ]
    every = [r.name for r in runs if met_every_target(r.cells)]
    lines += [
        "",
        f"Every target met in {len(every)} of {len(runs)} runs"
        + (f": {', '.join(every)}." if every else "."),
    ]
    return lines


def target_panels(runs: Sequence[Run]) -> list[speed_plots.TargetPanel]:
    """The judged numbers of ``runs`` as pictures: a panel per ``Part.panel``, a series
    per label, a value and its verdict (``Part.met``) per run; panels and series in the
    order of the rows and their parts."""
    found: dict[str, tuple[float, dict[str, list[Part | None]]]] = {}
    cells = [run.cells for run in runs]
    for j, row in enumerate(ROWS):
        for i in range(len(runs)):
            cell = cells[i][j]
            if not row.target or cell is None:
                continue
            for p in cell.parts:
                if p.limit is None or not p.panel:
                    continue
                series = found.setdefault(p.panel, (p.limit, {}))[1]
                series.setdefault(p.label, [None] * len(runs))[i] = p
    return [
        speed_plots.TargetPanel(
            title,
            limit,
            tuple(
                speed_plots.RunSeries(
                    label,
                    tuple(None if p is None else p.value for p in parts),
                    tuple(None if p is None else p.met() for p in parts),
                )
                for label, parts in s.items()
            ),
        )
        for title, (limit, s) in found.items()
    ]


def pace_runs(runs: Sequence[Run]) -> list[speed_plots.PaceRun]:
    """The thread rounds of ``runs`` for ``speed_plots.plot_pace``: each round's ratio of
    the GIL-free bundles and of the pinned workers (``speed.py``'s ``per_run``), and
    whether the run's pinned workers missed their row; in the order of ``runs``, leaving
    out a run that did not keep both round by round."""
    found = []
    for run in runs:
        per_run = _get(run.sections, "threads", "per_run") or {}
        pairs = list(zip(per_run.get("bundles") or (), per_run.get("pinned") or ()))
        if not pairs:
            continue
        cell = run.cell("pinned")
        found.append(
            speed_plots.PaceRun(
                run.name,
                tuple(float(b) for b, _ in pairs),
                tuple(float(p) for _, p in pairs),
                cell is not None and cell.met() is False,
            )
        )
    return found


@dataclass(frozen=True)
class Shortfall:
    """The two-thread rounds of one kind over the runs that kept their CPU time
    (``speed.py`` since session 68): how many, how many fell under the threads' limit,
    and the medians of the two threads' CPU time over the wall time (``share``) and
    over one thread's for the same work (``cost``) in those (``under``) and in the
    others (``met``); a round's ratio is share / cost, times the one-thread run's wall
    over its CPU, so a round under the limit lost its pace to time not computed or to
    slower computing. ``stolen_s``: the seconds stolen from the VM's vCPUs during the
    rounds (``benches/steal.py``), with the rounds in which any was, or ``None`` where
    not read."""

    kind: str
    rounds: int
    under: int
    share: tuple[float | None, float | None]
    cost: tuple[float | None, float | None]
    stolen_s: tuple[float, int] | None


def _median(xs: Sequence[float]) -> float | None:
    return statistics.median(xs) if xs else None


def shortfalls(runs: Sequence[Run]) -> list[Shortfall]:
    """The GIL-free bundles' and the pinned workers' rounds of ``runs`` (see
    :class:`Shortfall`), each kind that at least one run kept."""
    found = []
    for kind, name in (("bundles", "GIL-free bundles"), ("pinned", "pinned workers")):
        rows: list[tuple[float, float, float]] = []
        stolen: list[float] = []
        for run in runs:
            threads = _get(run.sections, "threads") or {}
            per_run = threads.get("per_run") or {}
            kept = zip(
                per_run.get(kind) or (),
                per_run.get(f"{kind}_share") or (),
                per_run.get(f"{kind}_cost") or (),
            )
            rows += [(float(r), float(s), float(c)) for r, s, c in kept]
            if kind == "bundles" and per_run.get("bundles_share"):
                stolen += [float(x) for x in threads.get("bundles_steal_s") or () if x is not None]
        if not rows:
            continue
        under = [r for r in rows if r[0] < tg.THREADS_RATIO]
        met = [r for r in rows if r[0] >= tg.THREADS_RATIO]
        found.append(
            Shortfall(
                name,
                len(rows),
                len(under),
                (_median([r[1] for r in under]), _median([r[1] for r in met])),
                (_median([r[2] for r in under]), _median([r[2] for r in met])),
                (sum(stolen), sum(x > 0 for x in stolen)) if stolen else None,
            )
        )
    return found


def shortfall_lines(runs: Sequence[Run]) -> list[str]:
    """:func:`shortfalls` as a table, or nothing where no run kept its CPU times."""
    found = shortfalls(runs)
    if not found:
        return []

    def pair(values: tuple[float | None, float | None]) -> str:
        return " / ".join("–" if v is None else f"{v:.2f}" for v in values)

    def stolen(s: Shortfall) -> str:
        if s.stolen_s is None:
            return "–"
        return f"{1e3 * s.stolen_s[0]:.0f} ms, in {s.stolen_s[1]} rounds"

    return [
        f"| two-thread rounds | rounds | under {tg.THREADS_TEXT} | CPU / wall (median: "
        "under / the others) | CPU over one thread's (median: under / the others) "
        "| stolen from the vCPUs |",
        "|---|---|---|---|---|---|",
        *(
            f"| {s.kind} | {s.rounds} | {s.under} | {pair(s.share)} | {pair(s.cost)} "
            f"| {stolen(s)} |"
            for s in found
        ),
    ]


def machines(runs: Sequence[Run]) -> list[str]:
    """Each machine (and commit) the runs name, with its runs."""
    seen: dict[str, list[str]] = {}
    for r in runs:
        seen.setdefault(r.machine, []).append(r.name)
    return [f"- {m}: runs {', '.join(names)}" for m, names in seen.items()]


def _drew(path: Path, draw: Callable[[], Path | None]) -> bool:
    """Runs ``draw`` (a picture into ``path``) and prints where it went; on an error
    writing ``path``, says so on stderr and returns ``False``."""
    try:
        drawn = draw()
    except OSError as e:
        print(f"error: {path}: {e.strerror}", file=sys.stderr)
        return False
    print(f"\nPicture: {drawn}")
    return True


def main(argv: Sequence[str] | None = None) -> int:
    """Print the tables of the runs named on the command line."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "runs",
        nargs="+",
        type=Path,
        help="speed.py --json files; shown in the order of the numbers in their names",
    )
    ap.add_argument("--columns", type=int, default=8, help="runs per table (default 8)")
    ap.add_argument("--partial", action="store_true", help="also runs that stopped part-way")
    ap.add_argument(
        "--plot", type=Path, metavar="PATH", help="also draw each target run by run (a PNG)"
    )
    ap.add_argument(
        "--plot-pace",
        type=Path,
        metavar="PATH",
        help="also draw the pinned workers against the GIL-free bundles, round by round",
    )
    args = ap.parse_args(argv)
    if args.columns < 1:
        ap.error(f"--columns: expected an integer >= 1, got {args.columns}")
    for option, path in (("--plot", args.plot), ("--plot-pace", args.plot_pace)):
        if path is not None and speed_plots.pyplot() is None:
            ap.error(f"{option} needs matplotlib (pip install matplotlib)")
    try:
        runs = [read_run(p, args.partial) for p in in_run_order(args.runs)]
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print("\n".join(["Machines:", *machines(runs), "", *run_tables(runs, args.columns)]))
    print("\n" + "\n".join(summary(runs)))
    if lines := shortfall_lines(runs):
        print("\n" + "\n".join(lines))
    if args.plot is not None:
        title = (
            f"Issue 7's targets in {len(runs)} runs of benches/speed.py "
            "(dashed: the limit; ringed: a miss)"
        )
        if not _drew(
            args.plot,
            lambda: speed_plots.plot_runs(
                [r.name for r in runs], target_panels(runs), title, args.plot
            ),
        ):
            return 2
    if args.plot_pace is not None:
        paced = pace_runs(runs)
        if not paced:
            print("error: --plot-pace: no run kept its thread rounds", file=sys.stderr)
            return 2
        title = (
            f"Two pinned workers against the GIL-free bundles in {len(paced)} runs of "
            "benches/speed.py"
        )
        if not _drew(
            args.plot_pace,
            lambda: speed_plots.plot_pace(paced, tg.THREADS_RATIO, title, args.plot_pace),
        ):
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
