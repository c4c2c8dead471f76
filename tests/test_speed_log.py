"""``benches/SPEED_LOG.md``, issue 7's sessions one section each, and what points into it.

The code, the docs and the benches cite the log as "benches/SPEED_LOG.md, session N"; a
citation of a session the log has no section for, a session out of order, a link that
does not resolve, or BENCHMARK.md naming a different last session fails here; so does
a session whose criterion results are kept (``benches/criterion/sessionN.json``) without
their table, as ``benches/criterion_table.py --from`` prints it, in its section; and
BENCHMARK.md's Core section not showing the newest kept table, or its history of the
sessions' criterion tables quoting a 683-point time other than the session's own; or the
README's ranges over the Zen 4 VM's kept tables not the ones those tables give.
"""

from __future__ import annotations

import functools
import os
import re
from pathlib import Path

from tests._benches import (
    BENCHES,
    ROOT,
    ZEN4_MACHINE,
    doc,
    flat,
    flat_doc,
    listed,
    load_bench,
)

LOG = BENCHES / "SPEED_LOG.md"

# "## Session 59 (…" or "## Sessions 22\u201323 (…" (an en dash, \u2013)
HEADING = re.compile(r"^## Sessions? (\d+)(?:\u2013(\d+))?\b", re.MULTILINE)
# "benches/SPEED_LOG.md, session 28", "``benches/SPEED_LOG.md``, sessions 29 and\n33",
# a comment's prefix allowed where the citation wraps
CITATION = re.compile(
    r"SPEED_LOG\.md`*,\s*(?:(?://[/!]?|#)\s*)?sessions?\s+"
    r"(\d+(?:\s*(?:(?://[/!]?|#)\s*)?(?:,|and|\u2013|-)\s*(?:(?://[/!]?|#)\s*)?\d+)*)"
)
SUFFIXES = {".py", ".pyi", ".rs", ".md", ".toml"}
SKIP_DIRS = {"target", "__pycache__", "node_modules"}


@functools.cache
def sections() -> list[tuple[int, int, str]]:
    """Each section's sessions, first and last, and its text (its heading to the next), in
    the log's order."""
    text = doc("benches/SPEED_LOG.md")
    heads = list(HEADING.finditer(text))
    ends = [m.start() for m in heads[1:]] + [len(text)]
    return [(int(m[1]), int(m[2] or m[1]), text[m.start() : end]) for m, end in zip(heads, ends)]


def section(session: int) -> str:
    """The text of the log's section of ``session`` (its heading to the next)."""
    (body,) = [body for first, _, body in sections() if first == session]
    return body


def benchmark() -> str:
    """BENCHMARK.md's text (read once, by :func:`doc`)."""
    return doc("BENCHMARK.md")


def readme() -> str:
    """The README's text as a reader sees it, white space runs one space (by :func:`flat_doc`)."""
    return flat_doc("README.md")


def core_section() -> str:
    """BENCHMARK.md's "Core: insert and match" section, its heading to the next."""
    text = benchmark()
    start = text.index("## Core: insert and match")
    return text[start : text.index("\n## ", start)]


@functools.cache
def kept_files() -> list[tuple[int, str, str]]:
    """Each kept criterion file's session, machine line and table, from its header to its
    targets, as ``benches/criterion_table.py --from`` prints it (the first line, naming
    where the file was read, left out), newest first."""
    ct = load_bench("criterion_table")
    kept = []
    for path in (BENCHES / "criterion").glob("session*.json"):
        est, machine = ct.load(path)
        assert "+ uncommitted changes" not in machine, f"{path.name}: {machine}"
        lines = ct.lines_of(est)
        table = "\n".join(lines[lines.index("") + 1 :])
        kept.append((int(path.stem.removeprefix("session")), machine, table))
    assert kept, "no criterion results kept in benches/criterion/"
    return sorted(kept, reverse=True)


def kept_tables() -> list[tuple[int, str]]:
    """Each kept criterion file's session and its table (:func:`kept_files`), newest
    first."""
    return [(session, table) for session, _, table in kept_files()]


