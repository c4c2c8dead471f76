"""Reader for the index CSVs that link SLAM-corrected scans to raw scans.

Each ``<dataset>__<corrected-log>__index.csv`` beside the Freiburg benchmark
scans has one row per corrected scan with the columns ``gfs_scan, raw_scan,
ipc_ts, logger_ts, corr_x, corr_y, corr_theta, raw_odo_x, raw_odo_y,
raw_odo_theta``: the corrected (RBPF/GMapping) pose of a scan and the raw
odometry pose of the same scan in the full-rate log.
"""

from __future__ import annotations

import csv
import os
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

__all__ = ["BenchmarkIndex", "read_benchmark_index"]

_COLUMNS = (
    "gfs_scan",
    "raw_scan",
    "ipc_ts",
    "logger_ts",
    "corr_x",
    "corr_y",
    "corr_theta",
    "raw_odo_x",
    "raw_odo_y",
    "raw_odo_theta",
)


@dataclass(frozen=True, eq=False)
class BenchmarkIndex:
    """The rows of one index CSV as arrays (K rows).

    Attributes
    ----------
    corrected_scan : ndarray of int64, shape (K,)
        Index of the scan in the corrected log.
    raw_scan : ndarray of int64, shape (K,)
        Index of the same scan in the full-rate raw log.
    timestamp : ndarray of float64, shape (K,)
        IPC timestamp of the scan [s].
    corrected : ndarray of float64, shape (K, 3)
        Corrected pose ``[x, y, theta]`` (m, m, rad): the reference.
    raw_odom : ndarray of float64, shape (K, 3)
        Raw odometry pose of the scan (m, m, rad).
    """

    corrected_scan: npt.NDArray[np.int64]
    raw_scan: npt.NDArray[np.int64]
    timestamp: npt.NDArray[np.float64]
    corrected: npt.NDArray[np.float64]
    raw_odom: npt.NDArray[np.float64]

    def __len__(self) -> int:
        return len(self.raw_scan)


def read_benchmark_index(path: str | os.PathLike[str]) -> BenchmarkIndex:
    """Read an index CSV.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.

    Returns
    -------
    BenchmarkIndex
        Its rows as arrays.

    Raises
    ------
    ValueError
        If a column is missing or a value is not a number; the message names the
        file and the line.
    """
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in _COLUMNS if c not in (reader.fieldnames or ())]
        if missing:
            raise ValueError(f"{path}:1: missing columns {missing}")
        rows = []
        for line, row in enumerate(reader, start=2):
            try:
                rows.append([float(row[c]) for c in _COLUMNS])
            except (TypeError, ValueError) as exc:
                raise ValueError(f"{path}:{line}: expected numbers, got {row}") from exc
    table = np.array(rows, dtype=float).reshape(-1, len(_COLUMNS))
    return BenchmarkIndex(
        corrected_scan=table[:, 0].astype(np.int64),
        raw_scan=table[:, 1].astype(np.int64),
        timestamp=table[:, 2].copy(),
        corrected=table[:, 4:7].copy(),
        raw_odom=table[:, 7:10].copy(),
    )
