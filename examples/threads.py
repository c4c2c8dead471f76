"""Match scans on two cores: from Python threads pinned to their cores, or in one call.

``NdtGrid.match`` releases the GIL while the core works, so two threads matching
different scans against one map run in parallel. On Linux, pin each worker thread to
its own core: some kernels (this project's VM, benches/SPEED_LOG.md, session 29) wake a
thread on the core of the busy thread that woke it, and the two then take turns on one
core for milliseconds. ``os.sched_setaffinity(0, ...)`` in a thread pins that thread
only; a ``ThreadPoolExecutor`` initializer runs once in each worker.

With the scans at hand as a batch, no threads of your own are needed:
``grid.match_many(scans, guesses)`` matches them on every core in one call (the calling
thread and helpers started for the batch, which the kernel places on idle cores), each
result bit for bit that of its own ``match``.

Runnable as is (simulated URG-04LX scans of the paper's sticks room, no data needed);
prints the matches per second of one thread, of two pinned workers and of one
``match_many`` call, and checks that all give the same poses, bit for bit. The gain is
what the two cores have free: on this project's 2-vCPU VM, pinned workers gave 1.4-1.5x
in a phase in which the VM gave GIL-free work (SHA-256) 1.5x, and 1.59-2.00x over
thirteen runs of ``benches/speed.py``'s thread section (benches/SPEED_LOG.md, session
29; ``match_many`` in session 30).
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

# The same scans in one call, on every core.
t0 = time.perf_counter()
batch = grid.match_many([points for points, _ in jobs], np.array([g for _, g in jobs]))
t_many = time.perf_counter() - t0

same = all(np.array_equal(a, b) and np.array_equal(a, r.pose) for a, b, r in zip(one, two, batch))
print(f"{len(jobs)} scans, map of {len(grid)} cells; worker CPUs: {sorted(pinned)}")
print(f"one thread: {len(jobs) / t_one:.0f} matches/s")
print(f"{workers} pinned workers: {len(jobs) / t_two:.0f} matches/s ({t_one / t_two:.2f}x)")
print(f"one match_many call: {len(jobs) / t_many:.0f} matches/s ({t_one / t_many:.2f}x)")
print(f"same poses: {same}")
