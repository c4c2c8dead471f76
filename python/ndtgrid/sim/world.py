"""Worlds for the laser simulator: line segments (walls, boxes) and circles
(pillars, sticks), and the room of the paper's Fig. 8 experiment.

A circle whose diameter is below :data:`SMALL_DIAMETER` is a *sub-grid
object* (a stick): the laser model of :mod:`ndtgrid.sim.laser` applies the
false detections of §V-A to it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import numpy.typing as npt

__all__ = ["SMALL_DIAMETER", "World", "sticks_room"]

F64 = npt.NDArray[np.float64]

#: Circles thinner than this [m] are sub-grid objects (the paper: 1.3-1.5 cm sticks).
SMALL_DIAMETER = 0.03


def _as_rows(values: npt.ArrayLike, width: int, what: str) -> F64:
    arr = np.asarray(values, dtype=np.float64).reshape(-1, width) if np.size(values) else None
    if arr is None:
        return np.zeros((0, width))
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{what}: expected finite values")
    return arr


@dataclass(frozen=True, eq=False)
class World:
    """A 2D world of line segments and circles (metres, map frame).

    Parameters
    ----------
    segments : array_like, shape (S, 4)
        Segments ``[x0, y0, x1, y1]``: walls and the faces of boxes.
    circles : array_like, shape (C, 3)
        Circles ``[cx, cy, radius]``: pillars, and sticks when the diameter is
        below :data:`SMALL_DIAMETER`.
    materials : tuple of str, optional
        One label per circle (e.g. ``"wood"``, ``"iron"``); only reported.
    tour : array_like, shape (W, 2), optional
        Suggested waypoints for a robot (see :func:`ndtgrid.sim.trajectory`).

    Examples
    --------
    >>> from ndtgrid import sim
    >>> room = sim.sticks_room()
    >>> room.sticks.shape
    (8, 3)
    >>> float(room.distance_to_surface([[0.0, -2.0]])[0])
    0.0
    """

    segments: F64
    circles: F64 = field(default_factory=lambda: np.zeros((0, 3)))
    materials: tuple[str, ...] = ()
    tour: F64 = field(default_factory=lambda: np.zeros((0, 2)))

    def __post_init__(self) -> None:
        segs = _as_rows(self.segments, 4, "segments")
        circ = _as_rows(self.circles, 3, "circles")
        if np.any(circ[:, 2] <= 0):
            raise ValueError("circles: expected radii > 0")
        mats = tuple(self.materials) or ("",) * len(circ)
        if len(mats) != len(circ):
            raise ValueError(f"materials: expected {len(circ)} labels, got {len(mats)}")
        object.__setattr__(self, "segments", segs)
        object.__setattr__(self, "circles", circ)
        object.__setattr__(self, "materials", mats)
        object.__setattr__(self, "tour", _as_rows(self.tour, 2, "tour"))

    @property
    def small(self) -> npt.NDArray[np.bool_]:
        """Shape (C,): which circles are sub-grid objects (sticks)."""
        return np.asarray(2.0 * self.circles[:, 2] < SMALL_DIAMETER)

    @property
    def sticks(self) -> F64:
        """Shape (K, 3): the sticks as ``[x, y, diameter]`` [m]."""
        s = self.circles[self.small]
        return np.column_stack([s[:, :2], 2.0 * s[:, 2]])

    @property
    def stick_materials(self) -> tuple[str, ...]:
        """The material label of each stick, in the order of :attr:`sticks`."""
        return tuple(m for m, s in zip(self.materials, self.small) if s)

    def with_box(self, x0: float, y0: float, x1: float, y1: float) -> World:
        """A copy with an axis-aligned box added.

        Parameters
        ----------
        x0, y0, x1, y1 : float
            Corners of the box ``[x0, x1] x [y0, y1]`` [m].

        Returns
        -------
        World
            This world with the box's four walls added to ``segments``.
        """
        box = np.array(
            [[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]],
            dtype=np.float64,
        )
        return replace(self, segments=np.vstack([self.segments, box]))

    def with_circle(self, x: float, y: float, radius: float, material: str = "") -> World:
        """A copy with a circle added (a stick if thinner than :data:`SMALL_DIAMETER`).

        Parameters
        ----------
        x, y : float
            Centre [m].
        radius : float
            Radius [m].
        material : str, default ""
            Its material (e.g. ``"wood"``, ``"iron"``; see ``materials``).

        Returns
        -------
        World
            This world with the circle added to ``circles``.
        """
        return replace(
            self,
            circles=np.vstack([self.circles, [[x, y, radius]]]),
            materials=(*self.materials, material),
        )

    def translated(self, dx: float, dy: float) -> World:
        """A copy moved by ``(dx, dy)``: surfaces, sticks and tour.

        Parameters
        ----------
        dx, dy : float
            Translation [m].

        Returns
        -------
        World
            The moved world.
        """
        shift = np.array([dx, dy], dtype=np.float64)
        return replace(
            self,
            segments=self.segments + np.tile(shift, 2),
            circles=self.circles + np.append(shift, 0.0),
            tour=self.tour + shift,
        )

    def distance_to_surface(self, points: npt.ArrayLike) -> F64:
        """Distance [m] from each point to the nearest surface.

        Parameters
        ----------
        points : array_like, shape (N, 2)
            Map-frame points [m].

        Returns
        -------
        ndarray, shape (N,)
            Distance to the nearest segment or circle boundary (``inf`` in an
            empty world).
        """
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        best = np.full(len(p), np.inf)
        if len(self.segments):
            a, b = self.segments[:, :2], self.segments[:, 2:]
            ab = b - a
            denom = np.maximum(np.einsum("sk,sk->s", ab, ab), 1e-300)
            ap = p[:, None, :] - a[None, :, :]
            t = np.clip(np.einsum("nsk,sk->ns", ap, ab) / denom, 0.0, 1.0)
            closest = a[None] + t[..., None] * ab[None]
            best = np.minimum(best, np.linalg.norm(p[:, None] - closest, axis=2).min(axis=1))
        if len(self.circles):
            d = np.linalg.norm(p[:, None, :] - self.circles[None, :, :2], axis=2)
            best = np.minimum(best, np.abs(d - self.circles[None, :, 2]).min(axis=1))
        return best

    def surface_points(self, spacing: float = 0.005) -> F64:
        """Points on every surface (for plots).

        Parameters
        ----------
        spacing : float, default 0.005
            Distance between neighbouring points along a surface [m] (about).

        Returns
        -------
        ndarray, shape (N, 2)
            The points [m], wall by wall, then circle by circle.
        """
        out = []
        for x0, y0, x1, y1 in self.segments:
            n = max(2, int(np.hypot(x1 - x0, y1 - y0) / spacing) + 1)
            t = np.linspace(0.0, 1.0, n)[:, None]
            out.append((1 - t) * [x0, y0] + t * [x1, y1])
        for cx, cy, r in self.circles:
            n = max(8, int(2 * np.pi * r / spacing) + 1)
            a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
            out.append(np.column_stack([cx + r * np.cos(a), cy + r * np.sin(a)]))
        return np.vstack(out) if out else np.zeros((0, 2))


#: Wooden sticks of the paper's experiment (§VI): 1.5 cm, centres [m]. The
#: millimetres keep them off the 2 cm lattice's lines (a stick centred on a
#: cell boundary would flatter any cell-based measure).
_WOOD = [
    (-0.803, -1.647),
    (0.906, -0.953),
    (2.047, 0.494),
    (1.007, 1.652),
    (-0.894, 0.957),
    (-2.052, -0.605),
]
#: Iron sticks: 1.3 cm; the first is "the iron stick at the center" of Fig. 9.
_IRON = [(0.004, 0.347), (1.196, -0.356)]


def sticks_room() -> World:
    """The world of the paper's Fig. 8 experiment, as far as the text describes it.

    A 5 m x 4 m room (``x`` in [-2.5, 2.5], ``y`` in [-2, 2]) with a cabinet
    against the north wall, a 20 cm round pillar, six wooden sticks of 1.5 cm
    and two iron sticks of 1.3 cm (§VI). Several sticks stand 35-45 cm in
    front of a wall, the case of Fig. 7(b). The suggested :attr:`World.tour`
    starts at ``(-1.7, 0)``, runs a 3.4 m x 2.6 m loop around the centre and
    then crosses the room along ``y = 0``; it passes every stick at 35 cm, inside the 0.5 m
    reliable range (Area 1), and sees each of them from farther away too.

    Returns
    -------
    World
        With 8 sticks (``sticks``, ``stick_materials``: 6 ``"wood"``, then
        2 ``"iron"``) and the tour.
    """
    world = World(
        segments=np.array(
            [
                [-2.5, -2.0, 2.5, -2.0],
                [2.5, -2.0, 2.5, 2.0],
                [2.5, 2.0, -2.5, 2.0],
                [-2.5, 2.0, -2.5, -2.0],
            ]
        ),
        circles=np.array([[-1.0, -0.45, 0.10]]),
        materials=("pillar",),
        tour=np.array(
            [
                [-1.7, 0.0],
                [-1.7, -1.3],
                [1.7, -1.3],
                [1.7, 1.3],
                [-1.7, 1.3],
                [-1.7, 0.0],
                [1.7, 0.0],
            ]
        ),
    ).with_box(-0.4, 1.75, 0.4, 2.0)
    for x, y in _WOOD:
        world = world.with_circle(x, y, 0.015 / 2, "wood")
    for x, y in _IRON:
        world = world.with_circle(x, y, 0.013 / 2, "iron")
    return world
