"""Occupancy images and ROS ``map_server`` maps (``.pgm`` + ``.yaml``).

The image has three values: a cell holding a point of the map is **occupied**, a cell a
laser beam passed through on its way to a hit is **free**, every other cell is
**unknown**. The ray tracing and rasterising run in the core
(:class:`ndtgrid._core.FreeSpace`); this module writes the files.

The map follows ``map_server``'s convention with ``negate: 0``: a pixel's occupancy is
``p = (255 - value) / 255``, occupied pixels are 0 (black, ``p = 1 > occupied_thresh``),
free pixels 254 (white, ``p = 0.004 < free_thresh``) and unknown ones 205 (grey,
``p = 0.196``, between the thresholds), as ``map_saver`` writes them. The first row of the
PGM is the top of the map (largest y); ``origin`` is the map-frame pose of the lower-left
pixel's outer corner.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from ndtgrid._core import FreeSpace

__all__ = [
    "FREE_THRESH",
    "OCCUPIED_THRESH",
    "OccupancyImage",
    "occupancy_image",
    "read_ros_map",
    "write_ros_map",
]

#: ``occupied_thresh`` written to the YAML.
OCCUPIED_THRESH = 0.65
#: ``free_thresh`` written to the YAML.
FREE_THRESH = 0.196
_PGM = {-1: 205, 0: 254, 100: 0}


@dataclass(frozen=True, eq=False)
class OccupancyImage:
    """A dense occupancy image (the ``nav_msgs/OccupancyGrid`` convention).

    Attributes
    ----------
    cells : ndarray of int8, shape (H, W)
        Row ``r``, column ``c`` covers ``origin + (c, r) * resolution``; row 0 is the lowest
        y. Values: -1 unknown, 0 free, 100 occupied.
    origin : ndarray, shape (2,)
        Map-frame position of the outer corner of cell (0, 0) [m].
    resolution : float
        Side of a cell [m].
    """

    cells: npt.NDArray[np.int8]
    origin: npt.NDArray[np.float64]
    resolution: float


def occupancy_image(
    free: FreeSpace, occupied: npt.ArrayLike, *, max_cells: int = 100_000_000
) -> OccupancyImage:
    """The occupancy image of a map.

    Parameters
    ----------
    free : FreeSpace
        The beams traced so far; its ``resolution`` is the image's.
    occupied : array_like, shape (K, 2)
        Map-frame points of the map [m], e.g. the centres of ``NdtGrid.cells()``.
    max_cells : int, default 10**8
        Largest image (cells) to make.

    Returns
    -------
    OccupancyImage
        Covers every traced cell and every occupied point.

    Raises
    ------
    ValueError
        If there is nothing to draw, or the image would exceed ``max_cells`` (choose a
        coarser resolution).
    """
    cells, origin = free.raster(np.asarray(occupied, dtype=np.float64), max_cells=max_cells)
    return OccupancyImage(cells=cells, origin=origin, resolution=free.resolution)


def write_ros_map(path: str | os.PathLike[str], image: OccupancyImage) -> tuple[Path, Path]:
    """Write a ROS ``map_server`` map.

    Parameters
    ----------
    path : str or os.PathLike
        The YAML file to write (e.g. ``out/map.yaml``); the image goes beside it with the
        suffix ``.pgm``, and the YAML names it relative to itself.
    image : OccupancyImage
        The map.

    Returns
    -------
    pgm, yaml : pathlib.Path
        The files written.
    """
    yaml_path = Path(os.fspath(path))
    pgm_path = yaml_path.with_suffix(".pgm")
    h, w = image.cells.shape
    lut = np.full(256, 205, dtype=np.uint8)
    for value, grey in _PGM.items():
        lut[value & 0xFF] = grey
    pixels = lut[image.cells.view(np.uint8)][::-1]
    with open(pgm_path, "wb") as f:
        f.write(f"P5\n# ndtgrid occupancy map, {image.resolution} m/pixel\n{w} {h}\n255\n".encode())
        f.write(np.ascontiguousarray(pixels).tobytes())
    ox, oy = (float(v) for v in image.origin)
    yaml_path.write_text(
        f"image: {pgm_path.name}\n"
        f"resolution: {image.resolution!r}\n"
        f"origin: [{ox!r}, {oy!r}, 0.0]\n"
        f"negate: 0\n"
        f"occupied_thresh: {OCCUPIED_THRESH}\n"
        f"free_thresh: {FREE_THRESH}\n"
    )
    return pgm_path, yaml_path


def read_ros_map(path: str | os.PathLike[str]) -> OccupancyImage:
    """Read a map written by :func:`write_ros_map` (a flat YAML and a binary P5 PGM).

    Parameters
    ----------
    path : str or os.PathLike
        The YAML file.

    Returns
    -------
    OccupancyImage
        Pixels 0 as occupied (100), 254 as free (0), others as unknown (-1).

    Raises
    ------
    ValueError
        If a key is missing or the PGM is not an 8-bit P5 image of the size it declares.
    """
    yaml_path = Path(os.fspath(path))
    meta: dict[str, str] = {}
    for line in yaml_path.read_text().splitlines():
        key, sep, value = line.partition(":")
        if sep:
            meta[key.strip()] = value.strip()
    missing = {"image", "resolution", "origin"} - meta.keys()
    if missing:
        raise ValueError(f"{yaml_path}: missing keys {sorted(missing)}")
    origin = [float(v) for v in meta["origin"].strip("[]").split(",")]
    data = (yaml_path.parent / meta["image"]).read_bytes()
    fields: list[bytes] = []
    pos = 0
    while len(fields) < 4:
        while data[pos : pos + 1].isspace():
            pos += 1
        if data[pos : pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end : end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    if fields[0] != b"P5" or fields[3] != b"255":
        raise ValueError(f"{meta['image']}: expected an 8-bit binary PGM (P5, 255)")
    w, h = int(fields[1]), int(fields[2])
    pixels = np.frombuffer(data[pos + 1 :], dtype=np.uint8)
    if pixels.size != w * h:
        raise ValueError(f"{meta['image']}: declares {w} x {h} pixels, holds {pixels.size}")
    grey = pixels.reshape(h, w)[::-1]
    cells = np.where(grey == 0, 100, np.where(grey == 254, 0, -1)).astype(np.int8)
    return OccupancyImage(
        cells=cells, origin=np.array(origin[:2]), resolution=float(meta["resolution"])
    )
