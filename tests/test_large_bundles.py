"""``benches/large_bundles.py``: two threads against one on bundles of Intel scans merged
into one, and the bundles themselves (``benches/speed.py``'s ``bundle_scans``, which its
thread section's control uses too)."""

from __future__ import annotations

import threading
from typing import Any

import numpy as np
import pytest

from ._benches import cells, load_bench
from ._data import require_real

large = load_bench("large_bundles")
speed = large.speed
TIMES, DASH = "\u00d7", "\u2013"  # the table's multiplication sign and its dash for "unread"


def scans(n: int, seed: int = 1) -> tuple[list[np.ndarray], np.ndarray]:
    """``n`` scans of random points seen from random poses."""
    rng = np.random.default_rng(seed)
    pts = [rng.uniform(-5.0, 5.0, (int(rng.integers(3, 9)), 2)) for _ in range(n)]
    poses = np.c_[rng.uniform(-10.0, 10.0, (n, 2)), rng.uniform(-np.pi, np.pi, n)]
    return pts, poses


def test_a_bundle_holds_its_scans_in_the_frame_of_the_middle_one() -> None:
    pts, poses = scans(11)
    bundles = speed.bundle_scans(pts, poses, 3, np.random.default_rng(0))
    assert len(bundles) == 3  # the last two scans make no whole bundle
    for b, (merged, start) in enumerate(bundles):
        first = 3 * b
        middle = poses[first + 1]
        world = np.vstack([speed.apply(poses[j], pts[j]) for j in range(first, first + 3)])
        np.testing.assert_allclose(speed.apply(middle, merged), world, atol=1e-9)
        assert np.all(np.abs(start[:2] - middle[:2]) <= 0.05)
        assert abs(start[2] - middle[2]) <= np.radians(2.0) + 1e-12


def test_bundles_draw_their_starts_from_the_generator_in_order() -> None:
    pts, poses = scans(8)
    a = speed.bundle_scans(pts, poses, 4, np.random.default_rng(5))
    rng = np.random.default_rng(5)
    for (_, start), k in zip(a, (2, 6)):
        np.testing.assert_array_equal(
            start, poses[k] + speed.convergence.starts(rng, 1, 0.05, 2.0)[0]
        )


@pytest.mark.parametrize("size", [0, -3])
def test_a_bundle_of_no_scans_is_refused(size: int) -> None:
    pts, poses = scans(4)
    with pytest.raises(ValueError, match=rf"^a bundle holds at least 1 scan, not {size}$"):
        speed.bundle_scans(pts, poses, size, np.random.default_rng(0))


def test_cases_put_sizes_first_and_leave_out_maps_smaller_than_a_bundle() -> None:
    assert large.cases([20, 80], [60, 910], 910) == [(20, 60), (20, 910), (80, 910)]


