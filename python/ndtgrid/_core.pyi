"""Type stubs of the compiled core ``ndtgrid._core`` (Rust, PyO3)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
F64Array = npt.NDArray[np.float64]
I64Array = npt.NDArray[np.int64]

class MatchResult:
    """Outcome of :meth:`NdtGrid.match`; frozen.

    Attributes
    ----------
    pose : ndarray, shape (3,)
        Best pose ``[x, y, theta]`` (m, m, rad) of the scan in the map frame.
    converged : bool
        The Newton step fell below the tolerances (not merely ran out of
        iterations, lost every point, or failed its line search).
    iterations : int
        Newton steps taken.
    score : float
        ``E(p)`` of eq. (1) at ``pose``, with the distributions used (expanded
        by ``k``, fused, neighbour-paired).
    num_matched : int
        Points that had a reference distribution at ``pose``.
    hessian : ndarray, shape (3, 3)
        Hessian of ``-E`` at ``pose`` in the order ``(x, y, theta)``.
    covariance : ndarray, shape (3, 3)
        Pose covariance estimate ``H^-1`` (Laplace approximation treating ``E``
        as a log-likelihood). Eigenvalues of ``H`` below ``1e-9 * max|lambda|``
        (directions the scan does not constrain) are floored, giving very large
        but finite variances there.
    unconstrained : ndarray, shape (K, 3)
        Pose directions ``(dx, dy, dtheta)`` the scan does not constrain: the
        eigenvectors of the Hessian, with rotation scaled to arc length at the
        scan's RMS radius ``L``, whose eigenvalue is below 2 % of the largest.
        Each row is scaled so that ``dx**2 + dy**2 + (L * dtheta)**2 = 1``. A
        long corridor gives one row along the corridor. Empty (K = 0) when the
        scan constrains every direction.
    degenerate : bool
        ``len(unconstrained) > 0``: fall back on odometry along those rows.
    """

    @property
    def pose(self) -> F64Array: ...
    @property
    def converged(self) -> bool: ...
    @property
    def iterations(self) -> int: ...
    @property
    def score(self) -> float: ...
    @property
    def num_matched(self) -> int: ...
    @property
    def hessian(self) -> F64Array: ...
    @property
    def covariance(self) -> F64Array: ...
    @property
    def unconstrained(self) -> F64Array: ...
    @property
    def degenerate(self) -> bool: ...

class NdtGrid:
    """Sparse, unbounded NDT grid map (paper §III-B).

    Each cell keeps only the sums of eq. (6): the point count ``M``, the sum
    ``m`` and the outer-product sum ``S``; never the points. Memory grows with
    the mapped area, not with the number of scans.

    Parameters
    ----------
    cell_size : float, default 0.02
        Side of the square cells [m] (the paper: 2 cm).
    levels : int, default 6
        Levels of the multi-resolution pyramid kept with the map (1 = the fine
        grid only, at most 12). Level ``l`` has cells ``cell_size * 2**l``; its
        sums are exact sums of the fine cells' (no points are stored, nothing
        is rebuilt), so coarse-to-fine matching (``match(levels=...)``) costs
        no extra data.

    Raises
    ------
    ValueError
        If ``cell_size`` is not a finite number > 0 or ``levels`` is not in 1..12.

    Notes
    -----
    Thread safety: any number of threads may call :meth:`match`,
    :meth:`evaluate`, :meth:`cells` at once (the GIL is released while they
    run); :meth:`insert` waits for them and runs alone. Every method either
    succeeds or leaves the map unchanged.
    """

    def __init__(self, cell_size: float = 0.02, *, levels: int = 6) -> None: ...
    @property
    def cell_size(self) -> float:
        """Cell size [m]."""
    @property
    def levels(self) -> int:
        """Pyramid levels kept (fine level included)."""
    def __len__(self) -> int:
        """Number of cells holding at least one point."""
    def insert(self, points: ArrayLike, pose: ArrayLike) -> None:
        """Add a scan to the map (eq. 6).

        Parameters
        ----------
        points : array_like, shape (N, 2)
            Scan-frame points [m]; float64 C-contiguous arrays are used without
            a copy, other real dtypes are converted. ``N = 0`` is a no-op.
        pose : array_like, shape (3,)
            ``[x, y, theta]`` (m, m, rad) of the scan in the map frame.

        Raises
        ------
        TypeError
            If an argument is not array-like or holds non-real numbers.
        ValueError
            On a wrong shape, a NaN or infinite value, or a point whose cell
            index would overflow (``|coordinate| >= 2**30 * cell_size``). The
            map is unchanged after any error.
        """
    def match(
        self,
        points: ArrayLike,
        guess: ArrayLike,
        *,
        expansion: float = 10.0,
        neighbor_search: bool = True,
        fuse_minority: bool = True,
        pair_neighbors: bool = False,
        search_radius: int = 1,
        max_iterations: int = 50,
        translation_tolerance: float = 1e-4,
        rotation_tolerance: float = 1e-4,
        max_step_cells: float = 2.0,
        max_step_rotation: float = 0.05,
        rotation_search: float = 0.15,
        freeze_unconstrained: bool = True,
        levels: int | None = None,
        expansion_phases: Sequence[float] | None = None,
    ) -> MatchResult:
        """Match a scan against the map by Newton's method on eq. (1).

        The defaults are the paper's method (§IV-A: k = 10, neighbour search and
        fusion on) run coarse to fine over the pyramid (2-64 cm on a 2 cm
        grid), with a rotational multi-start on the coarsest level and the
        directions the scan does not constrain frozen: the best setting
        measured by ``benches/convergence.py`` (BENCHMARK.md). The paper's
        method alone is ``levels=1, rotation_search=0.0,
        freeze_unconstrained=False, search_radius=3``; the original NDT of
        Biber & Strasser on the same grid is additionally ``expansion=1.0,
        neighbor_search=False, fuse_minority=False``.

        Parameters
        ----------
        points : array_like, shape (N, 2)
            Scan-frame points [m], N >= 1.
        guess : array_like, shape (3,)
            Initial pose ``[x, y, theta]`` (m, m, rad).
        expansion : float, default 10.0
            ``k`` of eq. (8): both covariance eigenvalues are multiplied by it.
        neighbor_search : bool, default True
            §IV-A(1): a point whose own cell has no distribution is paired with
            the distribution whose mean is nearest to it among the first ring of
            cells (Chebyshev distance 1, 2, ..., ``search_radius``) that holds any.
        fuse_minority : bool, default True
            §IV-A(3): a cell with fewer than 3 points takes the distribution of
            the summed eq. (6) terms of itself and its 8 neighbours.
        pair_neighbors : bool, default False
            Score each point against every distribution of the 3x3 block of
            cells around it (summed, as Biber's overlapping grids and
            Magnusson's NDT do) instead of its own cell's alone; points with
            none there fall back to the neighbour search. Smooths the score of
            fine cells.
        search_radius : int, default 1
            Neighbour-search radius [cells], at most 1000. Larger radii
            measured worse on real scan pairs (points get paired with the wrong
            wall); the pyramid provides the wide basin instead.
        max_iterations : int, default 50
            Newton steps at most.
        translation_tolerance, rotation_tolerance : float, default 1e-4
            Convergence thresholds on the step [m], [rad].
        max_step_cells : float, default 2.0
            Largest translation per Newton step [cells]; keeps the solver inside
            the narrow basin of a fine grid.
        max_step_rotation : float, default 0.05
            Largest rotation per Newton step [rad].
        rotation_search : float, default 0.15
            Half-width [rad] of the rotational multi-start of the first
            (coarsest) stage: it also solves from the guess turned by +/- this
            angle and keeps the best score; 0 turns it off.
        freeze_unconstrained : bool, default True
            From the second pyramid stage on, project Newton steps onto the
            pose directions the scan constrains (point-to-plane information,
            see ``MatchResult.unconstrained``): along a corridor's axis the
            pose stays where the guess and the coarse stages put it instead of
            being dragged by fine cells ("solution remapping").
        levels : int, optional
            Pyramid levels to match on, coarse to fine (1 = the fine grid only,
            the paper's method; at most the grid's ``levels``). By default as
            many as keep the coarsest cell at most 0.64 m: 6 levels (2-64 cm)
            on a 2 cm grid, 2 on a 20 cm grid. Stage ``l``
            (from ``levels - 1`` down to 0) starts from the previous stage's
            pose and maximises the summed score of its level and the next
            coarser one, so the last stage includes the fine cells.
        expansion_phases : sequence of float, optional
            The phased adjustment of the authors' earlier paper (ICRA 2008):
            solve with each ``k`` in turn (e.g. ``[100, 10, 1]``), each from the
            previous result; overrides ``expansion``.

        Returns
        -------
        MatchResult
            Not converging is a result (``converged=False``), not an exception.

        Raises
        ------
        TypeError, ValueError
            As for :meth:`insert`; also for an empty scan, a guess that is not 3
            finite values, or an option out of range.
        """
    def evaluate(
        self,
        points: ArrayLike,
        pose: ArrayLike,
        *,
        expansion: float = 10.0,
        neighbor_search: bool = True,
        fuse_minority: bool = True,
        pair_neighbors: bool = False,
        search_radius: int = 1,
    ) -> tuple[float, F64Array, F64Array, int]:
        """Score terms at ``pose`` without solving.

        Returns
        -------
        score : float
            ``E(p)`` of eq. (1).
        gradient : ndarray, shape (3,)
            Gradient of ``-E`` (eq. 4).
        hessian : ndarray, shape (3, 3)
            Hessian of ``-E`` (eq. 5).
        num_matched : int
            Points with a reference distribution.
        """
    def cells(self) -> tuple[F64Array, I64Array]:
        """Occupied cells, sorted by cell index.

        Returns
        -------
        centers : ndarray, shape (K, 2)
            Cell centres [m].
        counts : ndarray, shape (K,)
            Point counts ``M``.
        """
    def cell_statistics(self) -> tuple[I64Array, I64Array, F64Array, F64Array]:
        """The eq. (6) sums of every cell in map coordinates, sorted by index.

        Returns
        -------
        indices : ndarray, shape (K, 2)
            Integer cell indices ``floor(x / cell_size)``.
        counts : ndarray, shape (K,)
            ``M``.
        sums : ndarray, shape (K, 2)
            ``m = sum x`` [m].
        scatters : ndarray, shape (K, 2, 2)
            ``S = sum x x^T`` [m^2].
        """

def default_match_options() -> dict[str, Any]:
    """The core's defaults for :meth:`NdtGrid.match`."""

def compose(a: ArrayLike, b: ArrayLike) -> F64Array:
    """``a o b``: pose ``b`` (given in frame ``a``) in ``a``'s parent frame, shape (3,)."""

def inverse(p: ArrayLike) -> F64Array:
    """The inverse motion of ``p``, shape (3,)."""

def between(a: ArrayLike, b: ArrayLike) -> F64Array:
    """``a^-1 o b``: the motion from ``a`` to ``b`` in ``a``'s frame, shape (3,)."""

def ranges_to_points(
    ranges: ArrayLike,
    angles: ArrayLike,
    *,
    min_range: float = 0.0,
    max_range: float = ...,
) -> F64Array:
    """Scan-frame points of the valid beams of a laser scan.

    Parameters
    ----------
    ranges : array_like, shape (B,)
        Ranges [m]. Beams with a range that is 0, NaN, infinite, below
        ``min_range`` or at or above ``max_range`` are skipped.
    angles : array_like, shape (B,)
        Beam angles in the sensor frame [rad]; must be finite.
    min_range : float, default 0.0
        Smallest valid range [m].
    max_range : float, default inf
        Ranges at or above it mean "no return" [m].

    Returns
    -------
    ndarray, shape (N, 2)
        ``(r cos a, r sin a)`` of the N valid beams, in beam order.

    Raises
    ------
    ValueError
        If the lengths differ, an angle is not finite or the limits are invalid.
    """
