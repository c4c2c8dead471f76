"""`benches/criterion_table.py`: criterion's estimates read and judged as BENCHMARK.md
records them, on a criterion tree written here."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from tests._benches import load_bench

ct = load_bench("criterion_table")
# What the table writes for a time not measured, and its ratio sign.
NA = ct.fmt(None)
TIMES = "\N{MULTIPLICATION SIGN}"


def write(root: Path, bench: str, slope: float | None, mean: float | None = None) -> None:
    """Criterion's ``new/estimates.json`` for ``bench`` with these point estimates [ns]."""
    d = root / bench / "new"
    d.mkdir(parents=True)
    doc = {
        "mean": None if mean is None else {"point_estimate": mean},
        "median": {"point_estimate": 1.0},
        "slope": None if slope is None else {"point_estimate": slope},
    }
    (d / "estimates.json").write_text(json.dumps(doc))


def test_slope_else_mean_and_the_targets(tmp_path: Path) -> None:
    write(tmp_path, "insert/cell_2cm/683", slope=51_000.0, mean=1.0)
    write(tmp_path, "insert_loop/cell_2cm/683", slope=None, mean=49_000.0)
    write(tmp_path, "match/cell_2cm/683", slope=98_600.0)
    write(tmp_path, "match_many/one_thread", slope=6.5e6)
    write(tmp_path, "match_many/every_core", slope=3.25e6)
    lines = ct.table(tmp_path)
    assert f"| insert | {NA} / {NA} / 51.0 / {NA} µs |  |" in lines
    assert f"| insert_loop | {NA} / {NA} / 49.0 / {NA} µs |  |" in lines
    # Groups not run at all have no row.
    assert not any(line.startswith("| pyramid_update") for line in lines)
    assert (
        f"- `match_many`, 64 scans: 6.500 ms on one thread, 3.250 ms on every core (2.00{TIMES})."
        in lines
    )
    assert (
        "| insert of a 683-point scan ≤ 50 µs (into a fresh clone) "
        "| `insert/cell_2cm/683` 51.0 µs | no |" in lines
    )
    assert (
        "| insert of a 683-point scan ≤ 50 µs (a loop's inserts) "
        "| `insert_loop/cell_2cm/683` 49.0 µs | yes |" in lines
    )
    assert (
        "| match of a 683-point scan on a 2 cm map ≤ 0.2 ms "
        "| `match/cell_2cm/683` 98.6 µs | yes |" in lines
    )


def test_a_target_not_run_is_not_judged(tmp_path: Path) -> None:
    write(tmp_path, "match/cell_20cm/180", slope=16_600.0)
    lines = ct.table(tmp_path)
    assert f"| match |  | 16.6 / {NA} / {NA} / {NA} µs |" in lines
    assert (
        "| insert of a 683-point scan ≤ 50 µs (into a fresh clone) "
        f"| `insert/cell_2cm/683` {NA} | {NA} |" in lines
    )


def test_batches_per_scan_and_times_in_ms(tmp_path: Path) -> None:
    for n, call in ((1, 47_600.0), (4, 116_640.0), (16, 293_980.0), (64, 816_980.0)):
        write(tmp_path, f"insert_many/cell_2cm_683/{n}", slope=call)
    write(tmp_path, "match_large/one_thread/16384", slope=2.285e6)
    write(tmp_path, "match_large/parallel/16384", slope=1.839e6)
    lines = ct.table(tmp_path)
    assert (
        "- `insert_many` (2 cm, 683 points), batches of 1 / 4 / 16 / 64 scans: "
        "47.6 / 29.2 / 18.4 / 12.8 µs a scan (47.6 / 116.6 / 294.0 / 817.0 µs a call)."
    ) in lines
    assert (
        "- `match_large` (2 cm), 16384 points, one thread / `parallel`: "
        f"2.285 / 1.839 ms (1.24{TIMES})."
    ) in lines


def test_estimates_without_a_point_estimate_are_an_error(tmp_path: Path) -> None:
    write(tmp_path, "insert/cell_2cm/683", slope=None, mean=None)
    path = tmp_path / "insert" / "cell_2cm" / "683" / "new" / "estimates.json"
    with pytest.raises(ValueError) as e:
        ct.table(tmp_path)
    assert str(e.value) == f"{path}: no slope or mean point estimate"


