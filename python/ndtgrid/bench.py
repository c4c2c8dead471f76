"""How fast the installed library runs on this machine: ``ndtgrid bench``.

The scans are simulated (the paper's sticks room seen by a URG-04LX, 683 beams, from
:mod:`ndtgrid.sim`), so neither data nor another library is needed, and every number
comes with a check that the work was done right: matches must recover the true pose,
and the odometry's error against the simulator's truth is reported beside its speed.

What is timed (wall clock, :func:`time.perf_counter_ns`, Python's call overhead
included; one call at a time on the calling thread unless said otherwise):

- ``insert``: :meth:`ndtgrid.NdtGrid.insert` of each scan at its true pose into a 2 cm map
  that holds the scans before it. As in a SLAM loop, the map's distributions are prepared
  (by an untimed :meth:`~ndtgrid.NdtGrid.match` before each insert), so each insert also
  keeps them up to date.
- ``insert_many``: the same scans into a second map, :data:`INSERT_BATCH` at a time by
  :meth:`ndtgrid.NdtGrid.insert_many` (each batch's first scan matched first, untimed),
  per scan; the row checks that this map equals the first one bit for bit.
- ``match``: :meth:`ndtgrid.NdtGrid.match` of each scan against the finished map, from its
  true pose moved by 3 cm, -2 cm and 1 degree.
- ``match_many``: the same matches in one :meth:`~ndtgrid.NdtGrid.match_many` call, on one
  thread and then on every core.
- ``match, N Python threads``: the same matches by one, then two Python threads started
  together, each calling :meth:`~ndtgrid.NdtGrid.match` for every other scan (the GIL is
  released during a match); on Linux with two CPUs to run on, also by two threads each
  pinned to its own CPU (``os.sched_setaffinity``), as the README advises for matching
  threads.
- ``odometry``: :meth:`ndtgrid.Odometry.step` over the scans with drifting odometry, the
  whole SLAM front end (matching, its own grid's upkeep, and the §V map on a helper
  thread, waited for at the end).

The project's own benchmarks, with peer libraries and real logs, are
``benches/speed.py`` and ``cargo bench`` in the source tree (``BENCHMARK.md``).
"""

from __future__ import annotations

import math
import os
import platform
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import asdict, dataclass, field
from functools import partial
from typing import Any

import numpy as np
import numpy.typing as npt

from ndtgrid import __version__, se2, sim
from ndtgrid._core import NdtGrid, ranges_to_points, vector_extension
from ndtgrid.evaluation import anchored_errors, pose_error
from ndtgrid.odometry import Odometry

__all__ = [
    "MIN_SCANS",
    "BenchReport",
    "BenchRow",
    "kernels_name",
    "max_scans",
    "pinnable_cpus",
    "processor_name",
    "run_bench",
]

F64 = npt.NDArray[np.float64]

#: Fewest scans a run takes: enough for medians and a map that holds several scans.
MIN_SCANS = 20
#: Cell size of every grid of the run [m] (the paper's 2 cm).
CELL_SIZE = 0.02
#: How far each match's guess is from the true pose: x, y [m], theta [rad].
GUESS_OFFSET = (0.03, -0.02, math.radians(1.0))
#: A match recovered the pose when it ends this close to the truth: [m], [rad].
RECOVERED = (0.01, math.radians(0.2))
#: Drift of the simulated odometry the odometry loop is given (fraction of the motion).
ODOMETRY_DRIFT = 0.02
#: Inserts before the timed ones (the map first holds a few scans).
UNTIMED_INSERTS = 10
#: Scans per :meth:`~ndtgrid.NdtGrid.insert_many` call of the ``insert_many`` row.
INSERT_BATCH = 16
#: The row of two Python threads, each pinned to its own CPU.
PINNED_ROW = "match, 2 Python threads, pinned"


@dataclass(frozen=True)
class BenchRow:
    """One timed operation of :func:`run_bench`.

    Attributes
    ----------
    name : str
        What was timed (``"insert"``, ``"match"``, ...).
    unit : str
        Unit of ``median`` and ``p90`` (``"ms"`` or ``"µs"`` per call).
    median : float
        Median time of a call, in ``unit`` (for a batch timed as a whole: its time over
        ``calls``).
    p90 : float or None
        90th percentile of the calls' times, in ``unit``; ``None`` for a batch.
    calls : int
        Calls (or scans of a batch) timed.
    note : str
        What the run checked or counted alongside (e.g. how many poses were recovered).
    """

    name: str
    unit: str
    median: float
    p90: float | None
    calls: int
    note: str


