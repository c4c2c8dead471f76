"""Reader for CARMEN laser logs (``.log``, ``.clf``, ``.gfs.log``), plain text or gzip.

A CARMEN log holds one message per line, as whitespace-separated fields whose first field
names the message. This module reads the laser messages into :class:`~ndtgrid.io.Scan`
objects and the ``ODOM`` messages into :class:`OdomRecord` objects:

``FLASER`` (and ``RLASER``, same layout, only when asked for)::

    FLASER n r_1 ... r_n x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname
        logger_timestamp

``ROBOTLASER1`` (and ``ROBOTLASER2``, same layout, only when asked for)::

    ROBOTLASER1 laser_type start_angle field_of_view angular_resolution maximum_range
        accuracy remission_mode num_readings r_1 ... r_n num_remissions rem_1 ... rem_k
        laser_pose_x laser_pose_y laser_pose_theta robot_pose_x robot_pose_y
        robot_pose_theta laser_tv laser_rv forward_safety_dist side_safety_dist turn_axis
        ipc_timestamp ipc_hostname logger_timestamp

``ODOM``::

    ODOM x y theta tv rv accel ipc_timestamp ipc_hostname logger_timestamp

Empty lines, ``#`` comment lines and every other message (``PARAM``, ``SYNC``,
``TRUEPOS``, GMapping's ``NEFF``, ``RAWLASER*``, laser kinds not asked for, ...) are
skipped without being parsed.
"""

from __future__ import annotations

import gzip
import math
import os
import zlib
from collections.abc import Generator, Iterable
from dataclasses import dataclass
from typing import Callable, TextIO

import numpy as np
import numpy.typing as npt

from .scan import Scan

__all__ = ["DEFAULT_LASERS", "LASER_MESSAGES", "OdomRecord", "iter_carmen_messages", "read_carmen"]

_GZIP_MAGIC = b"\x1f\x8b"
_FLASER_LIKE = frozenset({"FLASER", "RLASER"})
_ROBOTLASER_LIKE = frozenset({"ROBOTLASER1", "ROBOTLASER2"})

#: Laser message kinds this reader understands (values allowed in ``lasers``).
LASER_MESSAGES: tuple[str, ...] = ("FLASER", "RLASER", "ROBOTLASER1", "ROBOTLASER2")
#: Laser message kinds read by default: the front laser in the old and the new format.
DEFAULT_LASERS: tuple[str, ...] = ("FLASER", "ROBOTLASER1")

_FLASER_TAIL = tuple(
    "x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname logger_timestamp".split()
)
_ROBOTLASER_HEAD = tuple(
    (
        "laser_type start_angle field_of_view angular_resolution maximum_range accuracy "
        "remission_mode num_readings"
    ).split()
)
_ROBOTLASER_TAIL = tuple(
    (
        "laser_pose_x laser_pose_y laser_pose_theta robot_pose_x robot_pose_y "
        "robot_pose_theta laser_tv laser_rv forward_safety_dist side_safety_dist "
        "turn_axis ipc_timestamp ipc_hostname logger_timestamp"
    ).split()
)
_ODOM_FIELDS = tuple(
    "ODOM x y theta tv rv accel ipc_timestamp ipc_hostname logger_timestamp".split()
)


@dataclass(frozen=True, eq=False, repr=False)
class OdomRecord:
    """One ``ODOM`` message: the robot's odometry pose at a time.

    Parameters
    ----------
    timestamp : float
        Time in seconds (the message's ``ipc_timestamp``).
    pose : numpy.ndarray
        float64 array of shape (3,): ``[x, y, theta]`` in metres and radians.
    line : int
        1-based line number of the message in its file.
    """

    timestamp: float
    pose: npt.NDArray[np.float64]
    line: int

    def __post_init__(self) -> None:
        pose = np.asarray(self.pose, dtype=np.float64)
        if pose.shape != (3,):
            raise ValueError(
                f"OdomRecord.pose must have shape (3,) = (x, y, theta), got {pose.shape}"
            )
        object.__setattr__(self, "pose", pose)
        object.__setattr__(self, "timestamp", float(self.timestamp))
        object.__setattr__(self, "line", int(self.line))

    def __repr__(self) -> str:
        pose = ", ".join(f"{v:.6g}" for v in self.pose)
        return f"OdomRecord(timestamp={self.timestamp!r}, pose=[{pose}], line={self.line})"


class _MalformedLineError(ValueError):
    """A message line that does not follow its format; the caller adds ``path:line: ``."""


# --------------------------------------------------------------------------- public API


