"""Readers for real laser logs.

Only light, pure-Python modules live here: importing :mod:`ndtgrid.io` loads numpy and the
standard library, never the compiled core.

- :func:`read_carmen`: the laser scans of a CARMEN log (``FLASER``, ``ROBOTLASER1``, ...),
  plain or gzip, as :class:`Scan` objects.
- :func:`iter_carmen_messages`: the same plus the ``ODOM`` messages, as :class:`OdomRecord`.
"""

from __future__ import annotations

from .carmen import OdomRecord, iter_carmen_messages, read_carmen
from .scan import Scan

__all__ = ["OdomRecord", "Scan", "iter_carmen_messages", "read_carmen"]
