"""Long-lived Python worker threads, each pinned to its own core, run by run.

For the thread section of ``benches/speed.py``. On this project's VM the kernel places a
thread woken by a busy thread on the waker's own vCPU, even with the other vCPU idle
(``sched_switch`` / ``sched_wakeup`` traces in benches/SPEED_LOG.md, session 29): the
second of two matching threads then waits there for the scheduler tick (4 ms at
``CONFIG_HZ=250``) or shares that vCPU for a while. A thread pinned to its own core
cannot be placed on the other's, which is what a program that wants two cores' worth of
matching does with its worker threads on Linux (``os.sched_setaffinity(0, {cpu})`` in
each worker; 0 is the calling thread).

Each worker pins itself once, then waits at a barrier; :meth:`PinnedWorkers.run` hands
every worker its task (or none), lets them go together and returns when all are done.
"""

from __future__ import annotations

import ctypes
import os
import threading
from collections.abc import Callable, Sequence
from types import TracebackType
from typing import cast

from ndtgrid.bench import pinnable_cpus

Task = Callable[[], None]


def two_cpus() -> list[int] | None:
    """The first two CPUs this process may run on, or ``None`` where threads cannot be
    pinned (no ``os.sched_setaffinity``: not Linux) or fewer than two are allowed
    (:func:`ndtgrid.bench.pinnable_cpus`, which ``ndtgrid bench`` pins its threads by)."""
    return pinnable_cpus(2)


def _libc_sched_getcpu() -> Callable[[], int] | None:
    """glibc's ``sched_getcpu`` through :class:`ctypes.PyDLL`, which keeps the GIL over
    the call (:class:`ctypes.CDLL` would let it go and invite a hand-over to another
    thread), or ``None`` where the C library has no such function."""
    try:
        fn = ctypes.PyDLL(None).sched_getcpu
    except (OSError, AttributeError, TypeError):  # TypeError: no PyDLL(None) on Windows
        return None
    fn.restype = ctypes.c_int
    fn.argtypes = []
    return cast(Callable[[], int], fn)


_SCHED_GETCPU = _libc_sched_getcpu()


def current_cpu() -> int | None:
    """The CPU the calling thread is running on, or ``None`` where that cannot be read.

    glibc's ``sched_getcpu`` (no system call on x86-64 Linux: about 0.1 µs from Python), or
    else field 39 (``processor``) of ``/proc/self/task/<tid>/stat`` (about 14 µs); read by
    the thread itself, it is the CPU the thread runs on at that moment. The thread
    section of ``benches/speed.py`` reads it per thread at the first match and half-way
    through each two-thread run, to tell runs in which the kernel had both threads on
    one vCPU.
    """
    if _SCHED_GETCPU is not None:
        cpu = _SCHED_GETCPU()
        if cpu >= 0:
            return cpu
    try:
        with open(f"/proc/self/task/{threading.get_native_id()}/stat") as f:
            stat = f.read()
    except OSError:
        return None
    # Field 2, the command, is in parentheses and may hold spaces or ")": the fields
    # after the last ")" are 3, 4, ..., so field 39 is the 37th of them.
    fields = stat.rsplit(")", 1)[-1].split()
    return int(fields[36]) if len(fields) > 36 else None


class PinnedWorkers:
    """One thread per CPU of ``cpus``, each pinned to it, started at once and kept until
    :meth:`close` (or the end of a ``with`` block).

    Parameters
    ----------
    cpus : sequence of int
        The CPU of each worker (distinct, allowed for this process).
    """

    def __init__(self, cpus: Sequence[int]) -> None:
        self._cpus = list(cpus)
        n = len(self._cpus)
        self._go = threading.Barrier(n + 1)
        self._done = threading.Barrier(n + 1)
        self._tasks: list[Task | None] = [None] * n
        self._errors: list[BaseException] = []
        self._stop = False
        self._threads = [
            threading.Thread(target=self._loop, args=(i,), daemon=True) for i in range(n)
        ]
        for t in self._threads:
            t.start()
        # The first round only checks that every worker pinned itself.
        try:
            self.run([None] * n)
        except BaseException:
            self.close()
            raise

    def _loop(self, i: int) -> None:
        try:
            os.sched_setaffinity(0, {self._cpus[i]})
        except OSError as e:
            self._errors.append(e)
        while True:
            self._go.wait()
            if self._stop:
                return
            task = self._tasks[i]
            if task is not None:
                try:
                    task()
                except BaseException as e:  # handed to the caller of run()
                    self._errors.append(e)
            self._done.wait()

    def run(self, tasks: Sequence[Task | None]) -> None:
        """Runs ``tasks[i]`` on worker ``i`` (``None``: that worker sits this round
        out), all let go at once; returns when every worker is done.

        Raises
        ------
        ValueError
            If ``tasks`` does not have one entry per worker.
        Exception
            The first exception a task (or a worker's pinning) raised.
        """
        if len(tasks) != len(self._threads):
            raise ValueError(f"{len(tasks)} tasks for {len(self._threads)} workers")
        self._tasks = list(tasks)
        self._go.wait()
        self._done.wait()
        if self._errors:
            err, self._errors = self._errors[0], []
            raise err

    def close(self) -> None:
        """Lets the workers end and waits for them."""
        if self._stop:
            return
        self._stop = True
        self._go.wait()
        for t in self._threads:
            t.join()

    def __enter__(self) -> PinnedWorkers:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
