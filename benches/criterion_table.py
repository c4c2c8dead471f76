"""Criterion's results as BENCHMARK.md's table: ``python benches/criterion_table.py``.

``cargo bench`` leaves each benchmark's estimates in ``target/criterion/<id>/new/
estimates.json``. This prints them in Markdown the way BENCHMARK.md records them: the
machine and commit, the insert, pyramid and match groups by cell size and scan points,
the other groups one line each, and the targets of issue 7 that criterion times (a
683-point scan inserted in ≤ 50 µs, matched on a 2 cm map in ≤ 0.2 ms). Each time is
the one criterion's ``time:`` line shows: the slope of its linear fit where it made one,
else the mean.

``--save PATH`` also writes the estimates it read to ``PATH`` (JSON: the machine and
commit, where and when they were written, each benchmark's time [s]), and ``--from
PATH`` prints the table again from such a file; a session's file is kept in
``benches/criterion/``, and the tests check that its table is the one its section of
``benches/SPEED_LOG.md`` shows.

Run from the repository root after ``cargo bench``::

    python benches/criterion_table.py
    python benches/criterion_table.py --dir other/target/criterion
    python benches/criterion_table.py --save benches/criterion/session63.json
    python benches/criterion_table.py --from benches/criterion/session63.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import datasets
import targets as tg

# The groups of crates/ndt-core/benches/core.rs timed by cell size and scan points.
GRID_GROUPS = (
    "insert",
    "insert_sums_only",
    "insert_loop",
    "pyramid_update",
    "match",
    "match_paper",
)
# Criterion's function names of the cell sizes, and their labels.
CELLS = {"cell_2cm": "2 cm", "cell_20cm": "20 cm"}
BEAMS = (180, 361, 683, 2000)
BATCHES = (1, 4, 16, 64)
LARGE = (2048, 4096, 8192, 16384, 32000)
ODOMETRY = ("181_beams_2cm", "181_beams_2cm_mapper_behind", "181_beams_2cm_poses_only")
# Issue 7's targets that criterion times: (benchmark, limit [s], what).
TARGETS = (
    (
        "insert/cell_2cm/683",
        tg.INSERT_S,
        f"insert of a 683-point scan ≤ {tg.INSERT_TEXT} (into a fresh clone)",
    ),
    (
        "insert_loop/cell_2cm/683",
        tg.INSERT_S,
        f"insert of a 683-point scan ≤ {tg.INSERT_TEXT} (a loop's inserts)",
    ),
    (
        "match/cell_2cm/683",
        tg.MATCH_S,
        f"match of a 683-point scan on a 2 cm map ≤ {tg.MATCH_TEXT}",
    ),
)


def estimate(path: Path) -> float:
    """The time [s] criterion shows for the estimates file ``path``: its slope, else
    its mean.

    Raises
    ------
    ValueError
        The file is not JSON or holds neither estimate.
    """
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not JSON ({e})") from e
    for kind in ("slope", "mean"):
        entry = doc.get(kind)
        if isinstance(entry, dict) and isinstance(entry.get("point_estimate"), (int, float)):
            return float(entry["point_estimate"]) * 1e-9
    raise ValueError(f"{path}: no slope or mean point estimate")


def results(root: Path) -> list[Path]:
    """The estimates files of the last run of each benchmark under ``root`` (criterion
    keeps the run before in ``base/``), none when ``root`` is not a directory."""
    return sorted(root.rglob("new/estimates.json")) if root.is_dir() else []


@dataclass(frozen=True)
class Estimates:
    """Criterion's times [s] by benchmark (``group/function/value``), where they were
    read from, and when the newest of them was written (``YYYY-MM-DD HH:MM``)."""

    times: dict[str, float]
    source: str
    written: str


def read(root: Path) -> Estimates:
    """Every benchmark's time under ``root`` (``group/function/value``, from the
    directory of its estimates file; see :func:`estimate`).

    Raises
    ------
    FileNotFoundError
        ``root`` holds no criterion results.
    ValueError
        An estimates file is not JSON or holds neither estimate.
    """
    files = results(root)
    if not files:
        raise FileNotFoundError(f"no criterion results in {root}: run `cargo bench` first")
    newest = time.localtime(max(f.stat().st_mtime for f in files))
    times = {f.parent.parent.relative_to(root).as_posix(): estimate(f) for f in files}
    return Estimates(times, str(root), time.strftime("%Y-%m-%d %H:%M", newest))


def save(est: Estimates, machine: str, path: Path) -> None:
    """``est`` and the ``machine`` line as ``--save``'s JSON at ``path``, whole or not
    at all (:func:`datasets.write_whole`)."""
    doc = {"machine": machine, "source": est.source, "written": est.written, "times": est.times}
    datasets.write_whole(path, json.dumps(doc, indent=1, sort_keys=True) + "\n")


def load(path: Path) -> tuple[Estimates, str]:
    """A file :func:`save` wrote: its estimates and its machine line.

    Raises
    ------
    ValueError
        ``path`` is not such a file (not JSON, a field missing, a time not a number).
    OSError
        ``path`` cannot be read.
    """
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not JSON ({e})") from e
    fields = ("machine", "source", "written", "times")
    if not isinstance(doc, dict) or any(k not in doc for k in fields):
        raise ValueError(f"{path}: not a file of --save (it needs {', '.join(fields)})")
    times = doc["times"]
    if not isinstance(times, dict) or not all(
        isinstance(v, (int, float)) and not isinstance(v, bool) for v in times.values()
    ):
        raise ValueError(f"{path}: its times are not numbers by benchmark")
    est = Estimates(
        {str(k): float(v) for k, v in times.items()}, str(doc["source"]), str(doc["written"])
    )
    return est, str(doc["machine"])


def _unit(seconds: float) -> str:
    """BENCHMARK.md's unit for a time: µs below 1 ms, else ms."""
    return "µs" if seconds < 1e-3 else "ms"


