"""Match scans on two cores from Python threads, each pinned to its own core.

``NdtGrid.match`` releases the GIL while the core works, so two threads matching
different scans against one map run in parallel. On Linux, pin each worker thread to
its own core: some kernels (this project's VM, BENCHMARK.md "Speed", session 29) wake a
thread on the core of the busy thread that woke it, and the two then take turns on one
core for milliseconds. ``os.sched_setaffinity(0, ...)`` in a thread pins that thread
only; a ``ThreadPoolExecutor`` initializer runs once in each worker.

Runnable as is (simulated URG-04LX scans of the paper's sticks room, no data needed);
prints the matches per second of one thread and of two pinned workers, and checks that
both give the same poses, bit for bit. The gain is what the two cores have free: on this
project's 2-vCPU VM, 1.4-1.5x in a phase in which the VM gave GIL-free work (SHA-256)
1.5x, and 1.59-2.00x over thirteen runs of ``benches/speed.py``'s thread section.
"""

import itertools
import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import ndtgrid
from ndtgrid import sim

# A map of the simulated room from 100 scans at their true poses.
room = sim.sticks_room()
truth = sim.trajectory(room.tour, step=0.05)
ranges, angles = sim.simulate(room, sim.URG04LX, truth, seed=1)
scans = [ndtgrid.ranges_to_points(r, angles, max_range=sim.URG04LX.max_range) for r in ranges]
grid = ndtgrid.NdtGrid(cell_size=0.02)
for points, pose in zip(scans[:100], truth[:100]):
    grid.insert(points, pose)

# Every scan matched from 3 cm / 1 degree off its true pose.
rng = np.random.default_rng(0)
offsets = rng.normal(0.0, [0.03, 0.03, np.radians(1.0)], (len(scans), 3))
jobs = [(points, pose + d) for points, pose, d in zip(scans, truth, offsets)]
grid.match(*jobs[0])  # the first match builds the distributions


def match_all(part: list[tuple[np.ndarray, np.ndarray]]) -> list[np.ndarray]:
    """The poses of a list of (points, guess) jobs, matched on the calling thread."""
    return [grid.match(points, guess).pose for points, guess in part]


# One worker thread per allowed CPU, each pinned to its own (where the OS allows it).
cpus = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
workers = min(2, len(cpus)) or 1
next_cpu = itertools.count()
lock = threading.Lock()
pinned: list[list[int]] = []


def pin() -> None:
    """ThreadPoolExecutor initializer: pins the calling worker thread to the next CPU."""
    if len(cpus) >= 2:
        with lock:
            cpu = cpus[next(next_cpu) % len(cpus)]
        os.sched_setaffinity(0, {cpu})  # 0: this thread only
        with lock:
            pinned.append(sorted(os.sched_getaffinity(0)))


t0 = time.perf_counter()
one = match_all(jobs)
t_one = time.perf_counter() - t0

with ThreadPoolExecutor(max_workers=workers, initializer=pin) as pool:
    # Start the workers (and pin them) before the clock starts: each waits for the
    # other, so the pool must start them all.
    ready = threading.Barrier(workers)
    list(pool.map(lambda _: ready.wait(), range(workers)))
    assert len(pinned) == (workers if len(cpus) >= 2 else 0)
    t0 = time.perf_counter()
    halves = [pool.submit(match_all, jobs[i::workers]) for i in range(workers)]
    parts = [h.result() for h in halves]
    t_two = time.perf_counter() - t0

two: list[np.ndarray] = [np.empty(0)] * len(jobs)
for i, part in enumerate(parts):
    two[i::workers] = part
same = all(np.array_equal(a, b) for a, b in zip(one, two))
print(f"{len(jobs)} scans, map of {len(grid)} cells; worker CPUs: {sorted(pinned)}")
print(f"one thread: {len(jobs) / t_one:.0f} matches/s")
print(f"{workers} pinned workers: {len(jobs) / t_two:.0f} matches/s ({t_one / t_two:.2f}x)")
print(f"same poses: {same}")
