"""The guest's stolen time, as ``benches/steal.py`` reads it for the thread section of
``benches/speed.py``."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from ._benches import load_bench

steal = load_bench("steal")

# proc(5)'s layout: the all-CPU line, then one line a CPU, then other counters.
STAT = """cpu  2607464 0 128807 2054960 4997 0 1023 468 0 0
cpu0 941842 0 49617 1403979 1108 0 342 251 0 0
cpu1 1665621 0 79189 650981 3888 0 680 216 0 0
intr 123 0 9
ctxt 456
"""


def test_parse_steal_reads_the_all_cpu_lines_eighth_value() -> None:
    assert steal.parse_steal(STAT) == 468


def test_parse_steal_skips_lines_before_the_cpu_line() -> None:
    assert steal.parse_steal("ctxt 1\n" + STAT) == 468


def test_parse_steal_without_a_cpu_line() -> None:
    with pytest.raises(ValueError, match=r"^no cpu line in /proc/stat$"):
        steal.parse_steal("cpu0 1 2 3 4 5 6 7 8\nctxt 1\n")


@pytest.mark.parametrize("line", ["cpu  1 2 3 4 5 6 7", "cpu  1 2 3 4 5 6 7 x 0"])
def test_parse_steal_without_steal_ticks(line: str) -> None:
    with pytest.raises(ValueError, match=r"^no steal ticks in /proc/stat's cpu line: "):
        steal.parse_steal(line + "\n")


def test_steal_seconds_are_ticks_over_the_clock_rate(tmp_path: Path) -> None:
    if not hasattr(os, "sysconf"):
        pytest.skip("no os.sysconf here")
    stat = tmp_path / "stat"
    stat.write_text(STAT)
    assert steal.steal_seconds(stat) == pytest.approx(468 / os.sysconf("SC_CLK_TCK"))


def test_steal_seconds_none_where_unreadable(tmp_path: Path) -> None:
    assert steal.steal_seconds(tmp_path / "missing") is None
    bad = tmp_path / "stat"
    bad.write_text("cpu  1 2 3\n")
    assert steal.steal_seconds(bad) is None


def test_steal_seconds_on_this_machine_do_not_go_back() -> None:
    first = steal.steal_seconds()
    if first is None:
        pytest.skip("no /proc/stat steal count on this machine")
    later = steal.steal_seconds()
    assert later is not None and later >= first >= 0.0


def test_stolen_between_two_readings() -> None:
    assert steal.stolen(1.25, 1.5) == pytest.approx(0.25)
    assert steal.stolen(None, 1.5) is None
    assert steal.stolen(1.25, None) is None
