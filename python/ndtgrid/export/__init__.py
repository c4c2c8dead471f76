"""Exports that other tools read: trajectories, ROS maps, images and map files.

- :func:`write_tum` / :func:`read_tum`: trajectories in the TUM format (``evo`` reads them).
- :func:`occupancy_image` and :func:`write_ros_map`: an occupancy image from the map's
  occupied cells and the free space of the beams, saved as a ROS ``map_server`` map
  (``.pgm`` + ``.yaml``).
- :func:`write_png`: the same image with the trajectory, as a PNG (extra ``plot``).
- :func:`save_map` / :func:`load_map`: a map file that loads back identical (the
  versioned, checksummed ndtgrid format; :func:`load_map` also reads the ``.npz`` of
  earlier releases).
"""

from __future__ import annotations

from .map_file import load_map, save_map
from .png import write_png
from .ros_map import OccupancyImage, occupancy_image, read_ros_map, write_ros_map
from .tum import read_tum, write_tum

__all__ = [
    "OccupancyImage",
    "load_map",
    "occupancy_image",
    "read_ros_map",
    "read_tum",
    "save_map",
    "write_png",
    "write_ros_map",
    "write_tum",
]