@pytest.mark.parametrize(
    ("sizes", "maps", "message"),
    [
        ([0], [60], r"^bundle sizes and maps must be at least 1 scan$"),
        ([20], [0], r"^bundle sizes and maps must be at least 1 scan$"),
        ([20], [911], r"^a map holds at most the log's 910 scans$"),
        ([80], [60], r"^no map holds a whole bundle: make a map at least as large as a bundle$"),
    ],
)
def test_cases_reject(sizes: list[int], maps: list[int], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        large.cases(sizes, maps, 910)


def test_repeated_goes_round_the_jobs() -> None:
    assert large.repeated(["a", "b", "c"], 7) == ["a", "b", "c", "a", "b", "c", "a"]


def run(wall: float, cpu: float, system: float = 0.0, tlb: int | None = 3) -> Any:
    return large.Run(wall=wall, cpu=cpu, system=system, shootdowns=tlb)


def test_summarise_takes_the_medians_of_the_rounds() -> None:
    rounds = [
        (run(2.0, 2.0, tlb=1), run(1.0, 2.2, 0.01, 5)),
        (run(3.0, 3.0, tlb=2), run(2.0, 3.3, 0.02, 7)),
        (run(1.8, 1.8, tlb=0), run(1.0, 1.8, 0.00, 6)),
    ]
    t = large.summarise(rounds)
    assert t.ratio == pytest.approx(1.8)  # of 2.0, 1.5 and 1.8
    assert t.cost == pytest.approx(1.1)  # of 1.1, 1.1 and 1.0
    assert t.system == pytest.approx(0.01)
    assert (t.shootdowns_two, t.shootdowns_one) == (6.0, 1.0)


def test_summarise_without_shootdowns() -> None:
    t = large.summarise([(run(1.0, 1.0, tlb=None), run(0.5, 1.0))])
    assert (t.shootdowns_two, t.shootdowns_one) == (3.0, None)


@pytest.mark.parametrize(
    ("rounds", "message"),
    [
        ([], r"^a turn needs at least one round$"),
        (
            [(run(0.0, 1.0), run(1.0, 1.0))],
            r"^a run took no wall or CPU time: give it more matches$",
        ),
        (
            [(run(1.0, 1.0), run(1.0, 0.0))],
            r"^a run took no wall or CPU time: give it more matches$",
        ),
    ],
)
def test_summarise_rejects(rounds: list[Any], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        large.summarise(rounds)


def test_a_row_gives_each_turns_medians_in_turn_order() -> None:
    turns = [large.Turn(1.756, 1.08, 0.0, 6.0, None), large.Turn(1.9, 1.014, 0.0012, 5.0, 2.0)]
    assert cells(large.row(20, 910, 3611.4, turns)) == [
        "map of 910 scans, bundles of 20 scans (about 3611 points)",
        f"1.76, 1.90{TIMES}",
        "1.08, 1.01",
        "0.000, 0.001",
        "6, 5",
        f"{DASH}, 2",
    ]
    assert len(cells(large.row(20, 910, 1.0, turns))) == len(cells(large.HEADER[0]))


class Recording:
    """A grid that notes the jobs it matched, from any thread, and fails on one."""

    def __init__(self, fail_on: int | None = None) -> None:
        self.seen: list[int] = []
        self.threads: set[str] = set()
        self.lock = threading.Lock()
        self.fail_on = fail_on

    def match(self, points: np.ndarray, start: np.ndarray) -> None:
        with self.lock:
            self.seen.append(int(points[0, 0]))
            self.threads.add(threading.current_thread().name)
        if int(points[0, 0]) == self.fail_on:
            raise RuntimeError(f"job {self.fail_on} failed")


def jobs(n: int) -> list[tuple[np.ndarray, np.ndarray]]:
    return [(np.full((1, 2), float(k)), np.zeros(3)) for k in range(n)]


def test_two_threads_match_every_job_once_on_two_threads() -> None:
    grid = Recording()
    large.two_threads(grid, jobs(9))
    assert sorted(grid.seen) == list(range(9))
    assert len(grid.threads) == 2 and threading.current_thread().name not in grid.threads


def test_two_threads_hand_a_threads_error_to_the_caller() -> None:
    with pytest.raises(RuntimeError, match=r"^job 5 failed$"):
        large.two_threads(Recording(fail_on=5), jobs(9))


def test_time_run_counts_the_work_and_its_cpu_time() -> None:
    done: list[int] = []
    r = large.time_run(lambda: done.append(sum(range(200_000))))
    assert done == [sum(range(200_000))]
    assert r.wall > 0.0 and r.cpu > 0.0 and r.system >= 0.0
    assert r.shootdowns is None or r.shootdowns >= 0


@pytest.mark.parametrize("name", ["turns", "rounds", "matches"])
def test_counts_below_one_are_refused(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        large.parse_args([f"--{name}", "0"])
    assert f"error: --{name} must be at least 1" in capsys.readouterr().err


def test_bad_cases_stop_with_the_reason() -> None:
    require_real("radish-gfs-corrected/intel-corrected.log.gz")
    with pytest.raises(SystemExit, match=r"^large_bundles.py: no map holds a whole bundle: "):
        large.main(["--sizes", "80", "--maps", "60"])


def test_a_small_run_prints_one_row_a_case(capsys: pytest.CaptureFixture[str]) -> None:
    require_real("radish-gfs-corrected/intel-corrected.log.gz")
    large.main(
        ["--sizes", "2", "3", "--maps", "6", "--turns", "2", "--rounds", "1", "--matches", "4"]
    )
    lines = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("| map of")]
    assert [cells(ln)[0].split(" (")[0] for ln in lines] == [
        "map of 6 scans, bundles of 2 scans",
        "map of 6 scans, bundles of 3 scans",
    ]
    for ln in lines:
        ratios = cells(ln)[1].rstrip(TIMES).split(", ")
        assert len(ratios) == 2 and all(float(r) > 0.0 for r in ratios)
