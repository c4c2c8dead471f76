"""``benches/speed.py``'s sweep over scan points times its beam counts in turn, so a
spell of the machine cannot fall on one count alone."""

from __future__ import annotations

import argparse
import types
from typing import Any

import numpy as np
import pytest

from ._benches import load_bench

speed = load_bench("speed")


def test_the_points_sweep_times_the_beam_counts_in_turn(monkeypatch: pytest.MonkeyPatch) -> None:
    real = speed.ndtgrid
    sizes: list[int] = []

    class Recording:
        """``NdtGrid`` that notes the size of each scan it matches."""

        def __init__(self, *args: Any) -> None:
            self.grid = real.NdtGrid(*args)

        def insert(self, *args: Any) -> None:
            self.grid.insert(*args)

        def match(self, points: np.ndarray, guess: np.ndarray) -> Any:
            sizes.append(len(points))
            return self.grid.match(points, guess)

    shim = types.ModuleType("ndtgrid_recording")
    shim.__dict__.update(real.__dict__, NdtGrid=Recording)
    monkeypatch.setattr(speed, "ndtgrid", shim)
    beams, maps, starts = [100, 400, 1000], 2, 3
    args = argparse.Namespace(seed=0, sweep_points=beams, sweep_maps=maps, starts=starts)
    rows = speed.points_sweep(args)

    assert [r["beams"] for r in rows] == beams
    # Each map: one match to build its distributions; then, map by map, one warm-up
    # match per beam count and the timed matches, every count once per start.
    assert len(sizes) == maps + maps * (len(beams) + starts * len(beams))
    blocks = sizes[maps:]
    per_map = len(beams) + starts * len(beams)
    scans = []
    for m in range(maps):
        block = blocks[m * per_map : (m + 1) * per_map]
        warm, timed = block[: len(beams)], block[len(beams) :]
        assert warm == sorted(warm) and len(set(warm)) == len(beams)
        assert timed == warm * starts
        scans.append(warm)
    # Each row's points: the mean size of its count's scans over the maps.
    assert [r["points"] for r in rows] == pytest.approx(np.mean(scans, axis=0).tolist())
    assert all(r["median"] > 0 and r["iterations"] >= 1 for r in rows)
