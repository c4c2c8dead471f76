"""The occupancy image and a trajectory as a PNG (needs the extra ``plot``: matplotlib)."""

from __future__ import annotations

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
    grey = np.select([image.cells == 100, image.cells == 0], [0.0, 1.0], default=0.8)
    h, w = image.cells.shape
    x0, y0 = (float(v) for v in image.origin)
    extent = (x0, x0 + w * image.resolution, y0, y0 + h * image.resolution)
    fig, ax = plt.subplots(figsize=(8, 8 * h / max(w, 1) + 0.5))
    try:
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