def read_carmen(
    path: str | os.PathLike[str],
    *,
    lasers: Iterable[str] = DEFAULT_LASERS,
    fov: float = np.pi,
) -> Generator[Scan, None, None]:
    """Read the laser scans of a CARMEN log, lazily, in file order.

    Parameters
    ----------
    path : str or os.PathLike
        The log file, plain text or gzip-compressed. Compression is detected from the
        first two bytes (``1f 8b``), not from the file name.
    lasers : iterable of str, optional
        Laser message kinds to read, among ``"FLASER"``, ``"RLASER"``, ``"ROBOTLASER1"`` and
        ``"ROBOTLASER2"``. Default ``("FLASER", "ROBOTLASER1")``: the front laser. Lines of
        other kinds, including ``RLASER`` unless asked for, are skipped.
    fov : float, optional
        Field of view in radians of ``FLASER``/``RLASER`` scans, which store no angles.
        Beam ``i`` of ``n`` points at ``-fov/2 + i * fov/(n-1)``: the beams span
        ``[-fov/2, fov/2]`` with both ends included (the Freiburg benchmark convention).
        Default ``pi`` (180 degrees, the SICK LMS of the classic logs). ``ROBOTLASER*``
        messages carry their own angles and ignore this.

    Returns
    -------
    Generator[Scan, None, None]
        One :class:`~ndtgrid.io.Scan` per laser message. ``timestamp`` is the
        ``ipc_timestamp`` field. For ``FLASER``/``RLASER`` the first pose triple is
        ``laser_pose``, the second ``odom``, and ``max_range`` is ``None``. For
        ``ROBOTLASER*``, ``laser_pose`` is ``laser_pose_*``, ``odom`` is ``robot_pose_*``,
        the angles are ``start_angle + i * angular_resolution`` and ``max_range`` is
        ``maximum_range`` (``None`` if that is not a positive number).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist (raised by this call, before iterating).
    TypeError
        If ``lasers`` is a single string or ``fov`` is not a number.
    ValueError
        If ``lasers`` names an unknown message or ``fov`` is not in ``(0, 2*pi]``. While
        iterating: a malformed laser line (too few or too many fields for its beam count,
        a non-number where a number must be, a non-finite pose or timestamp). The message
        starts with ``"{path}:{line}: "`` and says what was expected and what came. A
        gzip stream cut short or damaged: ``"{path}: damaged gzip data after line {n}: "``.

    See Also
    --------
    iter_carmen_messages : the same, with the ``ODOM`` messages too.

    Notes
    -----
    ``ODOM``, ``PARAM``, ``SYNC``, ``TRUEPOS``, ``NEFF``, other unknown messages, ``#``
    comments and empty lines are skipped without being parsed, so a malformed one of them
    raises nothing.

    Examples
    --------
    >>> for scan in read_carmen("intel-corrected.log.gz"):  # doctest: +SKIP
    ...     xy = scan.ranges[:, None] * np.c_[np.cos(scan.angles), np.sin(scan.angles)]
    """
    name, compressed = _probe(path)
    kinds = _check_lasers(lasers)
    width = _check_fov(fov)
    return _scans_only(_iter_lines(name, compressed, kinds, width, with_odom=False))


def iter_carmen_messages(
    path: str | os.PathLike[str],
    *,
    lasers: Iterable[str] = DEFAULT_LASERS,
    fov: float = np.pi,
) -> Generator[Scan | OdomRecord, None, None]:
    """Read the laser scans and the ``ODOM`` messages of a CARMEN log, in file order.

    Parameters
    ----------
    path : str or os.PathLike
        The log file, plain text or gzip-compressed (detected from the magic bytes).
    lasers : iterable of str, optional
        Laser message kinds to read; see :func:`read_carmen`.
    fov : float, optional
        Field of view in radians of ``FLASER``/``RLASER`` scans; see :func:`read_carmen`.

    Returns
    -------
    Generator[Scan | OdomRecord, None, None]
        A :class:`~ndtgrid.io.Scan` per laser message and an :class:`OdomRecord` per
        ``ODOM`` message (``timestamp`` = ``ipc_timestamp``, ``pose`` = ``[x, y, theta]``).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist (raised by this call, before iterating).
    TypeError
        If ``lasers`` is a single string or ``fov`` is not a number.
    ValueError
        As :func:`read_carmen`; a malformed ``ODOM`` line (not exactly 10 fields, a
        non-number, a non-finite pose or timestamp) raises too, with the same
        ``"{path}:{line}: "`` prefix.
    """
    name, compressed = _probe(path)
    kinds = _check_lasers(lasers)
    width = _check_fov(fov)
    return _iter_lines(name, compressed, kinds, width, with_odom=True)


# --------------------------------------------------------------------------- arguments


