"""Reader for the per-scan split of the Freiburg SLAM-benchmark logs (``<name>.tar.gz``).

Each archive holds one text member per ``FLASER`` scan of a benchmark ``.clf`` log,
``datasets/<name>/dataset_<k>.txt`` for ``k = 0 .. N-1``::

    1 180          <- "1 <n_beams>"
    46.56          <- range 0 [m]
    ...            <- n ranges in total, one per line
    -0.000602 0.012727 -1.570796   <- x y theta: the raw odometry (laser) pose (m, m, rad)

The files hold no timestamps and no angles: beam ``i`` of ``n`` points at
``-fov/2 + i * fov / (n - 1)`` (``-90 .. +90`` degrees, both ends included, for the default
``fov = pi``), as the repository that made the split converts them.
"""

from __future__ import annotations

import math
import os
import re
import tarfile
import zlib
from collections.abc import Generator

import numpy as np
import numpy.typing as npt

from .scan import Scan

__all__ = ["read_benchmark_split"]

_MEMBER = re.compile(r"(?:.*/)?dataset_(\d+)\.txt")

F64 = npt.NDArray[np.float64]


def read_benchmark_split(
    path: str | os.PathLike[str], *, fov: float = math.pi
) -> Generator[Scan, None, None]:
    """Read the scans of a benchmark-split archive in scan order (``k = 0, 1, ...``).

    Parameters
    ----------
    path : str or os.PathLike
        The ``.tar.gz`` archive (e.g. ``intel.tar.gz``). It is read as a stream; nothing is
        extracted to disk.
    fov : float, default pi
        Field of view [rad]; beam ``i`` of ``n`` points at ``-fov/2 + i * fov / (n - 1)``.

    Returns
    -------
    Generator[Scan, None, None]
        One :class:`~ndtgrid.io.Scan` per member ``dataset_<k>.txt``, in increasing ``k``.
        ``ranges`` (B,) as logged [m] (values at the sensor's maximum, e.g. 81.83, 81.91 or
        50.00, mean "no return" and are kept); ``angles`` (B,) [rad]; ``odom`` (3,) the raw
        pose ``[x, y, theta]`` of the file; ``laser_pose`` ``None``; ``max_range`` ``None``;
        ``timestamp`` **NaN** (the files hold no time: the position of a scan in the log is
        its ``k``); ``source`` the member's name; ``line`` 1 (the scan starts on line 1 of
        its member).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist (raised by this call, before iterating).
    ValueError
        If ``fov`` is not in ``(0, 2*pi]``. While iterating: a member that does not follow
        the format (message ``"{path}:{member}:{line}: ..."``), two members with the same
        ``k``, a gap in ``k`` (message names the first missing member), or a file that is
        not a gzip-compressed tar or is cut short (``"{path}: not a readable .tar.gz after
        {n} scans: ..."``).

    Notes
    -----
    The archives store their members in no particular order, so the scans cannot be
    yielded as they are decompressed: one pass through the gzip stream parses every member
    into compact arrays (8 bytes per range: about 20 MB for Intel's 13 631 scans), then the
    scans are yielded in order. Members whose name is not ``dataset_<k>.txt`` (directories,
    other files) are skipped.

    Examples
    --------
    >>> for scan in read_benchmark_split("intel.tar.gz"):  # doctest: +SKIP
    ...     pts = scan.points(max_range=40.0)
    """
    name = os.fspath(path)
    if not os.path.exists(name):
        raise FileNotFoundError(f"{name}: no such file")
    if not (isinstance(fov, (int, float)) and 0.0 < fov <= 2.0 * math.pi):
        raise ValueError(f"fov: expected a field of view in (0, 2*pi] rad, got {fov!r}")
    return _scans(name, float(fov))


def _scans(name: str, fov: float) -> Generator[Scan, None, None]:
    parsed: dict[int, tuple[F64, F64, str]] = {}
    try:
        with tarfile.open(name, "r:gz") as archive:
            for member in archive:
                match = _MEMBER.fullmatch(member.name)
                if not member.isfile() or match is None:
                    continue
                k = int(match.group(1))
                if k in parsed:
                    raise ValueError(f"{name}:{member.name}: scan {k} appears twice")
                stream = archive.extractfile(member)
                if stream is None:  # pragma: no cover - isfile() members always have data
                    continue
                ranges, pose = _parse_member(stream.read(), f"{name}:{member.name}")
                parsed[k] = (ranges, pose, member.name)
    except (EOFError, tarfile.TarError, zlib.error) as exc:
        # Not a gzip-compressed tar, or one cut short: named, with what was read.
        raise ValueError(
            f"{name}: not a readable .tar.gz after {len(parsed)} scans: {exc}"
        ) from exc
    for k in range(len(parsed)):
        if k not in parsed:
            raise ValueError(
                f"{name}: member dataset_{k}.txt is missing (found {len(parsed)} scans, "
                f"numbered up to {max(parsed)})"
            )
    angle_cache: dict[int, F64] = {}
    for k in range(len(parsed)):
        ranges, pose, member_name = parsed.pop(k)
        n = ranges.shape[0]
        if n not in angle_cache:
            angles = -0.5 * fov + np.arange(n) * (fov / (n - 1)) if n > 1 else np.zeros(n)
            angle_cache[n] = angles
        yield Scan(
            timestamp=math.nan,
            ranges=ranges,
            angles=angle_cache[n],
            odom=pose,
            source=member_name,
            line=1,
        )


def _parse_member(data: bytes, where: str) -> tuple[F64, F64]:
    """Ranges (B,) and pose (3,) of one member; ``ValueError`` with ``where:line`` on error."""
    lines = data.decode("ascii", errors="replace").splitlines()
    while lines and not lines[-1].strip():
        lines.pop()
    head = lines[0].split() if lines else []
    if len(head) != 2 or head[0] != "1" or not head[1].isdigit() or int(head[1]) < 1:
        raise ValueError(f"{where}:1: expected '1 <number of beams>', got {_show(lines, 0)}")
    n = int(head[1])
    if len(lines) != n + 2:
        raise ValueError(
            f"{where}:{len(lines)}: expected {n + 2} lines (header, {n} ranges, pose), "
            f"got {len(lines)}"
        )
    try:
        ranges = np.array(lines[1 : n + 1], dtype=np.float64)
    except ValueError:
        for i in range(1, n + 1):
            try:
                float(lines[i])
            except ValueError:
                raise ValueError(
                    f"{where}:{i + 1}: expected one range in metres, got {_show(lines, i)}"
                ) from None
        raise  # pragma: no cover - numpy and float() agree on what parses
    pose_fields = lines[n + 1].split()
    try:
        if len(pose_fields) != 3:
            raise ValueError
        pose = np.array([float(v) for v in pose_fields], dtype=np.float64)
    except ValueError:
        raise ValueError(
            f"{where}:{n + 2}: expected the pose 'x y theta' (3 numbers), got {_show(lines, n + 1)}"
        ) from None
    if not np.all(np.isfinite(pose)):
        raise ValueError(f"{where}:{n + 2}: expected a finite pose, got {_show(lines, n + 1)}")
    return ranges, pose


def _show(lines: list[str], i: int) -> str:
    text = lines[i] if i < len(lines) else "end of file"
    return repr(text[:60])
