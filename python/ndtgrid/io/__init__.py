"""Readers for real laser logs.

Importing :mod:`ndtgrid.io` loads numpy and the standard library only; the compiled core is
loaded when a scan is turned into points (:meth:`Scan.points`).

- :func:`read_carmen`: the laser scans of a CARMEN log (``FLASER``, ``ROBOTLASER1``, ...),
  plain or gzip, as :class:`Scan` objects.
- :func:`iter_carmen_messages`: the same plus the ``ODOM`` messages, as :class:`OdomRecord`.
- :func:`read_benchmark_index`: the CSVs linking corrected scans to raw scans and odometry.
- :func:`read_benchmark_split`: the per-scan split of the Freiburg benchmark logs (``.tar.gz``).
- :func:`read_mines`: the Mines URG-04LX logs of BreezySLAM, odometry from wheel ticks.
- :func:`read_rosbag`: ``LaserScan`` (+ ``Odometry``) of ROS 1/2 bags (extra ``rosbag``).
- :func:`read_log`: any of these, picked by the file name (or forced).
"""

from __future__ import annotations

from .benchmark_index import BenchmarkIndex, read_benchmark_index
from .benchmark_split import read_benchmark_split
from .carmen import OdomRecord, iter_carmen_messages, read_carmen
from .logs import LOG_FORMATS, guess_format, read_log
from .mines import read_mines
from .rosbag import read_rosbag
from .scan import Scan

__all__ = [
    "LOG_FORMATS",
    "BenchmarkIndex",
    "OdomRecord",
    "Scan",
    "guess_format",
    "iter_carmen_messages",
    "read_benchmark_index",
    "read_benchmark_split",
    "read_carmen",
    "read_log",
    "read_mines",
    "read_rosbag",
]
