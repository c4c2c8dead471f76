"""Pictures of ``benches/subgrid.py``: Fig. 8/9-style maps and the real log's maps.

matplotlib is imported lazily; without it the pictures raise an ``ImportError`` naming the
``plot`` extra.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from subgrid_common import CELL, F64, FALSE_DISTANCE, Scenario

import ndtgrid


def _plt() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as err:  # pragma: no cover - optional dependency
        raise ImportError("the pictures need matplotlib: pip install ndtgrid[plot]") from err
    return plt


def _draw_cells(ax: Any, cells: F64, color: str = "black") -> None:
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Rectangle

    rects = [Rectangle((x - CELL / 2, y - CELL / 2), CELL, CELL) for x, y in cells]
    ax.add_collection(PatchCollection(rects, facecolor=color, edgecolor="none"))


def plot_fig8(
    out: Path, scn: Scenario, store: dict[str, tuple[ndtgrid.Mapper, F64, Scenario]]
) -> None:
    """Fig. 8/9-style pictures of seed 0 (own poses): off vs all on, whole map and a zoom."""
    plt = _plt()
    world = scn.world
    panels = [("off", "(a) without elimination"), ("all on", "(b) with the §V elimination")]
    for zoom, fname, size in (
        (None, "fig8_sticks_room.png", (11, 4.6)),
        (3, "fig9_iron_stick.png", (8, 4)),
    ):
        fig, axes = plt.subplots(1, 2, figsize=size, constrained_layout=True)
        for ax, (name, title) in zip(axes, panels):
            mapper, used, _ = store[name]
            cells = mapper.occupied_cells()
            _draw_cells(ax, cells)
            ax.plot(used[:, 0], used[:, 1], color="0.6", lw=0.8)
            for x, y, d in world.sticks:
                ax.add_patch(plt.Circle((x, y), d / 2, fill=False, color="red", lw=1.0))
            for o in mapper.small_objects():
                ax.plot(*o.center, "+", color="tab:blue", ms=8 if zoom else 5, mew=1.2)
            if zoom is None:
                ax.set_xlim(-2.7, 2.7)
                ax.set_ylim(-2.2, 2.2)
                false_cells = int((world.distance_to_surface(cells) > FALSE_DISTANCE).sum())
                ax.set_title(f"{title}\n{len(cells)} cells, {false_cells} false (> 3 cm)")
            else:
                x, y, _ = world.sticks[6]
                ax.set_xlim(x - 0.2, x + 0.2)
                ax.set_ylim(y - 0.2, y + 0.2)
                ax.set_title(f"{title}\niron stick at the centre", fontsize=10)
                ax.grid(True, color="0.9", lw=0.5)
            ax.set_aspect("equal")
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]")
        fig.suptitle(
            "Simulated sticks room, URG-04LX model, own poses, 2 cm cells\n"
            "black: occupied cells, red: true sticks, +: detected small objects",
            fontsize=9,
        )
        fig.savefig(out / fname, dpi=110)
        plt.close(fig)


def plot_real(out: Path, maps: dict[str, tuple[ndtgrid.Mapper, F64]]) -> None:
    """The real log's maps: off and on at the same poses, and on with its own matching."""
    plt = _plt()
    names = ("off", "all on", "all on, own matching")
    fig, axes = plt.subplots(1, 3, figsize=(16, 6), constrained_layout=True)
    for ax, name in zip(axes, names):
        mapper, used = maps[name]
        cells = mapper.occupied_cells()
        _draw_cells(ax, cells)
        ax.plot(used[:, 0], used[:, 1], color="tab:orange", lw=0.8)
        ax.set_title(f"exp1.dat, elimination {name}: {len(cells)} cells", fontsize=10)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.savefig(out / "real_exp1_off_on.png", dpi=100)
    plt.close(fig)
