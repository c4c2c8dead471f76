"""Readers for real laser logs.

Importing :mod:`ndtgrid.io` loads numpy and the standard library only; the compiled core is
loaded when a scan is turned into points (:meth:`Scan.points`).

- :func:`read_carmen`: the laser scans of a CARMEN log (``FLASER``, ``ROBOTLASER1``, ...),
  plain or gzip, as :class:`Scan` objects.
- :func:`iter_carmen_messages`: the same plus the ``ODOM`` messages, as :class:`OdomRecord`.
- :func:`read_benchmark_index`: the CSVs linking corrected scans to raw scans and odometry.
"""

from __future__ import annotations

from .benchmark_index import BenchmarkIndex, read_benchmark_index
from .carmen import OdomRecord, iter_carmen_messages, read_carmen
from .scan import Scan

__all__ = [
    "BenchmarkIndex",
    "OdomRecord",
    "Scan",
    "iter_carmen_messages",
    "read_benchmark_index",
    "read_carmen",
]