def _probe(path: str | os.PathLike[str]) -> tuple[str, bool]:
    """Return ``path`` as a str and whether the file is gzip; raise if it cannot be opened."""
    try:
        name = os.fsdecode(path)
    except TypeError:
        raise TypeError(f"path: expected a str or os.PathLike, got {type(path).__name__}") from None
    with open(name, "rb") as raw:
        magic = raw.read(2)
    return name, magic == _GZIP_MAGIC


def _check_lasers(lasers: Iterable[str]) -> frozenset[str]:
    if isinstance(lasers, (str, bytes)):
        raise TypeError(
            f"lasers: expected a tuple of message names such as ('FLASER',), got the single "
            f"string {lasers!r}"
        )
    try:
        names = tuple(lasers)
    except TypeError:
        raise TypeError(
            f"lasers: expected a tuple of message names, got {type(lasers).__name__}"
        ) from None
    for laser in names:
        if laser not in LASER_MESSAGES:
            raise ValueError(f"lasers: expected names among {LASER_MESSAGES}, got {laser!r}")
    return frozenset(names)


def _check_fov(fov: float) -> float:
    if isinstance(fov, bool) or not isinstance(fov, (int, float, np.integer, np.floating)):
        raise TypeError(f"fov: expected a number of radians, got {type(fov).__name__}")
    value = float(fov)
    if not 0.0 < value <= 2.0 * math.pi:
        raise ValueError(f"fov: expected a field of view in (0, 2*pi] radians, got {value!r}")
    return value


# --------------------------------------------------------------------------- reading


def _open_text(name: str, compressed: bool) -> TextIO:
    # newline="\n": only LF ends a line, so line numbers match what editors show
    stream: TextIO
    if compressed:
        stream = gzip.open(name, "rt", encoding="utf-8", errors="replace", newline="\n")
    else:
        stream = open(name, encoding="utf-8", errors="replace", newline="\n")
    return stream


def _iter_lines(
    name: str, compressed: bool, lasers: frozenset[str], fov: float, *, with_odom: bool
) -> Generator[Scan | OdomRecord, None, None]:
    number = 0
    try:
        with _open_text(name, compressed) as stream:
            for number, text in enumerate(stream, start=1):
                tokens = text.split()
                if not tokens:
                    continue
                kind = tokens[0]
                message: Scan | OdomRecord
                try:
                    if kind in lasers:
                        if kind in _FLASER_LIKE:
                            message = _parse_flaser(tokens, number, fov)
                        else:
                            message = _parse_robotlaser(tokens, number)
                    elif with_odom and kind == "ODOM":
                        message = _parse_odom(tokens, number)
                    else:
                        continue
                except _MalformedLineError as exc:
                    raise ValueError(f"{name}:{number}: {exc}") from None
                yield message
    except (EOFError, gzip.BadGzipFile, zlib.error) as exc:
        # A truncated or damaged gzip stream: named, with the last line read.
        raise ValueError(f"{name}: damaged gzip data after line {number}: {exc}") from exc


def _scans_only(
    messages: Generator[Scan | OdomRecord, None, None],
) -> Generator[Scan, None, None]:
    try:
        for message in messages:
            if isinstance(message, Scan):
                yield message
    finally:
        messages.close()


# --------------------------------------------------------------------------- one line


def _count(tokens: list[str], index: int, what: str) -> int:
    """Parse the non-negative integer count in field ``index`` (0-based)."""
    kind = tokens[0]
    if index >= len(tokens):
        raise _MalformedLineError(
            f"{kind}: expected {what} (an integer) in field {index + 1}, got the end of the "
            f"line after {len(tokens)} fields"
        )
    token = tokens[index]
    try:
        value = int(token)
    except ValueError:
        value = -1
    if value < 0:
        raise _MalformedLineError(
            f"{kind}: expected {what} as a non-negative integer in field {index + 1}, got {token!r}"
        )
    return value


def _numbers(
    tokens: list[str], start: int, stop: int, field_name: Callable[[int], str]
) -> npt.NDArray[np.float64]:
    """Parse ``tokens[start:stop]`` as float64; on failure name the first bad field."""
    try:
        return np.array(tokens[start:stop], dtype=np.float64)
    except ValueError as exc:
        for index in range(start, stop):
            try:
                float(tokens[index])
            except ValueError:
                raise _MalformedLineError(
                    f"{tokens[0]}: expected a number for {field_name(index)} "
                    f"(field {index + 1}), got {tokens[index]!r}"
                ) from None
        raise _MalformedLineError(f"{tokens[0]}: expected numbers, {exc}") from None


