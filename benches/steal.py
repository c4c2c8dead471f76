"""The guest's stolen time: what the hypervisor kept from this VM's vCPUs.

For the thread section of ``benches/speed.py``. Where two threads that hold no lock
(the GIL-free bundles) fall short of twice one thread's pace, either the vCPUs were
not running for part of the time (the hypervisor ran something else on their host
cores: *steal*, which a KVM guest's kernel counts in the eighth value of each ``cpu``
line of ``/proc/stat``, and leaves out of its threads' CPU time under
``CONFIG_PARAVIRT_TIME_ACCOUNTING``), or they ran and computed slower (a busy
hyper-thread sibling or shared cache on the host, which no guest counter shows). The
counter tells the two apart: the first moves it, the second does not.
"""

from __future__ import annotations

import os
from pathlib import Path

PROC_STAT = Path("/proc/stat")


def parse_steal(text: str) -> int:
    """The steal ticks of every CPU together: the eighth value of the ``cpu`` line of a
    ``/proc/stat`` text (``proc(5)``: user, nice, system, idle, iowait, irq, softirq,
    steal, in clock ticks).

    Raises
    ------
    ValueError
        If the text has no ``cpu`` line, or one without a whole number as its eighth
        value.
    """
    for line in text.splitlines():
        fields = line.split()
        if fields[:1] == ["cpu"]:
            if len(fields) < 9 or not fields[8].isdigit():
                raise ValueError(f"no steal ticks in /proc/stat's cpu line: {line!r}")
            return int(fields[8])
    raise ValueError("no cpu line in /proc/stat")


def steal_seconds(path: Path = PROC_STAT) -> float | None:
    """Seconds stolen from this machine's CPUs since it booted (every CPU's together),
    or ``None`` where they cannot be read (no ``/proc/stat``, as off Linux, or one
    without a steal count)."""
    try:
        ticks = parse_steal(path.read_text())
        hz = os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, AttributeError):  # AttributeError: no os.sysconf
        return None
    return ticks / hz


def stolen(before: float | None, after: float | None) -> float | None:
    """Seconds stolen between two :func:`steal_seconds` readings, ``None`` where either
    could not be read."""
    if before is None or after is None:
        return None
    return after - before
