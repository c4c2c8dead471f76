"""Tests of ``ndtgrid.export``: TUM, ROS map (PGM + YAML), PNG, map file; ``FreeSpace``."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import ndtgrid
from ndtgrid._core import FreeSpace
from ndtgrid.export import (
    OccupancyImage,
    load_map,
    occupancy_image,
    read_ros_map,
    read_tum,
    save_map,
    write_png,
    write_ros_map,
    write_tum,
)
from ndtgrid.export.map_file import MAGIC, NPZ_FORMAT, NPZ_VERSION

from ._room import scan as room_scan

POSES = np.array([[0.0, 0.0, 0.0], [1.5, -0.5, 2.0], [-1.0, 1.0, -3.1], [2.0, 3.0, math.pi]])


def test_tum_round_trip_and_format(tmp_path: Path) -> None:
    path = tmp_path / "t.tum"
    write_tum(path, [10.0, 10.5, 11.25, 12.0], POSES)
    lines = path.read_text().splitlines()
    assert lines[0].startswith("#")
    fields = lines[2].split()
    assert len(fields) == 8 and fields[3:6] == ["0", "0", "0"]
    assert float(fields[6]) == pytest.approx(math.sin(1.0)) and float(fields[7]) == pytest.approx(
        math.cos(1.0)
    )
    t, p = read_tum(path)
    np.testing.assert_allclose(t, [10.0, 10.5, 11.25, 12.0])
    np.testing.assert_allclose(p[:, :2], POSES[:, :2], atol=1e-9)
    np.testing.assert_allclose(np.cos(p[:, 2] - POSES[:, 2]), 1.0, atol=1e-12)


def test_tum_is_read_by_evo(tmp_path: Path) -> None:
    file_interface = pytest.importorskip("evo.tools.file_interface")
    path = tmp_path / "t.tum"
    write_tum(path, [0.0, 1.0, 2.0, 3.0], POSES)
    traj = file_interface.read_tum_trajectory_file(str(path))
    assert traj.num_poses == 4
    np.testing.assert_allclose(traj.positions_xyz[:, :2], POSES[:, :2], atol=1e-9)
    np.testing.assert_allclose(traj.timestamps, [0.0, 1.0, 2.0, 3.0])


def test_tum_rejects_bad_input(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="strictly increasing"):
        write_tum(tmp_path / "x.tum", [0.0, 0.0, 1.0, 2.0], POSES)
    with pytest.raises(ValueError, match=r"shapes \(T,\) and \(T, 3\)"):
        write_tum(tmp_path / "x.tum", [0.0, 1.0], POSES)
    bad = tmp_path / "bad.tum"
    bad.write_text("# c\n0 1 2 3 0 0 0 1\n1 2 3\n")
    with pytest.raises(ValueError, match=rf"^{bad}:3: expected 8 numbers"):
        read_tum(bad)


def room_map(resolution: float) -> tuple[ndtgrid.NdtGrid, FreeSpace]:
    grid = ndtgrid.NdtGrid(0.02)
    free = FreeSpace(resolution)
    for k, pose in enumerate([[0.0, 0.0, 0.0], [0.5, -0.5, 2.5], [-1.5, -1.0, -1.0]]):
        pts = room_scan(pose, seed=k)
        grid.insert(pts, pose)
        free.add_scan(pts, pose)
    return grid, free


def test_ros_map_files_follow_map_server(tmp_path: Path) -> None:
    yaml = pytest.importorskip("yaml")
    grid, free = room_map(0.05)
    image = occupancy_image(free, grid.cells()[0])
    pgm, yml = write_ros_map(tmp_path / "map.yaml", image)
    meta = yaml.safe_load(yml.read_text())
    assert meta["image"] == "map.pgm" and meta["resolution"] == 0.05
    assert meta["negate"] == 0 and meta["occupied_thresh"] == 0.65 and meta["free_thresh"] == 0.196
    assert len(meta["origin"]) == 3
    data = pgm.read_bytes()
    header = data.split(b"\n", 4)
    assert header[0] == b"P5" and header[3] == b"255"
    w, h = map(int, header[2].split())
    # The room is 6 m x 4 m: 120 x 80 pixels of 5 cm, plus the walls' cells.
    assert 120 <= w <= 124 and 80 <= h <= 84
    assert len(header[4]) == w * h
    pixels = np.frombuffer(header[4], dtype=np.uint8).reshape(h, w)[::-1]
    ox, oy, _ = meta["origin"]

    def pixel(x: float, y: float) -> int:
        return int(pixels[int((y - oy) / 0.05), int((x - ox) / 0.05)])

    assert pixel(0.01, 0.01) == 254  # inside the room, seen through: free (white)
    assert pixel(0.0, -2.0 + 1e-3) == 0  # on the bottom wall: occupied (black)
    assert pixel(-1.5, 0.8) == 205  # inside the closed box: never seen (grey)
    back = read_ros_map(yml)
    np.testing.assert_array_equal(back.cells, image.cells)
    np.testing.assert_allclose(back.origin, image.origin)


def test_free_space_and_raster_errors() -> None:
    free = FreeSpace(0.1)
    with pytest.raises(ValueError, match="resolution"):
        FreeSpace(-1.0)
    with pytest.raises(ValueError, match=r"free space and occupied: expected at least one point"):
        free.raster(np.zeros((0, 2)))
    free.add_scan([[1.0, 0.0]], [0.05, 0.05, 0.0])
    assert len(free) == 10
    with pytest.raises(ValueError, match=r"raster: .* would exceed the limit of 100"):
        free.raster([[30.0, 30.0]], max_cells=100)
    with pytest.raises(ValueError, match="points: expected finite values"):
        free.add_scan([[np.nan, 0.0]], [0.0, 0.0, 0.0])
    assert len(free) == 10


def test_png_is_written(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    grid, free = room_map(0.05)
    image = occupancy_image(free, grid.cells()[0])
    write_png(tmp_path / "m.png", image, trajectory=[[0, 0, 0], [0.5, -0.5, 2.5]], title="room")
    data = (tmp_path / "m.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000


def test_png_of_a_large_map_draws_it_reduced_with_its_thin_walls(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An image with more cells than the figure has pixels is drawn in blocks (a large
    log's took gigabytes drawn whole): no larger than the axes, a block black where it
    holds an occupied cell, else white where it holds a free one, else grey."""
    axes = pytest.importorskip("matplotlib.axes")
    cells = np.full((3000, 4001), -1, np.int8)  # unknown
    cells[:, :2000] = 0  # free on the left
    cells[1501, :] = 100  # a wall one cell thick across the whole image
    drawn: list[np.ndarray] = []
    imshow = axes.Axes.imshow

    def spy(self: object, grey: np.ndarray, *args: object, **kwargs: object) -> object:
        drawn.append(np.asarray(grey))
        return imshow(self, grey, *args, **kwargs)

    monkeypatch.setattr(axes.Axes, "imshow", spy)
    image = OccupancyImage(cells=cells, origin=np.array([-1.0, 2.0]), resolution=0.05)
    write_png(tmp_path / "big.png", image)
    (grey,) = drawn
    factor = math.ceil(4001 / grey.shape[1])
    assert factor >= 3 and grey.shape == (math.ceil(3000 / factor), math.ceil(4001 / factor))
    wall = 1501 // factor
    assert np.all(grey[wall] == 0.0)  # the wall in every block column
    rows = np.delete(np.arange(grey.shape[0]), wall)
    free_blocks = 2000 // factor  # blocks wholly left of the free edge
    assert np.all(grey[np.ix_(rows, np.arange(free_blocks))] == 1.0)
    assert np.all(grey[np.ix_(rows, np.arange(free_blocks + 1, grey.shape[1]))] == 0.8)


