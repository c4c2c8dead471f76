"""The peers' picture of ``benches/speed.py`` (``benches/speed_plots.py``): which rows of
the match, map update and odometry tables it draws, and the file it writes."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from ._benches import load_bench

plots = load_bench("speed_plots")

# The results of speed.py's first three sections, in the shapes it returns them.
RESULTS: dict[str, dict[str, Any]] = {
    "match": {
        "sick": {
            "ours": 1.2e-4,
            "methods": [
                ("ndtgrid 2 cm, default match()", 1.2e-4, 0.73),
                ("small_gicp GICP (1.0→0.25 m)", 2.3e-3, 0.75),
                ("Open3D ICP point-to-point (1.0→0.1 m)", 3.2e-3, 0.65),
            ],
        },
        "urg_log": {"≥ 500": (1.5e-4, 560.0)},
        "sim_map": {
            "ours": 1.0e-4,
            "methods": [
                ("ndtgrid 2 cm, default match()", 1.0e-4, 1.0),
                ("small_gicp GICP (1.0→0.25 m)", 7.0e-3, 1.0),
            ],
        },
    },
    "insert": {
        "sim URG-04LX 683 beams (true poses)": {
            "ours": 5.6e-5,
            "points": 548.0,
            "methods": [
                ("ndtgrid `NdtGrid(0.02).insert`", 5.6e-5, math.nan),
                ("small_gicp `GaussianVoxelMap(0.2).insert` (3 layers)", 1.1e-4, 1.8e-3),
                ("KISS-ICP `VoxelHashMap(0.3).update` (z = 0)", 3.7e-5, math.nan),
            ],
        },
    },
    "odometry": {
        "ours": 1.5,
        "methods": [
            ("ndtgrid `Odometry(cell_size=0.02)` (defaults)", 1.5, 0.0331),
            ("KISS-ICP, voxel 0.3 m (its default for 30 m), wheel-odometry prior", 4.9, 0.0504),
        ],
    },
}


def png_size(path: Path) -> tuple[int, int]:
    """Width and height of the PNG at ``path`` (from its IHDR chunk), after checking its
    signature."""
    header = path.read_bytes()[:24]
    assert header[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(header[16:20], "big"), int.from_bytes(header[20:24], "big")


def test_bars_are_the_tables_rows_in_order() -> None:
    bars = plots.peer_bars(RESULTS)
    match = bars["match"]
    # The case sets in speed.py's order (the URG log's times are no case set).
    assert [(b.group, b.library, b.seconds, b.note) for b in match] == [
        ("real SICK pairs", "ndtgrid", 1.2e-4, "73 %"),
        ("real SICK pairs", "small_gicp", 2.3e-3, "75 %"),
        ("real SICK pairs", "Open3D", 3.2e-3, "65 %"),
        ("simulated URG-04LX\nscan to map", "ndtgrid", 1.0e-4, "100 %"),
        ("simulated URG-04LX\nscan to map", "small_gicp", 7.0e-3, "100 %"),
    ]
    insert = bars["insert"]
    assert [b.group for b in insert] == ["sim URG-04LX 683 beams"] * 3
    assert [b.method for b in insert] == [
        "ndtgrid NdtGrid(0.02).insert",
        "small_gicp GaussianVoxelMap(0.2).insert (3 layers)",
        "KISS-ICP VoxelHashMap(0.3).update (z = 0)",
    ]
    assert [b.library for b in insert] == ["ndtgrid", "small_gicp", "KISS-ICP"]
    assert insert[1].seconds == 1.1e-4 and insert[1].extra == 1.8e-3
    assert math.isnan(insert[0].extra) and math.isnan(insert[2].extra)
    odometry = bars["odometry"]
    assert [(b.method, b.seconds, b.note) for b in odometry] == [
        ("ndtgrid Odometry(cell_size=0.02) (defaults)", 1.5, "0.033 m"),
        ("KISS-ICP, voxel 0.3 m (its default for 30 m), wheel-odometry prior", 4.9, "0.050 m"),
    ]


def test_sections_not_run_give_no_bars() -> None:
    bars = plots.peer_bars({"match": RESULTS["match"], "threads": {"ratio": 1.8}})
    assert len(bars["match"]) == 5
    assert bars["insert"] == [] and bars["odometry"] == []
    assert plots.peer_bars({}) == {"match": [], "insert": [], "odometry": []}


def test_a_row_of_no_known_library_is_other() -> None:
    assert plots.library_of("ndtgrid, `build_map=False` (poses only, one thread)") == "ndtgrid"
    assert plots.library_of("Open3D ICP point-to-plane (1.0→0.1 m)") == "Open3D"
    assert plots.library_of("libpointmatcher ICP") == "other"


def test_the_picture_is_written(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib", reason="the picture needs matplotlib (the plot extra)")
    path = tmp_path / "img" / "peers.png"
    assert plots.plot_peers(RESULTS, path, "a machine") == path.resolve()
    # figsize 13 x 10 inches at 110 dpi.
    assert png_size(path) == (1430, 1100)
    assert plots.plot_peers({"threads": {}}, tmp_path / "none.png", "a machine") is None
    assert not (tmp_path / "none.png").exists()


def test_the_thread_picture_is_written(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib", reason="the picture needs matplotlib (the plot extra)")
    nan = math.nan
    runs = {
        "unpinned": [1.8, 1.3, 1.75],
        # Ringed and dotted only where the two threads shared a vCPU; nan elsewhere.
        "unpinned_first_one_cpu": [nan, 1.3, nan],
        "unpinned_one_cpu": [nan, nan, nan],
        "pinned": [1.85, 1.84, 1.86],
        "sha": [1.7, 1.6, 1.72],
        "many": [1.9, 1.88, 1.91],
        # Rounds of threads that keep matching: fewer than the runs.
        "steady": [1.92, 1.9],
        "late_unpinned": [4e-4, 3.5e-3, 0.0],
        "late_pinned": [4e-5, 3e-5, 5e-5],
    }
    path = tmp_path / "img" / "threads.png"
    assert plots.plot_threads(runs, path, late_start=1e-3) == path.resolve()
    # figsize 11 x 4.8 inches at 110 dpi.
    assert png_size(path) == (1210, 528)
