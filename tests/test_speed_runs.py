"""`benches/speed_runs.py`: many `speed.py --json` runs as BENCHMARK.md's per-run tables,
on documents written here in the shape `speed.py` writes."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest

from tests._benches import cells, load_bench

sr = load_bench("speed_runs")
TIMES = "\N{MULTIPLICATION SIGN}"
DASH = "\N{EN DASH}"

SECTIONS: dict[str, Any] = {
    "match": {
        "sick": {"ours": 1e-4, "fastest": ["small_gicp GICP", 1.5e-3]},
        "urg_pairs": {"ours": 1e-4, "fastest": ["small_gicp GICP", 1.4e-3]},
        "urg_map": {"ours": 6e-5, "fastest": ["small_gicp VGICP", 1.5e-3]},
        "sim_map": {"ours": 8e-5, "fastest": ["small_gicp VGICP", 4.4e-3]},
        "urg_log": {"≥ 500": [1.2e-4, 560]},
    },
    "insert": {
        "sim URG-04LX 683 beams (true poses)": {"ours": 4.12e-5, "points": 548},
        "real URG-04LX exp1 (poses from ndtgrid.Odometry)": {"ours": 3e-5, "points": 420},
    },
    "odometry": {
        "scans": 13631,
        "ours": 1.05,
        "ours_one_thread": 1.9,
        "ours_poses_only": 1.0,
        "vmhwm_mib": 84.56,
        "fastest": ["KISS-ICP (voxel 1.0 m)", 3.9],
    },
    "sweeps": {
        "points": [0.0, 1e-7, 0.0, 0.9991],
        "map_recent": [0, 0, 0, [{"median": 1.0, "cells": 10}, {"median": 0.64, "cells": 90}]],
        "map_padded": [0, 0, 0, [{"median": 1.0, "cells": 10}, {"median": 0.97, "cells": 90}]],
    },
    "threads": {
        "ratio": 1.76,
        "control": 1.8,
        "bundle_ratio": 1.85,
        "steady_ratio": 1.9,
        "pinned_ratio": 1.86,
        "many_ratio": 1.88,
        "one_cpu_first_runs": 11,
        "one_cpu_runs": 1,
        "cpu_read_runs": 21,
        "late_runs": 4,
        "late_s": [0.0005] * 21,
    },
    "memory": {"bytes_per_cell": 260.6},
}


def write(path: Path, sections: dict[str, Any], complete: bool = True) -> Path:
    doc = {"machine": "2 cores of a test CPU, commit abc1234", "argv": [], "complete": complete}
    path.write_text(json.dumps({**doc, "sections": sections}))
    return path


def row(lines: list[str], words: str) -> list[str]:
    """The cells of the one table row whose name holds ``words`` (its name and the
    met column included)."""
    hits = [line for line in lines if line.startswith("| ") and words in line.split(" | ")[0]]
    assert len(hits) == 1, hits
    return cells(hits[0])


def test_a_run_meeting_every_target(tmp_path: Path) -> None:
    run = sr.read_run(write(tmp_path / "run539.json", SECTIONS))
    assert run.name == "539"
    lines = sr.run_tables([run], columns=8)
    assert lines[0] == "| target | 539 | met |"
    assert row(lines, "match sim / URG / URG ≥ 500 [ms]") == [
        "match sim / URG / URG ≥ 500 [ms]",
        "0.080 / 0.060 / 0.120",
        "1 of 1",
    ]
    assert row(lines, "fastest peer (SICK")[1] == (f"15.00 / 14.00 / 25.00 / 55.00{TIMES}")
    # Only the insert case of ≥ 500 points is judged, and shown.
    assert row(lines, "insert ≤ 50 µs")[1:] == ["41.2", "1 of 1"]
    assert row(lines, "Intel ≤ 3 s (one thread)")[1] == "1.05 (1.90)"
    assert row(lines, "fastest peer odometry")[1] == f"3.71{TIMES} (3.90)"
    assert row(lines, "no map")[1:] == [f"1.00 (3.90{TIMES})", DASH]
    assert row(lines, "linear (R²) / flat (padded / recent maps)")[1] == "0.999 / 0.97 / 0.64"
    assert row(lines, "started for each run")[1] == (f"1.76{TIMES} (1.80; 1.85)")
    assert row(lines, "memory")[1] == "261 B/cell, 84.6 MiB"
    assert sr.met_every_target([row.cell(run.sections) for row in sr.ROWS])


def test_misses_are_bold_and_never_round_onto_the_limit(tmp_path: Path) -> None:
    s = copy.deepcopy(SECTIONS)
    s["threads"]["ratio"] = 1.6951
    s["insert"]["sim URG-04LX 683 beams (true poses)"]["ours"] = 50.04e-6
    s["match"]["urg_log"]["≥ 500"][0] = 2.013e-4
    s["odometry"]["ours"] = 1.4  # the peer's 3.9 s over 1.4 s: 2.79 times
    lines = sr.run_tables([sr.read_run(write(tmp_path / "r7.json", s))], columns=8)
    assert row(lines, "started for each run")[1:] == [
        f"**1.695**{TIMES} (1.80; 1.85)",
        "0 of 1",
    ]
    assert row(lines, "insert ≤ 50 µs")[1:] == ["**50.04**", "0 of 1"]
    assert row(lines, "match sim / URG / URG ≥ 500 [ms]")[1] == "0.080 / 0.060 / **0.201**"
    assert row(lines, "fastest peer odometry")[1] == f"**2.79**{TIMES} (3.90)"
    # A miss that does not round onto the limit keeps its digits.
    s["threads"]["ratio"] = 1.52
    lines = sr.run_tables([sr.read_run(write(tmp_path / "r8.json", s))], columns=8)
    assert row(lines, "started for each run")[1] == (f"**1.52**{TIMES} (1.80; 1.85)")


def test_a_section_not_run_is_a_dash_and_not_judged(tmp_path: Path) -> None:
    s = {k: v for k, v in SECTIONS.items() if k != "threads"}
    s["threads"] = {**SECTIONS["threads"], "pinned_ratio": None}  # one CPU: no pinned row
    del s["threads"]["steady_ratio"]  # a run from before session 54
    s["odometry"] = {**SECTIONS["odometry"], "scans": 921}  # --quick: not the whole log
    run = sr.read_run(write(tmp_path / "run1.json", s))
    lines = sr.run_tables([run], columns=8)
    assert row(lines, "two pinned workers")[1:] == [DASH, DASH]
    assert row(lines, "keep matching")[1:] == [DASH, DASH]
    # Not the whole log: shown, not judged.
    assert row(lines, "Intel ≤ 3 s (one thread)")[1:] == ["1.05 (1.90)", DASH]
    assert not sr.met_every_target([r.cell(run.sections) for r in sr.ROWS])


def test_tables_of_at_most_columns_runs_and_the_summary(tmp_path: Path) -> None:
    slow = copy.deepcopy(SECTIONS)
    slow["insert"]["sim URG-04LX 683 beams (true poses)"]["ours"] = 5.43e-5
    slow["threads"]["ratio"] = 1.44
    runs = [
        sr.read_run(write(tmp_path / f"run{n}.json", slow if n == 11 else SECTIONS))
        for n in (10, 11, 12)
    ]
    lines = sr.run_tables(runs, columns=2)
    heads = [line for line in lines if line.startswith("| target |")]
    assert heads == ["| target | 10 | 11 | met |", "| target | 12 | met |"]
    assert lines[lines.index(heads[1]) - 1] == ""
    assert [c for c in lines if c.startswith("| insert ≤ 50 µs |")] == [
        "| insert ≤ 50 µs | 41.2 | **54.3** | 1 of 2 |",
        "| insert ≤ 50 µs | 41.2 | 1 of 1 |",
    ]
    summary = sr.summary(runs)
    assert summary[0] == "| target | 3 runs | met |"
    assert row(summary, "insert ≤ 50 µs")[1:] == [f"41.2{DASH}54.3", "2 of 3"]
    assert row(summary, "started for each run")[1:] == [
        f"1.44{DASH}1.76{TIMES} (1.80; 1.85)",
        "2 of 3",
    ]
    assert summary[-1] == "Every target met in 2 of 3 runs: 10, 12."


def test_the_machines_and_their_runs(tmp_path: Path) -> None:
    a = sr.read_run(write(tmp_path / "run1.json", SECTIONS))
    b = sr.Run("2", "another machine", SECTIONS)
    assert sr.machines([a, b, a]) == [
        "- 2 cores of a test CPU, commit abc1234: runs 1, 1",
        "- another machine: runs 2",
    ]


def test_unreadable_and_foreign_files_are_named(tmp_path: Path) -> None:
    missing = tmp_path / "run9.json"
    with pytest.raises(ValueError, match=rf"^{missing}: No such file or directory$"):
        sr.read_run(missing)
    bad = tmp_path / "bad.json"
    bad.write_text("{\n  'x': 1\n}")
    with pytest.raises(
        ValueError,
        match=rf"^{bad}: not JSON \(Expecting property name enclosed in double quotes, line 2\)$",
    ):
        sr.read_run(bad)
    foreign = tmp_path / "estimates.json"
    foreign.write_text('{"mean": {"point_estimate": 1.0}}')
    with pytest.raises(
        ValueError, match=rf'^{foreign}: not a `speed.py --json` document \(no "sections"\)$'
    ):
        sr.read_run(foreign)


def test_a_run_stopped_part_way_only_with_partial(tmp_path: Path) -> None:
    path = write(tmp_path / "run3.json", {"match": SECTIONS["match"]}, complete=False)
    with pytest.raises(
        ValueError, match=rf"^{path}: the run stopped part-way; --partial tables what it measured$"
    ):
        sr.read_run(path)
    run = sr.read_run(path, partial=True)
    lines = sr.run_tables([run], columns=8)
    assert row(lines, "match sim / URG / URG ≥ 500 [ms]")[1:] == ["0.080 / 0.060 / 0.120", "1 of 1"]
    assert row(lines, "insert ≤ 50 µs")[1:] == [DASH, DASH]
    assert sr.summary([run])[-1] == "Every target met in 0 of 1 runs."


def test_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    a, b = write(tmp_path / "run1.json", SECTIONS), write(tmp_path / "run2.json", SECTIONS)
    assert sr.main([str(a), str(b), "--columns", "1"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("Machines:\n- 2 cores of a test CPU, commit abc1234: runs 1, 2\n\n")
    assert out.count("| target | ") == 3  # two one-run tables and the summary
    assert out.endswith("Every target met in 2 of 2 runs: 1, 2.\n")
    assert sr.main([str(a), str(tmp_path / "run5.json")]) == 2
    err = capsys.readouterr().err
    assert err == f"error: {tmp_path / 'run5.json'}: No such file or directory\n"
    with pytest.raises(SystemExit):
        sr.main([str(a), "--columns", "0"])
    assert "--columns: expected an integer >= 1, got 0" in capsys.readouterr().err


def test_runs_in_the_order_of_their_numbers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A shell's run*.json lists run1000.json before run999.json.
    names = ("run1000", "run999", "notes", "run0")
    paths = [write(tmp_path / f"{n}.json", SECTIONS) for n in names]
    assert sr.in_run_order(paths) == [paths[3], paths[1], paths[0], paths[2]]
    assert sr.main([str(p) for p in paths]) == 0
    out = capsys.readouterr().out
    assert "| target | 0 | 999 | 1000 | notes | met |" in out.splitlines()
    assert out.endswith("Every target met in 4 of 4 runs: 0, 999, 1000, notes.\n")


def test_the_judged_numbers_run_by_run(tmp_path: Path) -> None:
    slow = copy.deepcopy(SECTIONS)
    slow["insert"]["sim URG-04LX 683 beams (true poses)"]["ours"] = 5.43e-5
    slow["threads"]["ratio"] = 1.44
    short = {k: v for k, v in SECTIONS.items() if k != "sweeps"}
    short["odometry"] = {**SECTIONS["odometry"], "scans": 921}  # not the whole log
    runs = [
        sr.read_run(write(tmp_path / f"run{n}.json", s))
        for n, s in ((1, SECTIONS), (2, slow), (3, short))
    ]
    panels = sr.target_panels(runs)
    assert [p.title for p in panels] == [
        "median match ≤ 0.2 ms [ms]",
        f"match: the fastest peer's time / ours ≥ 3{TIMES}",
        "insert of a scan of ≥ 500 points ≤ 50 µs [µs]",
        "the Intel log (13631 scans) ≤ 3 s [s]",
        f"odometry: the fastest peer's time / ours ≥ 3{TIMES}",
        "match time linear in scan points: R² ≥ 0.95",
        "match time, largest map / smallest ≤ 1.2",
        f"two threads' throughput / one thread's ≥ 1.7{TIMES}",
    ]
    match, peers, insert, intel, _, linear, flat, threads = panels
    assert [s.label for s in match.series] == [
        "simulated URG-04LX",
        "real URG-04LX",
        "real URG-04LX, ≥ 500 points",
    ]
    assert match.series[0].values == pytest.approx((0.08, 0.08, 0.08))
    assert [s.label for s in peers.series] == [
        "real SICK pairs",
        "real URG pairs",
        "real URG map",
        "simulated map",
    ]
    assert peers.series[0].values == pytest.approx((15.0, 15.0, 15.0))
    # Only the case of ≥ 500 points, in µs; its miss is counted out of the legend.
    assert insert.limit == 50.0
    [case] = insert.series
    assert case.label == "sim URG-04LX 683 beams (true poses)"
    assert case.values == pytest.approx((41.2, 54.3, 41.2))
    assert case.met == (True, False, True)
    assert case.legend() == f"{case.label} (2 of 3)"
    # A short log is not judged: no value drawn.
    assert intel.series[0].values == (1.05, 1.05, None)
    assert intel.series[0].met == (True, True, None)
    assert intel.series[0].legend() == "ndtgrid.Odometry (2 of 2)"
    # R² must reach its limit, the growths not exceed theirs.
    assert linear.limit == 0.95
    assert linear.series[0].values == (0.9991, 0.9991, None)
    assert linear.series[0].met == (True, True, None)
    assert flat.limit == 1.2
    assert flat.series[1].values == pytest.approx((0.64, 0.64, None))
    assert flat.series[1].met == (True, True, None)
    assert [s.label for s in flat.series] == ["padded maps", "recent maps"]
    assert [s.label for s in threads.series] == [
        "started for each run",
        "keep matching",
        "pinned workers",
        "one match_many call",
    ]
    started = threads.series[0]
    assert started.values == (1.76, 1.44, 1.76)
    assert started.met == (True, False, True)
    assert started.legend() == "started for each run (2 of 3)"


def test_the_picture_on_the_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    a = write(tmp_path / "run1.json", SECTIONS)
    png = tmp_path / "pictures" / "runs.png"
    assert sr.main([str(a), "--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert capsys.readouterr().out.endswith(f"\nPicture: {png.resolve()}\n")
    blocked = tmp_path / "a file"
    blocked.write_text("")
    assert sr.main([str(a), "--plot", str(blocked / "runs.png")]) == 2
    assert capsys.readouterr().err == f"error: {blocked / 'runs.png'}: File exists\n"
    monkeypatch.setattr(sr.speed_plots, "pyplot", lambda: None)
    with pytest.raises(SystemExit):
        sr.main([str(a), "--plot", str(png)])
    assert "--plot needs matplotlib (pip install matplotlib)" in capsys.readouterr().err


def test_the_pinned_workers_against_the_bundles_round_by_round(tmp_path: Path) -> None:
    kept = copy.deepcopy(SECTIONS)
    kept["threads"]["per_run"] = {"bundles": [1.5, 2.0, 1.6], "pinned": [1.8, 1.9, 1.6]}
    missed = copy.deepcopy(kept)
    missed["threads"]["pinned_ratio"] = 1.62
    missed["threads"]["per_run"] = {"bundles": [1.4, 1.5], "pinned": [1.54, 1.5]}
    runs = [
        sr.read_run(write(tmp_path / f"run{n}.json", s))
        for n, s in ((1, kept), (2, SECTIONS), (3, missed))
    ]
    paced = sr.pace_runs(runs)
    # run 2 kept no rounds, so it is left out
    assert [(r.name, r.bundles, r.pinned, r.missed) for r in paced] == [
        ("1", (1.5, 2.0, 1.6), (1.8, 1.9, 1.6), False),
        ("3", (1.4, 1.5), (1.54, 1.5), True),
    ]
    assert paced[0].median_quotient() == pytest.approx(1.0)  # of 1.2, 0.95 and 1.0
    assert paced[1].median_quotient() == pytest.approx(1.05)  # of 1.1 and 1.0


def test_the_pace_picture_on_the_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    s = copy.deepcopy(SECTIONS)
    s["threads"]["per_run"] = {"bundles": [1.5, 2.0], "pinned": [1.8, 1.9]}
    a = write(tmp_path / "run1.json", s)
    png = tmp_path / "pictures" / "pace.png"
    assert sr.main([str(a), "--plot-pace", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert capsys.readouterr().out.endswith(f"\nPicture: {png.resolve()}\n")
    bare = write(tmp_path / "run2.json", SECTIONS)
    assert sr.main([str(bare), "--plot-pace", str(png)]) == 2
    assert capsys.readouterr().err == "error: --plot-pace: no run kept its thread rounds\n"
    monkeypatch.setattr(sr.speed_plots, "pyplot", lambda: None)
    with pytest.raises(SystemExit):
        sr.main([str(a), "--plot-pace", str(png)])
    assert "--plot-pace needs matplotlib (pip install matplotlib)" in capsys.readouterr().err


def test_the_rounds_under_the_limit_and_their_cpu_times(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    kept = copy.deepcopy(SECTIONS)
    kept["threads"]["per_run"] = {
        "bundles": [1.5, 2.0, 1.6],
        "bundles_share": [1.9, 1.98, 1.7],
        "bundles_cost": [1.3, 1.0, 1.1],
        "pinned": [1.8, 1.6],
        "pinned_share": [1.96, 1.8],
        "pinned_cost": [1.05, 1.1],
    }
    kept["threads"]["bundles_steal_s"] = [0.0, 0.01, None]
    older = copy.deepcopy(SECTIONS)  # a run from before session 68: ratios alone
    older["threads"]["per_run"] = {"bundles": [1.0], "pinned": [1.0]}
    runs = [sr.read_run(write(tmp_path / f"run{n}.json", s)) for n, s in ((1, kept), (2, older))]
    bundles, pinned = sr.shortfalls(runs)
    # under the limit: rounds 1 and 3 (medians of two), the others: round 2
    assert (bundles.kind, bundles.rounds, bundles.under) == ("GIL-free bundles", 3, 2)
    assert bundles.share == pytest.approx((1.8, 1.98))
    assert bundles.cost == pytest.approx((1.2, 1.0))
    assert bundles.stolen_s == (pytest.approx(0.01), 1)
    assert (pinned.kind, pinned.rounds, pinned.under) == ("pinned workers", 2, 1)
    assert pinned.share == pytest.approx((1.8, 1.96))
    assert pinned.cost == pytest.approx((1.1, 1.05))
    assert pinned.stolen_s is None
    lines = sr.shortfall_lines(runs)
    assert lines[2:] == [
        "| GIL-free bundles | 3 | 2 | 1.80 / 1.98 | 1.20 / 1.00 | 10 ms, in 1 rounds |",
        f"| pinned workers | 2 | 1 | 1.80 / 1.96 | 1.10 / 1.05 | {DASH} |",
    ]
    # Runs that kept no CPU times get no table, on the command line neither.
    assert sr.shortfalls(runs[1:]) == [] and sr.shortfall_lines(runs[1:]) == []
    assert sr.main([str(tmp_path / "run2.json")]) == 0
    assert "two-thread rounds" not in capsys.readouterr().out
    assert sr.main([str(tmp_path / "run1.json")]) == 0
    assert lines[-1] in capsys.readouterr().out.splitlines()
