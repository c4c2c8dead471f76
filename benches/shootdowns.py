"""TLB shootdowns: how often one CPU made the others drop their cached page mappings.

For ``benches/large_bundles.py``. When a process gives memory back to the kernel
(``munmap``, or ``madvise`` from the allocator) while another of its threads runs on
another CPU, the kernel interrupts that CPU to flush its TLB: a *TLB shootdown*, counted
per CPU on the ``TLB:`` line of ``/proc/interrupts`` (x86 Linux). Two matching threads
that take and free their working memory at each call show many of them; threads that
keep theirs show only the few of their own start and end (benches/SPEED_LOG.md,
sessions 68 and 69).
"""

from __future__ import annotations

from pathlib import Path

PROC_INTERRUPTS = Path("/proc/interrupts")


def parse_shootdowns(text: str) -> int:
    """The TLB shootdowns of every CPU together, from a ``/proc/interrupts`` text: the
    sum of the ``TLB:`` line's counts, one a CPU as the header line names them
    (``CPU0 CPU1 ...``).

    Raises
    ------
    ValueError
        If the text has no header of CPUs, no ``TLB:`` line, or one with fewer whole
        numbers than CPUs.
    """
    lines = text.splitlines()
    header = lines[0].split() if lines else []
    if not header or not all(h.startswith("CPU") for h in header):
        raise ValueError("no CPU header in /proc/interrupts")
    for line in lines[1:]:
        fields = line.split()
        if fields[:1] == ["TLB:"]:
            counts = fields[1 : 1 + len(header)]
            if len(counts) < len(header) or not all(c.isdigit() for c in counts):
                raise ValueError(f"no count for each of {len(header)} CPUs: {line!r}")
            return sum(int(c) for c in counts)
    raise ValueError("no TLB: line in /proc/interrupts")


def shootdowns(path: Path = PROC_INTERRUPTS) -> int | None:
    """TLB shootdowns on this machine since it booted (every CPU's together), or
    ``None`` where they cannot be read (no ``/proc/interrupts``, as off Linux, or one
    without a ``TLB:`` line, as on other architectures)."""
    try:
        return parse_shootdowns(path.read_text())
    except (OSError, ValueError):
        return None
