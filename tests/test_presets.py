"""The match presets are what they say they are."""

from __future__ import annotations

import numpy as np

import ndtgrid
from ndtgrid._core import default_match_options, default_odometry_config
from ndtgrid.presets import ORIGINAL_NDT, PAPER, SCAN_TO_MAP


def test_scan_to_map_is_the_odometry_loops_matcher() -> None:
    loop = default_odometry_config()
    assert SCAN_TO_MAP == {"sigma_floor": 0.005, "shape_cell": 0.0, "freeze_ratio": 0.02}
    for name, value in SCAN_TO_MAP.items():
        assert loop[name] == value, name
    # ... and differs from the scan-to-scan default in each of its settings.
    default = default_match_options()
    assert all(default[name] != value for name, value in SCAN_TO_MAP.items())


def test_presets_are_accepted_and_change_the_match() -> None:
    rng = np.random.default_rng(3)
    t = rng.uniform(0.0, 2.0 * np.pi, 600)
    room = np.c_[2.0 * np.cos(t), 1.2 * np.sin(t)] + rng.normal(0.0, 0.005, (600, 2))
    grid = ndtgrid.NdtGrid(0.02)
    grid.insert(room, [0.0, 0.0, 0.0])
    guess = np.array([0.03, -0.02, 0.02])
    poses = {
        name: grid.match(room, guess, **preset).pose
        for name, preset in [
            ("default", {}),
            ("paper", PAPER),
            ("biber", ORIGINAL_NDT),
            ("scan_to_map", SCAN_TO_MAP),
        ]
    }
    assert not np.array_equal(poses["default"], poses["scan_to_map"])
    assert not np.array_equal(poses["paper"], poses["biber"])


def test_paper_presets_equal_the_cores() -> None:
    from ndtgrid._core import preset_match_options

    default = default_match_options()
    assert sorted(PAPER) == [
        "freeze_unconstrained",
        "levels",
        "rotation_search",
        "search_radius",
        "shape_cell",
        "sigma_floor",
    ]
    assert set(ORIGINAL_NDT) == {*PAPER, "expansion", "neighbor_search", "fuse_minority"}
    assert {**default, **PAPER} == preset_match_options("paper")
    assert {**default, **ORIGINAL_NDT} == preset_match_options("original_ndt")