def test_map_file_loads_back_identical(tmp_path: Path) -> None:
    grid, _ = room_map(0.05)
    with pytest.raises(TypeError) as info:
        save_map(tmp_path / "map.ndtgrid", grid.cells())  # type: ignore[arg-type]
    assert str(info.value) == "grid: expected an NdtGrid or a Mapper, got tuple"
    assert not (tmp_path / "map.ndtgrid").exists()
    save_map(tmp_path / "map.ndtgrid", grid)
    assert (tmp_path / "map.ndtgrid").read_bytes() == grid.to_bytes()
    assert (tmp_path / "map.ndtgrid").read_bytes()[:8] == MAGIC
    back = load_map(tmp_path / "map.ndtgrid")
    assert back.cell_size == grid.cell_size and len(back) == len(grid)
    for a, b in zip(grid.cell_states(), back.cell_states()):
        np.testing.assert_array_equal(a, b)
    pts = room_scan([0.05, 0.02, 0.03], seed=9)
    ra, rb = grid.match(pts, [0.0, 0.0, 0.0]), back.match(pts, [0.0, 0.0, 0.0])
    np.testing.assert_array_equal(ra.pose, rb.pose)
    assert ra.score == rb.score


def test_map_file_reads_the_npz_of_earlier_releases(tmp_path: Path) -> None:
    grid, _ = room_map(0.05)
    indices, counts, sums, scatters = grid.cell_states()
    # Exactly what save_map wrote before the ndtgrid format.
    np.savez_compressed(
        tmp_path / "old.npz",
        format=np.array(NPZ_FORMAT),
        version=np.array(NPZ_VERSION),
        cell_size=np.array(grid.cell_size),
        indices=indices,
        counts=counts,
        sums=sums,
        scatters=scatters,
    )
    back = load_map(tmp_path / "old.npz")
    assert back.to_bytes() == grid.to_bytes()


def test_map_file_errors_name_the_file(tmp_path: Path) -> None:
    other = tmp_path / "other.npz"
    np.savez(other, x=np.zeros(3))
    with pytest.raises(ValueError, match=rf"^{other}: expected an ndtgrid-cells map file"):
        load_map(other)
    text = tmp_path / "notes.txt"
    text.write_text("not a map")
    with pytest.raises(ValueError, match=rf"^{text}: not an ndtgrid file"):
        load_map(text)
    with pytest.raises(FileNotFoundError, match=r"missing\.ndtgrid"):
        load_map(tmp_path / "missing.ndtgrid")
    grid, _ = room_map(0.05)
    idx, counts, sums, scatters = grid.cell_states()
    counts[3] = 0
    with pytest.raises(ValueError, match="cells: cell 3 has a count of 0"):
        ndtgrid.NdtGrid.from_cell_states(0.02, idx, counts, sums, scatters)
    with pytest.raises(ValueError, match=r"indices: expected shape"):
        ndtgrid.NdtGrid.from_cell_states(0.02, idx[:-1], counts, sums, scatters)