def _check_finite(kind: str, what: str, values: npt.NDArray[np.float64]) -> None:
    if not np.isfinite(values).all():
        shown = " ".join(repr(float(v)) for v in values)
        raise _MalformedLineError(f"{kind}: expected a finite {what}, got {shown}")


def _parse_flaser(tokens: list[str], line: int, fov: float) -> Scan:
    kind = tokens[0]
    n = _count(tokens, 1, "the beam count n")
    expected = n + 11
    if len(tokens) != expected:
        raise _MalformedLineError(
            f"{kind}: expected {expected} fields for n={n} beams ({kind} n, {n} ranges, "
            f"x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname "
            f"logger_timestamp), got {len(tokens)}"
        )

    def field_name(index: int) -> str:
        if index < 2 + n:
            return f"range {index - 1} of {n}"
        return _FLASER_TAIL[index - 2 - n]

    # ranges, both poses and ipc_timestamp in one call; logger_timestamp on its own
    values = _numbers(tokens, 2, n + 9, field_name)
    _numbers(tokens, n + 10, n + 11, field_name)
    laser_pose = values[n : n + 3]
    odom = values[n + 3 : n + 6]
    timestamp = values[n + 6 : n + 7]
    _check_finite(kind, "laser pose (x y theta)", laser_pose)
    _check_finite(kind, "odometry pose (odom_x odom_y odom_theta)", odom)
    _check_finite(kind, "ipc_timestamp", timestamp)
    return Scan(
        timestamp=float(timestamp[0]),
        ranges=values[:n].copy(),
        angles=np.linspace(-0.5 * fov, 0.5 * fov, n),
        odom=odom.copy(),
        laser_pose=laser_pose.copy(),
        max_range=None,
        source=kind,
        line=line,
    )


def _parse_robotlaser(tokens: list[str], line: int) -> Scan:
    kind = tokens[0]
    n = _count(tokens, 8, "num_readings")
    k = _count(tokens, 9 + n, "num_remissions")
    expected = n + k + 24
    if len(tokens) != expected:
        raise _MalformedLineError(
            f"{kind}: expected {expected} fields for num_readings={n} and num_remissions={k} "
            f"({kind}, 8 header fields, {n} ranges, num_remissions, {k} remissions, "
            f"14 pose/velocity/timestamp fields), got {len(tokens)}"
        )
    tail = 10 + n + k

    def field_name(index: int) -> str:
        if index < 9:
            return _ROBOTLASER_HEAD[index - 1]
        if index < 9 + n:
            return f"range {index - 8} of {n}"
        if index == 9 + n:
            return "num_remissions"
        if index < tail:
            return f"remission {index - 9 - n} of {k}"
        return _ROBOTLASER_TAIL[index - tail]

    # everything up to ipc_timestamp in one call; logger_timestamp on its own
    values = _numbers(tokens, 1, tail + 12, field_name)
    _numbers(tokens, expected - 1, expected, field_name)
    start_angle, resolution, maximum_range = values[1], values[3], values[4]
    _check_finite(kind, "start_angle and angular_resolution", values[[1, 3]])
    back = tail - 1  # index of laser_pose_x in ``values``
    laser_pose = values[back : back + 3]
    odom = values[back + 3 : back + 6]
    timestamp = values[back + 11 : back + 12]
    _check_finite(kind, "laser pose (laser_pose_x laser_pose_y laser_pose_theta)", laser_pose)
    _check_finite(kind, "robot pose (robot_pose_x robot_pose_y robot_pose_theta)", odom)
    _check_finite(kind, "ipc_timestamp", timestamp)
    max_range = float(maximum_range) if maximum_range > 0.0 else None
    return Scan(
        timestamp=float(timestamp[0]),
        ranges=values[8 : 8 + n].copy(),
        angles=start_angle + resolution * np.arange(n, dtype=np.float64),
        odom=odom.copy(),
        laser_pose=laser_pose.copy(),
        max_range=max_range,
        source=kind,
        line=line,
    )


def _parse_odom(tokens: list[str], line: int) -> OdomRecord:
    if len(tokens) != len(_ODOM_FIELDS):
        raise _MalformedLineError(
            f"ODOM: expected {len(_ODOM_FIELDS)} fields ({' '.join(_ODOM_FIELDS)}), "
            f"got {len(tokens)}"
        )

    def field_name(index: int) -> str:
        return _ODOM_FIELDS[index]

    values = _numbers(tokens, 1, 8, field_name)
    _numbers(tokens, 9, 10, field_name)
    pose = values[0:3]
    _check_finite("ODOM", "pose (x y theta)", pose)
    _check_finite("ODOM", "ipc_timestamp", values[6:7])
    return OdomRecord(timestamp=float(values[6]), pose=pose.copy(), line=line)