def _number(seconds: float | None, unit: str) -> str:
    """A time in ``unit``: µs with one decimal, ms with three; a dash when not measured."""
    if seconds is None:
        return "–"
    return f"{seconds * 1e6:.1f}" if unit == "µs" else f"{seconds * 1e3:.3f}"


def fmt(seconds: float | None) -> str:
    """A time as BENCHMARK.md writes it, with its unit; a dash when not measured."""
    if seconds is None:
        return _number(None, "")
    unit = _unit(seconds)
    return f"{_number(seconds, unit)} {unit}"


def _series(times: Iterable[float | None]) -> str:
    """Times joined by `` / ``, with the unit once at the end when they share one."""
    ts = list(times)
    units = {_unit(t) for t in ts if t is not None}
    if len(units) == 1:
        unit = units.pop()
        return " / ".join(_number(t, unit) for t in ts) + f" {unit}"
    return " / ".join(fmt(t) for t in ts)


def table(root: Path) -> list[str]:
    """The Markdown lines for the results under ``root`` (see the module docs): what
    :func:`lines_of` prints of :func:`read`'s estimates, with :func:`read`'s errors."""
    return lines_of(read(root))


def lines_of(est: Estimates) -> list[str]:
    """The Markdown lines for ``est`` (see the module docs)."""
    t = est.times.get
    head = " | ".join(f"{label}: {' / '.join(map(str, BEAMS))} points" for label in CELLS.values())
    lines = [
        f"Results in {est.source}, the newest written {est.written}.",
        "",
        f"| group | {head} |",
        "|---|" + "---|" * len(CELLS),
    ]
    for g in GRID_GROUPS:
        times = [[t(f"{g}/{c}/{b}") for b in BEAMS] for c in CELLS]
        if all(v is None for col in times for v in col):
            continue
        # A size the group does not time is left blank (`insert_loop`: 2 cm only).
        cols = ["" if all(v is None for v in col) else _series(col) for col in times]
        lines.append(f"| {g} | " + " | ".join(cols) + " |")
    lines.append("")
    many = [t(f"insert_many/cell_2cm_683/{n}") for n in BATCHES]
    if any(m is not None for m in many):
        per_scan = [None if m is None else m / n for m, n in zip(many, BATCHES)]
        lines.append(
            f"- `insert_many` (2 cm, 683 points), batches of {' / '.join(map(str, BATCHES))} "
            f"scans: {_series(per_scan)} a scan ({_series(many)} a call)."
        )
    for n in LARGE:
        one, par = t(f"match_large/one_thread/{n}"), t(f"match_large/parallel/{n}")
        if one is not None or par is not None:
            gain = f" ({one / par:.2f}×)" if one and par else ""
            lines.append(
                f"- `match_large` (2 cm), {n} points, one thread / `parallel`: "
                f"{_series([one, par])}{gain}."
            )
    one, every = t("match_many/one_thread"), t("match_many/every_core")
    if one is not None or every is not None:
        gain = f" ({one / every:.2f}×)" if one and every else ""
        lines.append(
            f"- `match_many`, 64 scans: {fmt(one)} on one thread, {fmt(every)} on every core{gain}."
        )
    odo = [t(f"odometry_step/{o}") for o in ODOMETRY]
    if any(o is not None for o in odo):
        lines.append(
            "- `odometry_step`: "
            + "; ".join(f"`{name}` {fmt(v)}" for name, v in zip(ODOMETRY, odo))
            + "."
        )
    lines += ["", "| target (issue 7) | criterion | met |", "|---|---|---|"]
    for bench, limit, what in TARGETS:
        v = t(bench)
        met = "–" if v is None else "yes" if v <= limit else "no"
        lines.append(f"| {what} | `{bench}` {fmt(v)} | {met} |")
    return lines


def main() -> int:
    """Print the table for ``--dir`` (``target/criterion`` by default) or ``--from``, and
    with ``--save`` keep what ``--dir`` held."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    where = ap.add_mutually_exclusive_group()
    where.add_argument("--dir", type=Path, default=datasets.REPO / "target" / "criterion")
    where.add_argument("--from", dest="kept", type=Path, metavar="PATH", help="a --save file")
    ap.add_argument("--save", type=Path, metavar="PATH", help="also write the estimates here")
    args = ap.parse_args()
    if args.kept is not None and args.save is not None:
        ap.error("--save writes what --dir holds; --from reads a file --save wrote")
    try:
        if args.kept is not None:
            est, machine = load(args.kept)
            head = f"Machine (and the commit checked out when saved): {machine}"
        else:
            est = read(args.dir)
            machine = f"{datasets.machine()}{datasets.dirty()}"
            head = f"Machine (and the commit checked out now): {machine}"
            if args.save is not None:
                save(est, machine, args.save)
    except (OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(f"{head}\n")
    print("\n".join(lines_of(est)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