@dataclass(frozen=True)
class BenchReport:
    """The result of :func:`run_bench`.

    Attributes
    ----------
    rows : tuple of BenchRow
        The timed operations, in the order run.
    scans : int
        Simulated scans the run used.
    points : int
        Median points per scan (of the URG-04LX's 683 beams, those that hit a wall within
        its 4 m range).
    matches_recovered : int
        Matches that ended within 1 cm and 0.2 degrees of the true pose.
    odometry_rms_error : float
        RMS position error of the odometry's poses against the simulator's truth [m].
    map_cells : int
        Occupied cells of the matched map.
    map_bytes_per_cell : float
        :meth:`ndtgrid.NdtGrid.memory_bytes` of that map over its cells.
    machine : dict of str to str
        ``processor`` (:func:`processor_name`), ``kernels`` (:func:`kernels_name`),
        ``cores``, ``python``, ``ndtgrid`` and ``platform``.
    """

    rows: tuple[BenchRow, ...]
    scans: int
    points: int
    matches_recovered: int
    odometry_rms_error: float
    map_cells: int
    map_bytes_per_cell: float
    machine: dict[str, str] = field(default_factory=dict)

    def speedup(self, first: str, other: str) -> float:
        """How many times faster row ``other`` ran than row ``first`` (ratio of their
        medians).

        Parameters
        ----------
        first, other : str
            Row names (:attr:`BenchRow.name`).

        Returns
        -------
        float
            ``first``'s median time over ``other``'s.

        Raises
        ------
        KeyError
            If the report has no row of either name.
        """
        rows = {r.name: r for r in self.rows}
        return rows[first].median / rows[other].median

    @property
    def match_many_speedup(self) -> float:
        """Scans per second of one ``match_many`` call on every core over one on one
        thread (median rounds)."""
        return self.speedup("match_many, one thread", "match_many, every core")

    @property
    def python_threads_speedup(self) -> float:
        """Scans per second of two Python threads calling ``match`` over one such thread
        (median rounds)."""
        return self.speedup("match, 1 Python thread", "match, 2 Python threads")

    @property
    def pinned_threads_speedup(self) -> float | None:
        """Scans per second of two Python threads calling ``match``, each pinned to its
        own CPU, over one thread (median rounds); ``None`` where threads could not be
        pinned (not Linux, or fewer than two CPUs to run on)."""
        if not any(r.name == PINNED_ROW for r in self.rows):
            return None
        return self.speedup("match, 1 Python thread", PINNED_ROW)

    def as_dict(self) -> dict[str, Any]:
        """The report as plain values (for JSON).

        Returns
        -------
        dict
            Every attribute (``rows`` as a list of dicts), and the speed-ups
            ``match_many_speedup``, ``python_threads_speedup`` and
            ``pinned_threads_speedup`` (``None`` when not measured).
        """
        return {
            **asdict(self),
            "match_many_speedup": self.match_many_speedup,
            "python_threads_speedup": self.python_threads_speedup,
            "pinned_threads_speedup": self.pinned_threads_speedup,
        }

    def table(self) -> str:
        """The report as a Markdown table with a heading line.

        Returns
        -------
        str
            A line naming the machine and scans, then one table row per operation.
        """
        m = self.machine
        lines = [
            f"ndtgrid {m.get('ndtgrid', '?')} on {m.get('cores', '?')} cores of "
            f"{m.get('processor', '?')}, {m.get('kernels', '?')}, "
            f"Python {m.get('python', '?')}: "
            f"{self.scans} simulated URG-04LX scans of {self.points} points, "
            f"2 cm cells ({self.map_cells} cells, {self.map_bytes_per_cell:.0f} B / cell).",
            "",
            "| operation | median | p90 | calls | checked |",
            "|---|---:|---:|---:|---|",
        ]
        for r in self.rows:
            p90 = "-" if r.p90 is None else f"{r.p90:.3f} {r.unit}"
            lines.append(f"| {r.name} | {r.median:.3f} {r.unit} | {p90} | {r.calls} | {r.note} |")
        return "\n".join(lines)


def max_scans() -> int:
    """The most scans :func:`run_bench` can take: the poses of the simulated tour.

    Returns
    -------
    int
        Poses of the sticks room's tour at 2 cm per scan.
    """
    return len(_tour(sim.sticks_room()))