# A full criterion table's header (at a line's start), as `benches/criterion_table.py`
# prints it; its rows give the 2 cm times first ("| insert | 26.7 / 33.9 / 48.1 / 68.7 µs | …").
GROUP_HEAD = "| group | 2 cm: 180 / 361 / 683 / 2000 points |"
# A row of BENCHMARK.md's criterion history: session, commit, machine, criterion's times,
# the 683-point insert and match.
HISTORY_ROW = re.compile(
    r"^\| (\d+) \| ([0-9a-f]{7,40}) \| [^|\n]+ \| [^|\n]+ \| ([^|\n]+) \| ([^|\n]+) \|",
    re.MULTILINE,
)


def cell_683(table: str, group: str) -> str:
    """The 683-point 2 cm time of the row ``group`` of a full criterion ``table``, with its
    row's unit ("48.1 µs")."""
    row = re.search(rf"^\| {group} \| ([^|\n]+) \|", table, re.MULTILINE)
    assert row, f"no {group} row in {table[:200]!r}"
    parts = row[1].split(" / ")
    assert len(parts) == 4, row[0]
    unit = parts[-1].split()[-1]
    return parts[2] if " " in parts[2] else f"{parts[2]} {unit}"


def first_table_683(body: str) -> tuple[str, str] | None:
    """The 683-point 2 cm times of the `insert` and `match` rows of ``body``'s first full
    criterion table, each with its row's unit ("48.1 µs"); ``None`` without one."""
    head = re.search(rf"^{re.escape(GROUP_HEAD)}", body, re.MULTILINE)
    if not head:
        return None
    table = body[head.start() :].split("\n\n", 1)[0]
    return cell_683(table, "insert"), cell_683(table, "match")


def sessions() -> list[tuple[int, int]]:
    """Each section's sessions, first and last, in the log's order."""
    return [(first, last) for first, last, _ in sections()]


def sources() -> list[Path]:
    """The repository's text files that may cite the log (build output and hidden or
    virtual-environment directories left out)."""
    found = []
    for top, dirs, files in os.walk(ROOT):
        dirs[:] = [
            d
            for d in dirs
            if d not in SKIP_DIRS
            and not d.startswith(".")
            and not (Path(top) / d / "pyvenv.cfg").exists()
        ]
        found += [Path(top) / f for f in files if Path(f).suffix in SUFFIXES]
    return found


def test_sections_run_newest_first_without_gaps() -> None:
    spans = sessions()
    assert spans[0][0] >= 59, spans[0]
    # the oldest section is session 5's, which also has sessions 3 and 4's figures
    assert spans[-1] == (5, 5)
    for (first, _), (_, last) in zip(spans, spans[1:]):
        assert last == first - 1, (first, last)


def test_every_citation_names_a_session_of_the_log() -> None:
    known = {n for first, last in sessions() for n in range(first, last + 1)}
    cited = 0
    for path in sources():
        text = path.read_text(encoding="utf-8", errors="replace")
        for m in CITATION.finditer(text):
            numbers = [int(n) for n in re.findall(r"\d+", m[1])]
            missing = [n for n in numbers if n not in known]
            assert not missing, f"{path.relative_to(ROOT)}: {m[0]!r} cites {missing}"
            cited += 1
    # the core's comments, the package's docstrings and the benches cite it dozens of times
    assert cited >= 60, cited


def test_no_session_section_left_in_benchmark() -> None:
    text = benchmark()
    assert not re.search(r"^#+ Sessions? \d", text, re.MULTILINE)
    newest = sessions()[0][1]
    assert f"What\neach session from 3 to {newest} measured is in the speed log" in text


def test_the_logs_links_resolve() -> None:
    text = doc("benches/SPEED_LOG.md")
    links = re.findall(r"\]\(([^)\s]+)\)", text)
    assert links
    for link in links:
        assert (LOG.parent / link.split("#")[0]).exists(), link


def test_each_kept_criterion_run_is_tabled_in_its_session() -> None:
    for session, tabled in kept_tables():
        assert tabled in section(session), f"session {session}'s table is not in its section"


