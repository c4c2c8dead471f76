"""A small deterministic room and ray caster for the Python tests (numpy only).

The full laser simulator is ``ndtgrid.sim``; this fixture keeps the core tests
independent of it.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]

#: Walls ``(x0, y0, x1, y1)`` [m]: a 6 m x 4 m room, a box, a pillar, a diagonal.
WALLS = np.array(
    [
        [-3, -2, 3, -2],
        [3, -2, 3, 2],
        [3, 2, -3, 2],
        [-3, 2, -3, -2],
        [1, 0.5, 2, 1.5],
        [-1.8, 0.5, -1.2, 0.5],
        [-1.2, 0.5, -1.2, 1.1],
        [-1.2, 1.1, -1.8, 1.1],
        [-1.8, 1.1, -1.8, 0.5],
        [0.35, -1.35, 0.65, -1.35],
        [0.65, -1.35, 0.65, -1.05],
        [0.65, -1.05, 0.35, -1.05],
        [0.35, -1.05, 0.35, -1.35],
    ],
    dtype=float,
)


def scan(
    pose: npt.ArrayLike, beams: int = 683, fov_deg: float = 240.0, noise: float = 0.0, seed: int = 0
) -> F64:
    """Scan-frame points of a laser at ``pose`` [x, y, theta] in the room."""
    x, y, th = np.asarray(pose, dtype=float)
    a = np.linspace(-np.radians(fov_deg) / 2, np.radians(fov_deg) / 2, beams)
    d = np.stack([np.cos(th + a), np.sin(th + a)], axis=1)
    p0, e = WALLS[:, :2], WALLS[:, 2:] - WALLS[:, :2]
    w = p0[None, :, :] - np.array([x, y])[None, None, :]
    den = d[:, None, 0] * e[None, :, 1] - d[:, None, 1] * e[None, :, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[..., 0] * e[None, :, 1] - w[..., 1] * e[None, :, 0]) / den
        u = (w[..., 0] * d[:, None, 1] - w[..., 1] * d[:, None, 0]) / den
    t = np.where((np.abs(den) > 1e-12) & (t > 1e-9) & (u >= 0) & (u <= 1), t, np.inf)
    r = t.min(axis=1)
    ok = np.isfinite(r)
    r = r[ok] + np.random.default_rng(seed).normal(0.0, noise, ok.sum())
    return np.stack([r * np.cos(a[ok]), r * np.sin(a[ok])], axis=1)
