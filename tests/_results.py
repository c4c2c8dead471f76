"""Match results as exact values, for tests that compare results bit for bit."""

from __future__ import annotations

from typing import Any

import ndtgrid


def exact(r: ndtgrid.MatchResult) -> tuple[Any, ...]:
    """Everything a match returns, as exact bytes."""
    return (
        r.pose.tobytes(),
        r.converged,
        r.iterations,
        float(r.score).hex(),
        r.num_matched,
        r.hessian.tobytes(),
        r.covariance.tobytes(),
        r.unconstrained.tobytes(),
        r.unconstrained.shape,
    )