def test_benchmark_shows_the_newest_kept_criterion_table() -> None:
    session, tabled = kept_tables()[0]
    core = core_section()
    assert tabled in core, f"BENCHMARK.md's Core section does not show session {session}'s table"
    assert f"`benches/criterion/session{session}.json`" in core


def test_the_core_history_quotes_each_sessions_criterion_table() -> None:
    rows = HISTORY_ROW.findall(core_section())
    tabled = [(n, body, cells) for n, _, body in sections() if (cells := first_table_683(body))]
    # one row for each section with a full table, newest first; the newest is the kept one
    assert [int(r[0]) for r in rows] == [n for n, _, _ in tabled]
    assert int(rows[0][0]) == kept_tables()[0][0]
    for (session, commit, insert, match), (_, body, cells) in zip(rows, tabled):
        assert commit in body, f"session {session}: no {commit} in its section"
        assert (insert, match) == cells, f"session {session}: {(insert, match)} against {cells}"


def test_the_prose_quotes_the_newest_criterion_table() -> None:
    """The sentences that quote the newest kept criterion table's 683-point insert (into a
    fresh clone and in the loop's case) and match, BENCHMARK.md's Core introduction, its
    insert status cell and the README's criterion paragraph, quote its numbers."""
    session, tabled = kept_tables()[0]
    insert, loop, match = (cell_683(tabled, g) for g in ("insert", "insert_loop", "match"))
    core = flat(core_section())
    assert f"The newest run, session {session}'s (" in core
    assert f"the 683-point insert into a fresh clone {insert}" in core
    assert f"the loop's {loop})" in core
    target = "| insert of a 683-point scan ≤ 50 µs |"
    (status,) = [row for row in benchmark().splitlines() if row.startswith(target)]
    assert f"(session {session} on the " in status, status
    assert f": {insert}, the loop's case {loop})" in status, status
    assert f"on session {session}'s " in readme()
    assert f"{insert} (the loop's case {loop}) and {match}" in readme()


def _micro(cell: str) -> float:
    """``cell_683``'s "48.1 µs" as a number of µs."""
    value, unit = cell.split()
    assert unit == "µs", cell
    return float(value)


def test_the_docs_quote_the_zen4_criterion_ranges() -> None:
    """The README's criterion paragraph and BENCHMARK.md's status table (its Zen 4
    `cargo bench` cell) sum up the kept criterion tables of the Zen 4 VM (family 25,
    model 17): the ranges of the 683-point insert into a fresh clone, the loop's insert
    and the match over those sessions, the newest session, and (the README) the sessions
    whose inserts were over the 50 µs target, as the kept files give them."""
    tables = {s: table for s, machine, table in kept_files() if machine.startswith(ZEN4_MACHINE)}
    assert len(tables) >= 2, f"kept Zen 4 tables: {sorted(tables)}"
    first, last = min(tables), max(tables)
    assert sorted(tables) == list(range(first, last + 1)), sorted(tables)

    def spread(group: str) -> tuple[str, list[str]]:
        cells = {s: cell_683(t, group) for s, t in tables.items()}
        values = {s: _micro(c) for s, c in cells.items()}
        low, high = min(values.values()), max(values.values())
        over = [str(s) for s in sorted(values) if values[s] > 50.0]
        return f"{low:.1f}\u2013{high:.1f} µs", over

    insert, insert_over = spread("insert")
    loop, loop_over = spread("insert_loop")
    match, _ = spread("match")
    assert insert_over and loop_over, "the sentence below names sessions over the target"
    quote = (
        f"the insert took {insert} (the loop's case {loop}) and the match {match} in the "
        f"`cargo bench` runs of sessions {first}\u2013{last}, the insert over 50 µs in "
        f"sessions {listed(insert_over)} and the loop's case in {listed(loop_over)}"
    )
    assert quote in readme(), quote
    flat_benchmark = flat_doc("BENCHMARK.md")
    assert f"the full table, session {last} (" in flat_benchmark, last
    assert (
        f"over sessions {first}\u2013{last}, the same core and VM kind: the 683-point insert "
        f"into a fresh clone {insert}, in the loop's case {loop}, the 683-point match {match};"
        in flat_benchmark
    ), (insert, loop, match)
