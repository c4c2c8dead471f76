"""One entry point for every log format: pick the reader from the file name, or force it."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

from .benchmark_split import read_benchmark_split
from .carmen import read_carmen
from .mines import read_mines
from .rosbag import read_rosbag
from .scan import Scan

__all__ = ["LOG_FORMATS", "guess_format", "read_log"]

#: Formats :func:`read_log` knows, and the file names :func:`guess_format` maps to them.
LOG_FORMATS: dict[str, str] = {
    "carmen": ".log, .clf, .txt (CARMEN text; also gzip-compressed, e.g. .log.gz)",
    "mines": ".dat (Mines URG-04LX log of BreezySLAM)",
    "split": ".tar.gz, .tgz (per-scan split of the Freiburg benchmark logs)",
    "rosbag": ".bag file (ROS 1) or a directory with metadata.yaml (ROS 2)",
}


def guess_format(path: str | os.PathLike[str]) -> str:
    """The format of a log from its name.

    Parameters
    ----------
    path : str or os.PathLike
        The log.

    Returns
    -------
    str
        A key of :data:`LOG_FORMATS`.

    Raises
    ------
    ValueError
        If the name matches no format; the message lists them.
    """
    p = Path(os.fspath(path))
    name = p.name.lower()
    if p.is_dir() or name.endswith((".bag", ".mcap", ".db3")):
        return "rosbag"
    if name.endswith((".tar.gz", ".tgz")):
        return "split"
    if name.endswith(".dat"):
        return "mines"
    stem = name[:-3] if name.endswith(".gz") else name
    if stem.endswith((".log", ".clf", ".txt")):
        return "carmen"
    known = "; ".join(f"{k}: {v}" for k, v in LOG_FORMATS.items())
    raise ValueError(f"{p}: cannot tell the log format from the name ({known}); force one")


def read_log(path: str | os.PathLike[str], *, format: str | None = None) -> Iterator[Scan]:
    """The scans of a log of any known format.

    Parameters
    ----------
    path : str or os.PathLike
        The log.
    format : str, optional
        A key of :data:`LOG_FORMATS`; by default :func:`guess_format`.

    Returns
    -------
    Iterator[Scan]
        The reader's scans, in log order.

    Raises
    ------
    ValueError
        If the format is unknown or cannot be guessed; the readers' own errors otherwise.
    """
    fmt = guess_format(path) if format is None else format
    if fmt == "carmen":
        return read_carmen(path)
    if fmt == "mines":
        return read_mines(path)
    if fmt == "split":
        return read_benchmark_split(path)
    if fmt == "rosbag":
        return read_rosbag(path)
    raise ValueError(f"format: expected one of {sorted(LOG_FORMATS)}, got {fmt!r}")
