"""TLB shootdowns, as ``benches/shootdowns.py`` reads them for
``benches/large_bundles.py``."""

from __future__ import annotations

from pathlib import Path

import pytest

from ._benches import load_bench

shootdowns = load_bench("shootdowns")

# proc(5)'s layout on x86: a header of CPUs, then one line an interrupt source.
INTERRUPTS = """           CPU0       CPU1
 24:          1          0  IO-APIC   5-edge      ACPI:Ged
RES:     225857     202205   Rescheduling interrupts
CAL:    3364753    1349688   Function call interrupts
TLB:     442596     257738   TLB shootdowns
ERR:          0
"""


def test_parse_shootdowns_adds_every_cpus_count() -> None:
    assert shootdowns.parse_shootdowns(INTERRUPTS) == 442596 + 257738


def test_parse_shootdowns_reads_as_many_counts_as_cpus() -> None:
    one_cpu = "           CPU0\nTLB:         17   TLB shootdowns\n"
    assert shootdowns.parse_shootdowns(one_cpu) == 17


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", r"^no CPU header in /proc/interrupts$"),
        (" 24: 1 0 IO-APIC\n", r"^no CPU header in /proc/interrupts$"),
        ("   CPU0   CPU1\nRES: 1 2 Rescheduling\n", r"^no TLB: line in /proc/interrupts$"),
        ("   CPU0   CPU1\nTLB: 5\n", r"^no count for each of 2 CPUs: 'TLB: 5'$"),
        ("   CPU0   CPU1\nTLB: 5 TLB shootdowns\n", r"^no count for each of 2 CPUs: "),
    ],
)
def test_parse_shootdowns_rejects(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        shootdowns.parse_shootdowns(text)


def test_shootdowns_none_where_unreadable(tmp_path: Path) -> None:
    assert shootdowns.shootdowns(tmp_path / "missing") is None
    bad = tmp_path / "interrupts"
    bad.write_text("           CPU0\nRES: 1\n")
    assert shootdowns.shootdowns(bad) is None


def test_shootdowns_reads_a_file(tmp_path: Path) -> None:
    path = tmp_path / "interrupts"
    path.write_text(INTERRUPTS)
    assert shootdowns.shootdowns(path) == 700334


def test_shootdowns_on_this_machine_do_not_go_back() -> None:
    first = shootdowns.shootdowns()
    if first is None:
        pytest.skip("no TLB: line in /proc/interrupts here (not x86 Linux)")
    second = shootdowns.shootdowns()
    assert second is not None and second >= first >= 0