def test_no_results_is_a_clear_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(FileNotFoundError) as e:
        ct.table(tmp_path)
    assert str(e.value) == f"no criterion results in {tmp_path}: run `cargo bench` first"
    monkeypatch.setattr(sys, "argv", ["criterion_table.py", "--dir", str(tmp_path / "absent")])
    assert ct.main() == 2
    err = capsys.readouterr().err
    assert err == f"error: no criterion results in {tmp_path / 'absent'}: run `cargo bench` first\n"


def test_a_broken_estimates_file_is_named(tmp_path: Path) -> None:
    path = tmp_path / "match" / "cell_2cm" / "683" / "new" / "estimates.json"
    path.parent.mkdir(parents=True)
    path.write_text("{")
    with pytest.raises(ValueError, match="not JSON") as e:
        ct.table(tmp_path)
    assert str(e.value).startswith(f"{path}: not JSON (")


def test_only_an_earlier_run_is_no_results(tmp_path: Path) -> None:
    # criterion's `base/` holds the run before the last; without a `new/`, nothing ran.
    d = tmp_path / "insert" / "cell_2cm" / "683" / "base"
    d.mkdir(parents=True)
    (d / "estimates.json").write_text('{"slope": {"point_estimate": 1.0}}')
    with pytest.raises(FileNotFoundError):
        ct.table(tmp_path)


def test_a_saved_file_prints_the_same_table(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    tree = tmp_path / "criterion"
    write(tree, "insert/cell_2cm/683", slope=51_234.0)
    write(tree, "match/cell_2cm/683", slope=None, mean=98_600.0)
    write(tree, "match_many/one_thread", slope=6.5e6)
    saved = tmp_path / "kept" / "session1.json"
    monkeypatch.setattr(
        sys, "argv", ["criterion_table.py", "--dir", str(tree), "--save", str(saved)]
    )
    assert ct.main() == 0
    live = capsys.readouterr().out.splitlines()
    doc = json.loads(saved.read_text())
    assert doc["times"] == {
        "insert/cell_2cm/683": pytest.approx(51.234e-6),
        "match/cell_2cm/683": pytest.approx(98.6e-6),
        "match_many/one_thread": pytest.approx(6.5e-3),
    }
    assert doc["source"] == str(tree)
    assert not saved.with_name(saved.name + ".part").exists()
    monkeypatch.setattr(sys, "argv", ["criterion_table.py", "--from", str(saved)])
    assert ct.main() == 0
    again = capsys.readouterr().out.splitlines()
    # the same lines but the machine's, which says when it was read
    assert live[0].startswith("Machine (and the commit checked out now): ")
    assert again[0] == live[0].replace("checked out now", "checked out when saved")
    assert again[1:] == live[1:]
    assert "| insert of a 683-point scan ≤ 50 µs (into a fresh clone) " in "\n".join(again)
    assert ct.lines_of(ct.load(saved)[0]) == ct.table(tree)


@pytest.mark.parametrize(
    ("text", "why"),
    [
        ("{", "not JSON ("),
        ('{"machine": "m", "source": "s", "times": {}}', "not a file of --save "),
        ("[1, 2]", "not a file of --save "),
        (
            '{"machine": "m", "source": "s", "written": "w", "times": {"a/b": "1"}}',
            "its times are not numbers by benchmark",
        ),
        (
            '{"machine": "m", "source": "s", "written": "w", "times": {"a/b": true}}',
            "its times are not numbers by benchmark",
        ),
    ],
)
def test_a_file_not_saved_here_is_named(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    text: str,
    why: str,
) -> None:
    path = tmp_path / "kept.json"
    path.write_text(text)
    with pytest.raises(ValueError) as e:
        ct.load(path)
    assert str(e.value).startswith(f"{path}: {why}")
    monkeypatch.setattr(sys, "argv", ["criterion_table.py", "--from", str(path)])
    assert ct.main() == 2
    assert capsys.readouterr().err.startswith(f"error: {path}: {why}")


def test_save_and_from_together_are_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(
        sys, "argv", ["criterion_table.py", "--from", "a.json", "--save", str(tmp_path / "b")]
    )
    with pytest.raises(SystemExit) as e:
        ct.main()
    assert e.value.code == 2
    assert "--save writes what --dir holds; --from reads a file --save wrote" in (
        capsys.readouterr().err
    )
    assert not (tmp_path / "b").exists()
