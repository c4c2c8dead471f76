"""Python threads that keep matching: the throughput of a SLAM loop's threads, which live
for the whole run, as ``benches/speed.py``'s thread section measures it beside its short
runs.

The section's main row starts two threads for each run of 300 matches each, about 15 ms:
where the kernel first puts a new thread weighs on such a run. On a VM whose kernel
starts the second thread on the first one's vCPU, the two can share that vCPU for several
milliseconds before the load balancer moves one (benches/SPEED_LOG.md, sessions 29 and
54). :func:`keep_matching` times threads that match for a whole second or more, so that
such a start is a small part of the run, as in a loop that runs for minutes.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class SteadyRun:
    """One run of :func:`keep_matching`.

    Attributes
    ----------
    calls : tuple of int
        The calls each thread finished.
    wall : float
        Seconds from the threads' start to the last one's end.
    cpu : float
        This process's CPU time over the run, in seconds.
    """

    calls: tuple[int, ...]
    wall: float
    cpu: float

    @property
    def rate(self) -> float:
        """Calls per second, all threads together."""
        return sum(self.calls) / self.wall

    @property
    def cpu_over_wall(self) -> float:
        """The process's CPU time over the wall time (2.0: two threads busy throughout)."""
        return self.cpu / self.wall


def keep_matching(task: Callable[[int], object], threads: int, seconds: float) -> SteadyRun:
    """Runs ``threads`` Python threads, started together where the kernel puts them (not
    pinned), thread ``k`` calling ``task(k)``, ``task(k + threads)``, ``task(k + 2 *
    threads)``, … until ``seconds`` have passed since the start; each then finishes its
    call and ends.

    Parameters
    ----------
    task : callable
        ``task(i)`` does the ``i``-th piece of work (``speed.py``: matches scan ``i``
        modulo its scans).
    threads : int
        Threads, at least 1.
    seconds : float
        How long the threads keep calling, more than 0.

    Returns
    -------
    SteadyRun
        The calls each thread finished, the wall time from the start to the last
        thread's end (the calls over it are the throughput) and the process's CPU time.

    Raises
    ------
    ValueError
        If ``threads`` or ``seconds`` is out of range.
    Exception
        The first exception a call of ``task`` raised (the other threads stop at their
        next call).
    """
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise ValueError(f"threads: expected an integer >= 1, got {threads!r}")
    if not seconds > 0:
        raise ValueError(f"seconds: expected more than 0, got {seconds!r}")
    calls = [0] * threads
    errors: list[BaseException] = []

    def work(k: int, stop_at: float) -> None:
        i, done = k, 0
        try:
            while time.perf_counter() < stop_at and not errors:
                task(i)
                i += threads
                done += 1
        except BaseException as e:  # handed to the caller
            errors.append(e)
        calls[k] = done

    c0, t0 = time.process_time(), time.perf_counter()
    workers = [threading.Thread(target=work, args=(k, t0 + seconds)) for k in range(threads)]
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    if errors:
        raise errors[0]
    return SteadyRun(tuple(calls), wall, cpu)
