"""Rigid motions of the plane on ``[x, y, theta]`` arrays (m, m, rad).

The arithmetic is the core's (eq. 2 of the paper: ``x' = R(theta) x + t``);
angles come back wrapped to (-pi, pi].

Examples
--------
>>> import numpy as np
>>> from ndtgrid import se2
>>> a = np.array([1.0, 0.0, np.pi / 2])
>>> se2.compose(a, [1.0, 0.0, 0.0]).round(6).tolist()
[1.0, 1.0, 1.570796]
>>> se2.between(a, se2.compose(a, [0.5, 0.2, 0.1])).round(6).tolist()
[0.5, 0.2, 0.1]
"""

from __future__ import annotations

from ndtgrid._core import between, compose, inverse

__all__ = ["between", "compose", "inverse"]