def _tour(room: sim.World) -> F64:
    """The simulated robot's true poses (``room``'s tour, 2 cm per scan)."""
    return sim.trajectory(room.tour)


#: Fields of ``/proc/cpuinfo`` that tell processors of one model name apart, with the
#: label each gets: x86's family, model and stepping, ARM's implementer, part, variant
#: and revision.
_CPU_IDS = (
    ("family", "cpu family"),
    ("model", "model"),
    ("stepping", "stepping"),
    ("implementer", "CPU implementer"),
    ("part", "CPU part"),
    ("variant", "CPU variant"),
    ("revision", "CPU revision"),
)


def processor_name(cpuinfo: str | None = None) -> str:
    """The processor, named so that two machines under one model name can be told apart.

    A virtual machine's ``model name`` can be as vague as ``AMD EPYC`` for several
    generations of processor, which ran the same code up to twice as fast as each other
    (``benches/SPEED_LOG.md``, session 34), and an ARM board's ``/proc/cpuinfo`` often
    has no model name at all. So the processor's identifiers follow the name (x86:
    family, model, stepping; ARM: implementer, part, variant, revision). The build of
    the core's kernels that runs is :func:`ndtgrid._core.vector_extension`.

    Parameters
    ----------
    cpuinfo : str, optional
        The text of ``/proc/cpuinfo`` (its first processor is read); read from the
        file when not given.

    Returns
    -------
    str
        For example ``"AMD EPYC (family 25, model 17, stepping 1)"``. The fields the
        text lacks are left out; without a model name (ARM, or not Linux) the name is
        :func:`platform.processor` or :func:`platform.machine`.
    """
    if cpuinfo is None:
        try:
            with open("/proc/cpuinfo", encoding="utf-8") as f:
                cpuinfo = f.read()
        except OSError:
            cpuinfo = ""
    fields: dict[str, str] = {}
    for line in cpuinfo.splitlines():
        if not line.strip():
            if fields:
                break  # the first processor's block only
            continue
        key, _, value = line.partition(":")
        fields.setdefault(key.strip(), value.strip())
    name = fields.get("model name") or platform.processor() or platform.machine()
    ids = ", ".join(f"{label} {fields[key]}" for label, key in _CPU_IDS if fields.get(key))
    return f"{name} ({ids})" if ids else name


def kernels_name() -> str:
    """The build of the core's kernels that runs here, for a report's machine line.

    Returns
    -------
    str
        ``"AVX-512 kernels"``, ``"AVX2 kernels"``, ``"NEON kernels"`` or ``"generic
        kernels"`` (:func:`ndtgrid._core.vector_extension`).
    """
    return f"{vector_extension() or 'generic'} kernels"


