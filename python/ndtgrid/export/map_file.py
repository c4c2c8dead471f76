"""A map file that loads back identical: the grid's exact cell state in a numpy ``.npz``.

This is a stopgap: the versioned, checksummed binary format (``NdtGrid.save`` /
``NdtGrid.load``, also used by pickle) is a later issue. The ``.npz`` holds the arrays of
:meth:`ndtgrid.NdtGrid.cell_states` (eq. 6 sums about each cell's centre, so nothing is
rounded on the way) and ``cell_size``, ``format`` and ``version`` entries.
"""

from __future__ import annotations

import os

import numpy as np

from ndtgrid._core import NdtGrid

__all__ = ["FORMAT", "VERSION", "load_map", "save_map"]

#: Value of the ``format`` entry.
FORMAT = "ndtgrid-cells"
#: Value of the ``version`` entry.
VERSION = 1


def save_map(path: str | os.PathLike[str], grid: NdtGrid) -> None:
    """Save a grid's cells to an ``.npz`` file.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write (numpy adds ``.npz`` when the name lacks it).
    grid : NdtGrid
        The map.
    """
    indices, counts, sums, scatters = grid.cell_states()
    np.savez_compressed(
        path,
        format=np.array(FORMAT),
        version=np.array(VERSION),
        cell_size=np.array(grid.cell_size),
        indices=indices,
        counts=counts,
        sums=sums,
        scatters=scatters,
    )


def load_map(path: str | os.PathLike[str]) -> NdtGrid:
    """Load a grid saved by :func:`save_map`.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.npz`` file.

    Returns
    -------
    NdtGrid
        A grid with exactly the saved cells (``cell_states()`` equal bit for bit).

    Raises
    ------
    ValueError
        If the file is not a map file of this version, or a cell is invalid (message names
        the file).
    """
    with np.load(path, allow_pickle=False) as data:
        fmt = str(data["format"]) if "format" in data.files else None
        version = int(data["version"]) if "version" in data.files else None
        if fmt != FORMAT or version != VERSION:
            raise ValueError(
                f"{path}: expected an {FORMAT} map file of version {VERSION}, got format "
                f"{fmt!r} version {version!r}"
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
