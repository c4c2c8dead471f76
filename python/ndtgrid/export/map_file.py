"""Map files: the versioned, checksummed ndtgrid format, and the ``.npz`` of earlier releases.

:func:`save_map` writes :meth:`ndtgrid.NdtGrid.save`'s file (``.ndtgrid`` by
convention): magic bytes ``NDTGRID\\0``, kind, format version, payload length and a
CRC-32, then the grid's exact cell state (eq. 6 sums about each cell's centre, so
nothing is rounded), its cell size and pyramid levels. It is written atomically (a
temporary file beside the target, synced, then renamed over it). Pickling a grid uses
the same bytes. See the README's "Persistence" section.

:func:`load_map` reads that format, and, for back-compatibility, the ``.npz`` map
files that earlier releases wrote (numpy arrays of :meth:`~ndtgrid.NdtGrid.cell_states`
with ``format = "ndtgrid-cells"``, ``version = 1``, ``cell_size`` entries); such a
grid gets the default pyramid levels, as it did then.
"""

from __future__ import annotations

import os

import numpy as np

from ndtgrid._core import FORMAT_VERSION, Mapper, NdtGrid

__all__ = ["FORMAT_VERSION", "MAGIC", "NPZ_FORMAT", "NPZ_VERSION", "load_map", "save_map"]

#: The first bytes of every ndtgrid file.
MAGIC = b"NDTGRID\x00"
#: The ``format`` entry of the ``.npz`` map files of earlier releases.
NPZ_FORMAT = "ndtgrid-cells"
#: The ``version`` entry of those files.
NPZ_VERSION = 1
#: The first bytes of a zip archive (an ``.npz`` file).
_ZIP_MAGIC = b"PK\x03\x04"


def save_map(path: str | os.PathLike[str], grid: NdtGrid | Mapper) -> None:
    """Save a map to an ndtgrid file, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write (replaced whole if it exists; ``.ndtgrid`` by convention).
    grid : NdtGrid or Mapper
        The map: a grid file for an :class:`~ndtgrid.NdtGrid`, a mapper file (grid and
        filter state) for a :class:`~ndtgrid.Mapper`.

    Raises
    ------
    TypeError
        If ``grid`` is neither an :class:`~ndtgrid.NdtGrid` nor a
        :class:`~ndtgrid.Mapper` (nothing is written).
    OSError
        If the file cannot be written (the message names it; an existing file is left
        as it was).
    """
    if not isinstance(grid, (NdtGrid, Mapper)):
        raise TypeError(f"grid: expected an NdtGrid or a Mapper, got {type(grid).__name__}")
    grid.save(path)


def load_map(path: str | os.PathLike[str]) -> NdtGrid:
    """Load a grid saved by :func:`save_map` (or an ``.npz`` map of an earlier release).

    Parameters
    ----------
    path : str or os.PathLike
        A grid file, or a legacy ``.npz`` map file.

    Returns
    -------
    NdtGrid
        A grid with exactly the saved cells (``cell_states()`` equal bit for bit).

    Raises
    ------
    OSError
        If the file cannot be read (the message names it).
    ValueError
        If the file is not a grid file of a supported version, is corrupt, or a cell
        is invalid (the message names the file and the problem).
    """
    with open(path, "rb") as f:
        head = f.read(len(_ZIP_MAGIC))
    if head == _ZIP_MAGIC:
        return _load_npz(path)
    return NdtGrid.load(path)


def _load_npz(path: str | os.PathLike[str]) -> NdtGrid:
    """The grid of an ``.npz`` map file of an earlier release."""
    with np.load(path, allow_pickle=False) as data:
        fmt = str(data["format"]) if "format" in data.files else None
        version = int(data["version"]) if "version" in data.files else None
        if fmt != NPZ_FORMAT or version != NPZ_VERSION:
            raise ValueError(
                f"{path}: expected an {NPZ_FORMAT} map file of version {NPZ_VERSION}, got "
                f"format {fmt!r} version {version!r}"
            )
        try:
            grid: NdtGrid = NdtGrid.from_cell_states(
                float(data["cell_size"]),
                data["indices"],
                data["counts"],
                data["sums"],
                data["scatters"],
            )
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
    return grid
