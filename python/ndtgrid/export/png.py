"""The occupancy image and a trajectory as a PNG (needs the extra ``plot``: matplotlib)."""

from __future__ import annotations

import math
import os
from typing import Any

import numpy as np
import numpy.typing as npt

from .ros_map import OccupancyImage

__all__ = ["write_png"]


def _pyplot() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("writing PNG images needs matplotlib: pip install ndtgrid[plot]") from exc
    return plt


def write_png(
    path: str | os.PathLike[str],
    image: OccupancyImage,
    *,
    trajectory: npt.ArrayLike | None = None,
    title: str | None = None,
    dpi: int = 150,
) -> None:
    """Draw an occupancy image (black occupied, white free, grey unknown) and a trajectory.

    Parameters
    ----------
    path : str or os.PathLike
        The PNG to write.
    image : OccupancyImage
        The map.
    trajectory : array_like, shape (T, 3) or (T, 2), optional
        Poses or positions to draw as a line [m].
    title : str, optional
        Title of the figure.
    dpi : int, default 150
        Resolution of the file.

    Raises
    ------
    ImportError
        Without matplotlib (names ``pip install ndtgrid[plot]``).
    """
    plt = _pyplot()
    h, w = image.cells.shape
    fig, ax = plt.subplots(figsize=(8, 8 * h / max(w, 1) + 0.5))
    try:
        # Pixels of the axes in the file: an image with more cells is first reduced to
        # them (a large log's image, drawn whole, took gigabytes and dropped walls).
        box = ax.get_position()
        pixels = (box.height * fig.get_figheight() * dpi, box.width * fig.get_figwidth() * dpi)
        factor = max(1, math.ceil(max(h / pixels[0], w / pixels[1])))
        grey = _reduced(image.cells, factor)
        x0, y0 = (float(v) for v in image.origin)
        side = factor * image.resolution
        extent = (x0, x0 + grey.shape[1] * side, y0, y0 + grey.shape[0] * side)
        ax.imshow(
            grey,
            cmap="gray",
            vmin=0.0,
            vmax=1.0,
            origin="lower",
            extent=extent,
            interpolation="nearest",
        )
        if trajectory is not None:
            t = np.asarray(trajectory, dtype=np.float64)
            ax.plot(t[:, 0], t[:, 1], "-", color="tab:red", linewidth=0.6, label="trajectory")
            ax.legend(loc="upper right")
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        if title:
            ax.set_title(title)
        fig.savefig(os.fspath(path), dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(fig)


def _reduced(cells: npt.NDArray[np.int8], factor: int) -> npt.NDArray[np.float64]:
    """The grey levels of ``cells`` (occupancy values: 100 occupied, 0 free, -1 unknown)
    in blocks of ``factor`` x ``factor`` cells: black where a block holds an occupied
    cell, else white where it holds a free one, else grey (so a wall one cell thick is
    still drawn). Blocks past the image's edge are unknown."""
    rank = np.where(cells == 100, np.int8(2), (cells == 0).astype(np.int8))
    if factor > 1:
        h, w = rank.shape
        padded = np.zeros((-(-h // factor) * factor, -(-w // factor) * factor), np.int8)
        padded[:h, :w] = rank
        rank = padded.reshape(padded.shape[0] // factor, factor, -1, factor).max(axis=(1, 3))
    grey: npt.NDArray[np.float64] = np.array([0.8, 1.0, 0.0])[rank]
    return grey
