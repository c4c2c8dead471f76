"""A deterministic 2D laser range finder with the false detections of §V-A.

The model, beam by beam (all numbers are :class:`Laser` fields):

1. **Footprint.** A beam is a spot of angular width ``footprint``, cast as
   ``sub_rays`` parallel rays across it. The nearest sub-ray hit is the near
   surface; the fraction ``f`` of sub-rays that hit within ``coverage_gap`` of
   it is the spot's coverage. Fully covered beams return the mean range of
   the covered sub-rays.
2. **Mixed returns behind edges** (§V-A, Fig. 7a). A partly covered beam
   (``min_coverage <= f < 1``) returns a range *behind* the near surface:
   ``r_near + (1 - f) * min(r_far - r_near, edge_tail)``, where ``r_far`` is
   the median range of the uncovered sub-rays (``inf`` when they hit nothing).
   Below ``min_coverage`` the near object is missed and the far range returns.
3. **Small object in front of a wall** (§V-A, Fig. 7b). When the near surface
   is a sub-grid object (a stick), lies beyond ``reliable_range`` and a wall
   or big object stands at most ``backshift_reach`` behind it along the beam,
   every return from it reads ``backshift`` behind its surface (instead of
   the mixing of 2.), never past that wall. Within ``reliable_range`` sticks
   are measured correctly.
4. **Wall speckle** (§V-A, "surface of wall"). A fully covered beam on a big
   surface returns, with probability ``speckle_probability``, a range off by
   a uniform ``speckle_offset`` (either sign).
5. **Noise and limits.** Gaussian range noise of standard deviation
   ``max(range_sigma, range_sigma_relative * r)``, rounding to
   ``range_resolution``, dropouts with probability ``dropout``; ranges outside
   ``[min_range, max_range)`` and misses return ``0`` ("no return", as the
   URG-04LX reports it).

The random draws per scan are a fixed set of arrays, so a seed gives the same
scan whatever the geometry.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ndtgrid.sim.world import World

__all__ = ["SICK_LMS", "URG04LX", "Laser", "cast_rays"]

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]


def cast_rays(
    world: World, origin: npt.ArrayLike, directions: F64, *, sticks: bool = True
) -> tuple[F64, I64]:
    """Nearest intersection of rays from one origin with the world's surfaces.

    Parameters
    ----------
    world : World
        The surfaces.
    origin : array_like, shape (2,)
        Ray origin [m].
    directions : ndarray, shape (..., 2)
        Unit ray directions.
    sticks : bool, default True
        ``False`` ignores the sub-grid circles (what lies behind a stick).

    Returns
    -------
    ranges : ndarray, shape (...)
        Distance to the nearest hit [m], ``inf`` for none.
    surface : ndarray, shape (...)
        Index of the surface hit: ``0 .. S-1`` segments, ``S .. S+C-1``
        circles, ``-1`` none.
    """
    o = np.asarray(origin, dtype=np.float64)
    shape = directions.shape[:-1]
    d = directions.reshape(-1, 2)
    best = np.full(len(d), np.inf)
    which = np.full(len(d), -1, dtype=np.int64)
    segs = world.segments
    if len(segs):
        a, e = segs[:, :2], segs[:, 2:] - segs[:, :2]
        w = a - o
        den = d[:, None, 0] * e[None, :, 1] - d[:, None, 1] * e[None, :, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (w[None, :, 0] * e[None, :, 1] - w[None, :, 1] * e[None, :, 0]) / den
            u = (w[None, :, 0] * d[:, None, 1] - w[None, :, 1] * d[:, None, 0]) / den
        t = np.where((np.abs(den) > 1e-12) & (t > 1e-9) & (u >= 0) & (u <= 1), t, np.inf)
        k = np.argmin(t, axis=1)
        tk = t[np.arange(len(d)), k]
        hit = tk < best
        best[hit], which[hit] = tk[hit], k[hit]
    circ = world.circles
    keep = np.ones(len(circ), dtype=bool) if sticks else ~world.small
    if len(circ) and keep.any():
        idx = np.flatnonzero(keep)
        c = circ[idx]
        oc = o - c[:, :2]
        b = d @ oc.T
        cc = np.einsum("ck,ck->c", oc, oc) - c[:, 2] ** 2
        disc = b * b - cc[None, :]
        with np.errstate(invalid="ignore"):
            t = -b - np.sqrt(disc)
        t = np.where((disc >= 0) & (t > 1e-9), t, np.inf)
        k = np.argmin(t, axis=1)
        tk = t[np.arange(len(d)), k]
        hit = tk < best
        best[hit], which[hit] = tk[hit], len(segs) + idx[k[hit]]
    return best.reshape(shape), which.reshape(shape)


@dataclass(frozen=True)
class Laser:
    """A 2D laser range finder and its false detections (see the module docstring).

    Attributes
    ----------
    name : str
        Label.
    num_beams : int
        Beams per scan.
    angle_min, angle_max : float
        Angles of the first and last beam in the sensor frame [rad], counter-clockwise.
    min_range, max_range : float
        Valid ranges [m]; others return 0.
    range_sigma : float
        Standard deviation of the range noise at short range [m].
    range_sigma_relative : float
        Beyond ``range_sigma / range_sigma_relative`` the standard deviation
        is this fraction of the range.
    range_resolution : float
        Ranges are rounded to it [m].
    footprint : float
        Full angular width of a beam's spot [rad].
    sub_rays : int
        Rays cast across the spot.
    coverage_gap : float
        Sub-ray hits within it of the nearest belong to the near surface [m].
    min_coverage : float
        Coverage below which the near surface is missed.
    edge_tail : float
        Largest shift behind an edge of a mixed return with nothing behind [m].
    reliable_range : float
        Beyond it sticks in front of walls are shifted backward [m].
    backshift : float
        That shift [m] (the paper's Fig. 7b: 5 cm).
    backshift_reach : float
        Only with a wall at most this far behind the stick [m].
    speckle_probability : float
        Per fully covered beam on a big surface.
    speckle_offset : tuple of float
        Range of the speckle offset magnitude [m].
    dropout : float
        Probability that a beam returns nothing.
    """

    name: str
    num_beams: int
    angle_min: float
    angle_max: float
    min_range: float
    max_range: float
    range_sigma: float
    range_resolution: float
    footprint: float
    range_sigma_relative: float = 0.0
    sub_rays: int = 9
    coverage_gap: float = 0.02
    min_coverage: float = 0.3
    edge_tail: float = 0.06
    reliable_range: float = 0.5
    backshift: float = 0.05
    backshift_reach: float = 1.0
    speckle_probability: float = 0.002
    speckle_offset: tuple[float, float] = (0.03, 0.20)
    dropout: float = 0.005

    @property
    def angles(self) -> F64:
        """Beam angles in the sensor frame [rad], shape (B,)."""
        return np.linspace(self.angle_min, self.angle_max, self.num_beams)

    @property
    def angle_increment(self) -> float:
        """Angle between adjacent beams [rad]."""
        return (self.angle_max - self.angle_min) / (self.num_beams - 1)

    def scan(
        self,
        world: World,
        pose: npt.ArrayLike,
        rng: np.random.Generator | int | None = None,
    ) -> tuple[F64, F64]:
        """One scan of ``world`` from the sensor pose ``pose``.

        Parameters
        ----------
        world : World
            What the laser sees.
        pose : array_like, shape (3,)
            Sensor pose ``[x, y, theta]`` (m, m, rad) in the world frame.
        rng : numpy.random.Generator or int, optional
            Source of noise, or a seed; ``None`` means seed 0.

        Returns
        -------
        ranges : ndarray, shape (B,)
            Ranges [m]; 0 where there is no return.
        angles : ndarray, shape (B,)
            Beam angles in the sensor frame [rad] (:attr:`angles`).
        """
        gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng or 0)
        x, y, th = (float(v) for v in np.asarray(pose, dtype=np.float64).reshape(3))
        angles = self.angles
        b = len(angles)
        # Random draws first, a fixed set per scan.
        noise = gen.normal(0.0, 1.0, b)
        speckle_draw = gen.random(b)
        speckle_size = gen.uniform(*self.speckle_offset, b)
        speckle_sign = np.where(gen.random(b) < 0.5, -1.0, 1.0)
        dropout_draw = gen.random(b)

        offsets = np.linspace(-0.5, 0.5, self.sub_rays) * self.footprint
        phi = th + angles[:, None] + offsets[None, :]
        dirs = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
        r_all, hit = cast_rays(world, (x, y), dirs)
        near = r_all.min(axis=1)
        covered = r_all <= near[:, None] + self.coverage_gap
        f = covered.mean(axis=1)
        r_cov = np.where(covered, r_all, 0.0).sum(axis=1) / np.maximum(covered.sum(axis=1), 1)
        # The far range: the (lower) median of the uncovered sub-rays, which
        # sort after the covered ones.
        n_cov = covered.sum(axis=1)
        n_sub = r_all.shape[1]
        pick = np.minimum(n_cov + (n_sub - n_cov - 1) // 2, n_sub - 1)
        r_far = np.sort(r_all, axis=1)[np.arange(len(r_all)), pick]
        r_far = np.where(n_cov < n_sub, r_far, np.inf)

        ranges = r_cov.copy()
        partial = (f < 1.0) & (f >= self.min_coverage)
        ranges[partial] = r_cov[partial] + (1.0 - f[partial]) * np.minimum(
            r_far[partial] - r_cov[partial], self.edge_tail
        )
        missed = f < self.min_coverage
        ranges[missed] = r_far[missed]

        # The near surface of each beam: the hit of its nearest sub-ray.
        near_id = hit[np.arange(b), np.argmin(r_all, axis=1)]
        n_seg = len(world.segments)
        small_ids = n_seg + np.flatnonzero(world.small)
        on_stick = ~missed & np.isin(near_id, small_ids)
        if self.backshift > 0 and on_stick.any():
            axis_dir = np.stack([np.cos(th + angles), np.sin(th + angles)], axis=-1)
            behind, _ = cast_rays(world, (x, y), axis_dir, sticks=False)
            with np.errstate(invalid="ignore"):
                gap = np.where(on_stick, behind - r_cov, np.inf)
            shifted = on_stick & (r_cov > self.reliable_range) & (gap <= self.backshift_reach)
            ranges[shifted] = np.minimum(r_cov[shifted] + self.backshift, behind[shifted])

        sigma = np.maximum(self.range_sigma, self.range_sigma_relative * np.nan_to_num(ranges))
        ranges = ranges + sigma * noise
        big = (f >= 1.0) & ~on_stick & np.isfinite(ranges)
        speckled = big & (speckle_draw < self.speckle_probability)
        ranges[speckled] += speckle_sign[speckled] * speckle_size[speckled]
        if self.range_resolution > 0:
            ranges = np.round(ranges / self.range_resolution) * self.range_resolution
        bad = (
            ~np.isfinite(ranges)
            | (ranges < self.min_range)
            | (ranges >= self.max_range)
            | (dropout_draw < self.dropout)
        )
        ranges[bad] = 0.0
        return ranges, angles


#: Hokuyo URG-04LX as in the paper (§IV-C): 683 beams over ±120° (the paper
#: rounds the 0.352° step to 0.36°), 4 m, ±10 mm (taken as 2 sigma) at every
#: range as the paper states it; a spot of two beam steps (the catalogue's
#: smallest object, 1°, spans 3 spots). The data sheet's ±1 % beyond 1 m is
#: ``dataclasses.replace(URG04LX, range_sigma_relative=0.005)``.
URG04LX = Laser(
    name="URG-04LX",
    num_beams=683,
    angle_min=float(np.radians(-120.0)),
    angle_max=float(np.radians(120.0)),
    min_range=0.02,
    max_range=4.0,
    range_sigma=0.005,
    range_resolution=0.001,
    footprint=float(np.radians(0.70)),
)

#: A SICK LMS-like scanner: 361 beams over 180° (0.5°), 8 m indoors,
#: sigma 1 cm, a 0.5° spot. Sticks are not shifted (no Fig. 7b data for it);
#: the other effects keep the URG-04LX numbers. Indicative, not measured.
SICK_LMS = Laser(
    name="SICK LMS",
    num_beams=361,
    angle_min=float(np.radians(-90.0)),
    angle_max=float(np.radians(90.0)),
    min_range=0.05,
    max_range=8.0,
    range_sigma=0.01,
    range_resolution=0.001,
    footprint=float(np.radians(0.5)),
    backshift=0.0,
)
