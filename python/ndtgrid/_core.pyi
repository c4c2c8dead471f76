"""Type stubs of the compiled core ``ndtgrid._core`` (Rust, PyO3)."""

from __future__ import annotations

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

class NdtGrid:
    """Sparse, unbounded NDT grid map (paper §III-B).

    Each cell keeps only the sums of eq. (6): the point count ``M``, the sum
    ``m`` and the outer-product sum ``S``; never the points. Memory grows with
    the mapped area, not with the number of scans.

    Parameters
    ----------
    cell_size : float, default 0.02
        Side of the square cells [m] (the paper: 2 cm).

    Raises
    ------
    ValueError
        If ``cell_size`` is not a finite number > 0.

    Notes
    -----
    Thread safety: any number of threads may call :meth:`match`,
    :meth:`evaluate`, :meth:`cells` at once (the GIL is released while they
    run); :meth:`insert` waits for them and runs alone. Every method either
    succeeds or leaves the map unchanged.
    """

    def __init__(self, cell_size: float = 0.02) -> None: ...
    @property
    def cell_size(self) -> float:
        """Cell size [m]."""
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
        search_radius: int = 3,
        max_iterations: int = 50,
        translation_tolerance: float = 1e-4,
        rotation_tolerance: float = 1e-4,
        max_step_cells: float = 2.0,
        max_step_rotation: float = 0.05,
    ) -> MatchResult:
        """Match a scan against the map by Newton's method on eq. (1).

        The defaults are the paper's method (§IV-A). The original NDT of Biber
        & Strasser on the same grid is ``expansion=1.0, neighbor_search=False,
        fuse_minority=False``.

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
        search_radius : int, default 3
            Neighbour-search radius [cells], at most 1000.
        max_iterations : int, default 50
            Newton steps at most.
        translation_tolerance, rotation_tolerance : float, default 1e-4
            Convergence thresholds on the step [m], [rad].
        max_step_cells : float, default 2.0
            Largest translation per Newton step [cells]; keeps the solver inside
            the narrow basin of a fine grid.
        max_step_rotation : float, default 0.05
            Largest rotation per Newton step [rad].

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
        search_radius: int = 3,
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
    def cell_states(self) -> tuple[I64Array, I64Array, F64Array, F64Array]:
        """The exact state of every cell, sorted by index (what a map file stores).

        Returns
        -------
        indices : ndarray of int64, shape (K, 2)
            Integer cell indices ``floor(x / cell_size)``.
        counts : ndarray of int64, shape (K,)
            ``M``.
        sums : ndarray, shape (K, 2)
            ``m`` about the cell's own centre [m] (the grid's internal form, so
            nothing is rounded).
        scatters : ndarray, shape (K, 2, 2)
            ``S`` about the cell's own centre [m^2].
        """
    @staticmethod
    def from_cell_states(
        cell_size: float,
        indices: ArrayLike,
        counts: ArrayLike,
        sums: ArrayLike,
        scatters: ArrayLike,
    ) -> NdtGrid:
        """A grid holding exactly the given cell states (see :meth:`cell_states`).

        Raises
        ------
        ValueError
            On an invalid cell size, shapes that disagree, or a cell with a count
            below 1, a non-finite sum, an index beyond +-2**30 or an index given
            twice (the message names the cell's position).
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

class OdometryStep:
    """What one :meth:`OdometryLoop.step` did; frozen.

    Attributes
    ----------
    pose : ndarray, shape (3,)
        Pose ``[x, y, theta]`` (m, m, rad) the loop settled on.
    prediction : ndarray, shape (3,)
        The motion prior the match started from (odometry increment, or constant
        velocity when there is no odometry or it failed / disagreed and lost).
    matched : bool
        A match was run (there was a map and a valid point).
    accepted : bool
        The match was used (``num_matched >= min_match_ratio * num_points``);
        otherwise ``pose`` is the prediction.
    inserted : bool
        The scan was added to the map.
    converged, iterations, num_matched
        Of the match (False, 0, 0 without one).
    num_points : int
        Valid points of the scan.
    """

    @property
    def pose(self) -> F64Array: ...
    @property
    def prediction(self) -> F64Array: ...
    @property
    def matched(self) -> bool: ...
    @property
    def accepted(self) -> bool: ...
    @property
    def inserted(self) -> bool: ...
    @property
    def converged(self) -> bool: ...
    @property
    def iterations(self) -> int: ...
    @property
    def num_matched(self) -> int: ...
    @property
    def num_points(self) -> int: ...

class OdometryLoop:
    """The core's scan-to-map odometry loop (wrapped by :class:`ndtgrid.Odometry`).

    Keyword arguments left at ``None`` take the core's defaults
    (:func:`default_odometry_config`); see :class:`ndtgrid.OdometryConfig` for
    their meaning and units.

    Raises
    ------
    ValueError
        If a setting is out of range (the message names it).
    """

    def __init__(
        self,
        cell_size: float = 0.02,
        *,
        min_range: float | None = None,
        max_range: float | None = None,
        insert_distance: float | None = None,
        insert_angle: float | None = None,
        map_window: int | None = None,
        min_match_ratio: float | None = None,
        rotation_search: float | None = None,
        rotation_step: float | None = None,
        prior_gap_distance: float | None = None,
        prior_gap_angle: float | None = None,
        expansion: float | None = None,
        neighbor_search: bool | None = None,
        fuse_minority: bool | None = None,
        search_radius: int | None = None,
        max_iterations: int | None = None,
        max_step_cells: float | None = None,
        max_step_rotation: float | None = None,
    ) -> None: ...
    def step(
        self, ranges: ArrayLike, angles: ArrayLike, odom: ArrayLike | None = None
    ) -> OdometryStep:
        """Process one scan (ranges (B,) [m], angles (B,) [rad], odom (3,) or None).

        Raises
        ------
        TypeError, ValueError
            On a wrong shape or type, lengths that differ, a non-finite angle or
            odom; the loop is unchanged after an error. The GIL is released.
        """
    @property
    def poses(self) -> F64Array:
        """Pose of every scan so far, shape (T, 3)."""
    @property
    def insertions(self) -> int:
        """Scans added to the map so far."""
    def __len__(self) -> int:
        """Cells in the map now."""
    def grid(self) -> NdtGrid:
        """A copy of the map."""
    def config(self) -> dict[str, Any]:
        """The settings in force, as keyword arguments (plus ``cell_size``)."""

def default_odometry_config() -> dict[str, Any]:
    """The core's default :class:`OdometryLoop` settings (with ``cell_size``)."""

class FreeSpace:
    """Cells crossed by laser beams, for occupancy exports (ROS maps, images).

    Each beam walks the lattice from the sensor to its hit (Amanatides & Woo)
    and counts one pass in every cell before the hit's own cell.

    Parameters
    ----------
    resolution : float, default 0.05
        Cell size [m].

    Raises
    ------
    ValueError
        If ``resolution`` is not a finite number > 0.
    """

    def __init__(self, resolution: float = 0.05) -> None: ...
    @property
    def resolution(self) -> float:
        """Cell size [m]."""
    def __len__(self) -> int:
        """Cells crossed by at least one beam."""
    def add_scan(self, points: ArrayLike, pose: ArrayLike) -> None:
        """Trace the beams from the sensor at ``pose`` (3,) to the scan-frame ``points`` (N, 2) [m].

        Raises
        ------
        TypeError, ValueError
            On a wrong shape, a non-finite value or a coordinate beyond the
            lattice; nothing changes after an error.
        """
    def raster(
        self, occupied: ArrayLike, *, max_cells: int = 100_000_000
    ) -> tuple[npt.NDArray[np.int8], F64Array]:
        """Dense occupancy image covering the traced cells and ``occupied`` (K, 2) points.

        Returns
        -------
        image : ndarray of int8, shape (H, W)
            Row 0 at the lowest y: 100 occupied (a point falls in the cell), 0
            free (a beam passed), -1 unknown.
        origin : ndarray, shape (2,)
            Map-frame position of the outer corner of cell (0, 0) [m].

        Raises
        ------
        ValueError
            If there is nothing to draw, or the image would exceed ``max_cells``.
        """