def _machine() -> dict[str, str]:
    """Processor, kernels, cores, Python and ndtgrid versions of this machine."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    return {
        "processor": processor_name(),
        "kernels": kernels_name(),
        "cores": str(cores),
        "python": platform.python_version(),
        "ndtgrid": __version__,
        "platform": platform.platform(),
    }


def _row(name: str, unit: str, times_ns: list[int], note: str) -> BenchRow:
    """A row from per-call times in nanoseconds, shown in ``unit``."""
    scale = {"ms": 1e-6, "µs": 1e-3}[unit]
    t = np.asarray(times_ns, dtype=np.float64) * scale
    return BenchRow(name, unit, float(np.median(t)), float(np.percentile(t, 90)), len(t), note)


def _batches(timers: dict[str, Callable[[], int]], repeats: int) -> dict[str, list[int]]:
    """Each timer's nanoseconds over ``repeats`` rounds, the timers taking turns in each
    round (so a slow spell of the machine falls on all of them)."""
    runs: dict[str, list[int]] = {label: [] for label in timers}
    for _ in range(repeats):
        for label, timer in timers.items():
            runs[label].append(timer())
    return runs


def _batch_rows(name: str, runs: dict[str, list[int]], scans: int) -> list[BenchRow]:
    """Rows of batches of ``scans`` scans timed as a whole (``label: ns per run``): the
    median run per scan; the first label is the baseline of the others' speed-ups (the
    ratio of the medians, and its range over the rounds)."""
    first, base = next(iter(runs.items()))
    base_ms = float(np.median(base)) / scans * 1e-6
    rows = []
    for k, (label, ns) in enumerate(runs.items()):
        ms = float(np.median(ns)) / scans * 1e-6
        note = f"{1e3 / ms:.0f} scans / s, median of {len(ns)} runs"
        if k:
            ratios = np.divide(base, ns)
            note += (
                f"; {base_ms / ms:.2f} x {first} "
                f"({ratios.min():.2f} to {ratios.max():.2f} by round)"
            )
        rows.append(BenchRow(f"{name}, {label}", "ms", ms, None, scans, note))
    return rows


def pinnable_cpus(n: int) -> list[int] | None:
    """The CPUs to pin ``n`` threads to, one each.

    Parameters
    ----------
    n : int
        Threads to pin.

    Returns
    -------
    list of int or None
        The first ``n`` CPUs this process may run on, or ``None`` where threads cannot be
        pinned (no ``os.sched_setaffinity``: not Linux) or fewer than ``n`` are allowed.
    """
    if not hasattr(os, "sched_setaffinity"):
        return None
    cpus = sorted(os.sched_getaffinity(0))
    return cpus[:n] if len(cpus) >= n else None


def _threads_ns(
    grid: NdtGrid,
    points: list[F64],
    guesses: F64,
    threads: int,
    cpus: list[int] | None = None,
) -> int:
    """Nanoseconds ``threads`` Python threads, started together, take to match every scan
    (scan ``i`` on thread ``i mod threads``), one :meth:`~ndtgrid.NdtGrid.match` call
    after the other; the clock runs from their start to the last one's end. With
    ``cpus``, thread ``k`` first pins itself to CPU ``cpus[k]``.

    Raises
    ------
    RuntimeError
        If a thread could not be pinned (no match is timed then).
    """
    start = threading.Barrier(threads + 1)
    failed: list[str] = []

    def work(k: int) -> None:
        if cpus is not None:
            try:
                os.sched_setaffinity(0, {cpus[k]})
            except OSError as e:
                failed.append(f"could not pin a thread to CPU {cpus[k]}: {e}")
        start.wait()
        if failed:
            return
        for i in range(k, len(points), threads):
            grid.match(points[i], guesses[i])

    workers = [threading.Thread(target=work, args=(k,)) for k in range(threads)]
    for w in workers:
        w.start()
    start.wait()
    t0 = time.perf_counter_ns()
    for w in workers:
        w.join()
    if failed:
        raise RuntimeError(failed[0])
    return time.perf_counter_ns() - t0


def _guesses(truth: F64) -> F64:
    """Each true pose moved by :data:`GUESS_OFFSET` in its own frame (``pose o offset``)."""
    return np.array([se2.compose(t, GUESS_OFFSET) for t in truth], dtype=np.float64)


def run_bench(
    scans: int | None = None,
    *,
    seed: int = 0,
    repeats: int = 5,
    progress: Callable[[Iterable[Any], str, int], Iterator[Any]] | None = None,
) -> BenchReport:
    """Time insert (one scan a call, and batches by ``insert_many``), match (alone, by
    ``match_many`` and from Python threads) and the odometry loop on simulated scans.

    Parameters
    ----------
    scans : int, optional
        Simulated scans, from :data:`MIN_SCANS` to :func:`max_scans` (the default: the
        whole tour). A run takes about 5 ms per scan on a 2-core VM, most of it
        simulating the laser.
    seed : int, default 0
        Seed of the laser's noise and the odometry's drift.
    repeats : int, default 5
        Rounds of the batches timed as a whole (``match_many`` and the Python threads),
        which take turns in each round; their rows give the median round. At least 1.
    progress : callable, optional
        ``progress(items, label, total)`` wraps the simulation's loop over the scans (the run's
        longest part), e.g. to draw a progress bar; it must yield the items in order. The
        timed loops run without it, so that no drawing falls between the timed calls.

    Returns
    -------
    BenchReport
        The timings and what was checked.

    Raises
    ------
    ValueError
        If ``scans`` or ``repeats`` is out of range.
    RuntimeError
        If a thread of the pinned row could not be pinned to its CPU (the CPUs this
        process may run on changed during the run).
    """
    room = sim.sticks_room()
    tour = _tour(room)
    most = len(tour)
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise ValueError(f"repeats: expected an integer >= 1, got {repeats!r}")
    if scans is None:
        scans = most
    if isinstance(scans, bool) or not isinstance(scans, int) or not MIN_SCANS <= scans <= most:
        raise ValueError(
            f"scans: expected an integer from {MIN_SCANS} to {most} (the simulated tour's "
            f"poses), got {scans!r}"
        )

    truth = tour[:scans]
    stream: Iterable[F64] = sim.scan_ranges(room, sim.URG04LX, truth, seed=seed)
    if progress is not None:
        stream = progress(stream, "simulating", scans)
    ranges = np.array(list(stream))
    angles = sim.URG04LX.angles
    points = [ranges_to_points(r, angles) for r in ranges]
    rows: list[BenchRow] = []

    grid = NdtGrid(CELL_SIZE)
    insert_ns: list[int] = []
    for i in range(scans):
        if i > 0:
            grid.match(points[i], truth[i])  # untimed: prepares the distributions
        t0 = time.perf_counter_ns()
        grid.insert(points[i], truth[i])
        dt = time.perf_counter_ns() - t0
        if i >= min(UNTIMED_INSERTS, scans // 2):
            insert_ns.append(dt)
    rows.append(_row("insert", "µs", insert_ns, f"map of up to {scans} scans"))

    batched = NdtGrid(CELL_SIZE)
    per_scan_ns: list[int] = []
    for start in range(0, scans, INSERT_BATCH):
        stop = min(start + INSERT_BATCH, scans)
        if start > 0:
            batched.match(points[start], truth[start])  # untimed, as above
        t0 = time.perf_counter_ns()
        batched.insert_many(points[start:stop], truth[start:stop])
        per_scan_ns.append((time.perf_counter_ns() - t0) // (stop - start))
    same = [a.tobytes() for a in batched.cell_states()] == [a.tobytes() for a in grid.cell_states()]
    rows.append(
        _row(
            f"insert_many, batches of {INSERT_BATCH}",
            "µs",
            per_scan_ns,
            f"per scan, one call per batch; the map {'equals' if same else 'DIFFERS FROM'} "
            "insert's, bit for bit",
        )
    )

    guesses = _guesses(truth)
    match_ns: list[int] = []
    recovered = 0
    for i in range(scans):
        t0 = time.perf_counter_ns()
        res = grid.match(points[i], guesses[i])
        match_ns.append(time.perf_counter_ns() - t0)
        err_t, err_r = pose_error(res.pose, truth[i])
        recovered += err_t <= RECOVERED[0] and err_r <= RECOVERED[1]
    rows.append(
        _row(
            "match",
            "ms",
            match_ns,
            f"{recovered} of {scans} within 1 cm and 0.2° of the truth",
        )
    )

    def many(threads: int | None) -> Callable[[], int]:
        def run() -> int:
            t0 = time.perf_counter_ns()
            grid.match_many(points, guesses, threads=threads)
            return time.perf_counter_ns() - t0

        return run

    many_runs = _batches({"one thread": many(1), "every core": many(None)}, repeats)
    rows += _batch_rows("match_many", many_runs, scans)
    python_timers: dict[str, Callable[[], int]] = {
        f"{n} Python thread{'s' if n > 1 else ''}": partial(_threads_ns, grid, points, guesses, n)
        for n in (1, 2)
    }
    cpus = pinnable_cpus(2)
    if cpus is not None:
        python_timers[PINNED_ROW.removeprefix("match, ")] = partial(
            _threads_ns, grid, points, guesses, 2, cpus
        )
    python_runs = _batches(python_timers, repeats)
    rows += _batch_rows("match", python_runs, scans)

    odometry = sim.odometry(truth, drift=ODOMETRY_DRIFT, seed=seed)
    odo = Odometry(cell_size=CELL_SIZE)
    step_ns: list[int] = []
    start = time.perf_counter_ns()
    for i in range(scans):
        t0 = time.perf_counter_ns()
        odo.step(ranges[i], angles, odometry[i])
        step_ns.append(time.perf_counter_ns() - t0)
    _ = odo.mapper  # waits for the helper thread to take in the last scans
    total = (time.perf_counter_ns() - start) * 1e-9
    rms = float(np.sqrt(np.mean(np.square(anchored_errors(odo.poses, truth)))))
    rows.append(
        _row(
            "odometry step",
            "ms",
            step_ns,
            f"{1e3 * total / scans:.3f} ms / scan with the map's helper; "
            f"{100 * rms:.2f} cm RMS from the truth",
        )
    )

    return BenchReport(
        rows=tuple(rows),
        scans=scans,
        points=int(np.median([len(p) for p in points])),
        matches_recovered=recovered,
        odometry_rms_error=rms,
        map_cells=len(grid),
        map_bytes_per_cell=grid.memory_bytes / max(len(grid), 1),
        machine=_machine(),
    )
