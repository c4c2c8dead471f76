"""Type stubs of the compiled core ``ndtgrid._core`` (Rust, PyO3)."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from typing import Any, TypedDict, final

import numpy as np
import numpy.typing as npt
from typing_extensions import Self, Unpack

__version__: str
#: The version of the ndtgrid file format this build writes (and the only one it reads).
FORMAT_VERSION: int

_ArrayLike = npt.ArrayLike
_F64Array = npt.NDArray[np.float64]
_I64Array = npt.NDArray[np.int64]
# Scans given together: a list of (N_i, 2) arrays, or one (K, N, 2) array.
_Scans = Sequence[_ArrayLike] | npt.NDArray[Any]

__all__ = [
    "FORMAT_VERSION",
    "FreeSpace",
    "Mapper",
    "MapperOptions",
    "MatchResult",
    "NdtGrid",
    "OdometryLoop",
    "OdometryStep",
    "RemovalCounts",
    "SmallObject",
    "__version__",
    "between",
    "compose",
    "default_mapper_options",
    "default_match_options",
    "default_odometry_config",
    "inverse",
    "preset_match_options",
    "ranges_to_points",
    "vector_extension",
]

class _MatchOptions(TypedDict, total=False):
    """The keyword options of :meth:`NdtGrid.match`, as :meth:`NdtGrid.match_many`
    takes them (see :meth:`NdtGrid.match` for each one's meaning and default); for
    type checkers only, it does not exist at run time."""

    expansion: float
    sigma_floor: float
    shape_cell: float
    neighbor_search: bool
    fuse_minority: bool
    pair_neighbors: bool
    search_radius: int
    max_iterations: int
    translation_tolerance: float
    rotation_tolerance: float
    max_step_cells: float
    max_step_rotation: float
    rotation_search: float
    rotation_gate: float
    freeze_unconstrained: bool
    freeze_ratio: float
    levels: int | None
    skip_levels: Sequence[int] | None
    coarse_model: bool
    expansion_phases: Sequence[float] | None
    parallel: bool

@final
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
    def pose(self) -> _F64Array: ...
    @property
    def converged(self) -> bool: ...
    @property
    def iterations(self) -> int: ...
    @property
    def score(self) -> float: ...
    @property
    def num_matched(self) -> int: ...
    @property
    def hessian(self) -> _F64Array: ...
    @property
    def covariance(self) -> _F64Array: ...
    @property
    def unconstrained(self) -> _F64Array: ...
    @property
    def degenerate(self) -> bool: ...
    def __reduce__(self) -> tuple[Callable[..., MatchResult], tuple[Any]]:
        """Pickle (and :mod:`copy`) by value: the class's ``_restore`` and the fields."""

@final
class NdtGrid:
    """Sparse, unbounded NDT grid map (paper §III-B).

    Each cell keeps only the sums of eq. (6): the point count ``M``, the sum
    ``m`` and the outer-product sum ``S``; never the points. Memory grows with
    the mapped area, not with the number of scans.

    Parameters
    ----------
    cell_size : float, default 0.02
        Side of the square cells [m] (the paper: 2 cm), at least 1 mm.
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
    Thread safety: many readers, one exclusive writer. Any number of threads
    may call :meth:`match`, :meth:`evaluate`, :meth:`cells`,
    :meth:`cell_states` at once (the GIL is released while they run);
    :meth:`insert` and :meth:`insert_many` wait for them and run alone. A match
    sees the map as it was between two inserts (or batches of
    :meth:`insert_many`), never half of one, and its result is bit for
    bit that of matching that state alone (distributions are prepared lazily
    but are a function of the cells' sums only). Every method either succeeds
    or leaves the map unchanged.
    """

    def __new__(cls, cell_size: float = 0.02, *, levels: int = 6) -> Self: ...
    @property
    def cell_size(self) -> float:
        """Cell size [m]."""
    @property
    def levels(self) -> int:
        """Pyramid levels kept (fine level included)."""
    def __len__(self) -> int:
        """Number of cells holding at least one point."""
    @property
    def memory_bytes(self) -> int:
        """Heap bytes the grid holds: the sums of every pyramid level and the
        distributions prepared for matching (built by the first ``match`` with
        a given set of options, kept up to date by ``insert``), look-up
        tables included. An estimate from the tables' capacities (hashbrown's
        layout; the allocator's own overhead is not counted):
        ``memory_bytes / len(grid)`` is the cost of an occupied cell."""
    def insert(self, points: _ArrayLike, pose: _ArrayLike) -> None:
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
    def insert_many(self, scans: _Scans, poses: _ArrayLike) -> None:
        """Add many scans to the map in one call (eq. 6 for each, in order).

        The map afterwards is, bit for bit, the one that :meth:`insert` gives
        scan by scan, but the coarser pyramid levels and the distributions
        prepared for matching are brought up to date once for the whole batch
        instead of after every scan. Consecutive scans of a log see mostly the
        same surfaces, so that upkeep, most of a single insert's work, is
        shared: building a map from a log whose poses are known (ground truth,
        a finished SLAM run, an optimised trajectory) takes less time per scan
        the longer the batch (benches/SPEED_LOG.md, session 37). The GIL is
        released once for the whole batch; matches wait for it to finish. The
        keys of the cells each scan changed (8 bytes a cell and scan) wait for
        the batch's end, so a very long log is best given in batches of some
        hundreds of scans.

        Parameters
        ----------
        scans : sequence of array_like, shape (N_i, 2)
            Scan-frame points [m] of each scan (a list of arrays, or one array
            of shape (K, N, 2)); a scan with ``N_i = 0`` adds nothing.
        poses : array_like, shape (K, 3)
            ``[x, y, theta]`` (m, m, rad) of each scan in the map frame, one row
            per scan.

        Raises
        ------
        TypeError
            If ``scans`` is not a sequence of arrays (one ``(N, 2)`` array is one
            scan: use :meth:`insert`) or an argument holds non-real numbers.
        ValueError
            On a number of poses other than one per scan, a wrong shape, or a
            scan :meth:`insert` would reject: the message names the first such
            scan (``"scan 3: points: ..."``). Every scan is checked before the
            map changes, so after any error the map is unchanged.
        """
    def match(
        self,
        points: _ArrayLike,
        guess: _ArrayLike,
        *,
        expansion: float = 10.0,
        sigma_floor: float = 0.02,
        shape_cell: float = 0.32,
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
        rotation_gate: float = 0.9,
        freeze_unconstrained: bool = True,
        freeze_ratio: float = 0.1,
        levels: int | None = None,
        skip_levels: Sequence[int] | None = None,
        coarse_model: bool = True,
        expansion_phases: Sequence[float] | None = None,
        parallel: bool = False,
    ) -> MatchResult:
        """Match a scan against the map by Newton's method on eq. (1).

        The defaults are the paper's method (§IV-A: k = 10, neighbour search and
        fusion on) run coarse to fine over the pyramid (2-64 cm on a 2 cm
        grid), with a rotational multi-start on the coarsest level, the
        directions the scan does not constrain frozen and fine cells shaped by
        their 32 cm ancestor: the best setting
        measured by ``benches/convergence.py`` (BENCHMARK.md). The paper's
        method alone is ``levels=1, rotation_search=0.0,
        freeze_unconstrained=False, search_radius=3, sigma_floor=0.005,
        shape_cell=0.0`` (``ndtgrid.presets.PAPER``); the original NDT of
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
        sigma_floor : float, default 0.02
            Smallest standard deviation [m] a cell's distribution is given before
            the expansion: the scatter between two scans of one surface (range
            noise, beam footprint, sampling; a URG-04LX is good to +-10 mm, a
            SICK LMS to +-15 mm). 2 cm was chosen among 0.5-3 cm on the real
            pairs of ``benches/convergence.py`` and confirmed on 960 held-out
            SICK pairs (``benches/sigma_floor.py``, BENCHMARK.md); lower it for
            a more precise sensor.
        shape_cell : float, default 0.32
            Cells finer than this [m] keep their own mean but take the covariance
            of the pyramid cell of at least this size that holds them (the wall
            segment they lie on), so that fine cells constrain a scan across a
            surface and hardly along it: against a single sparse scan, isotropic
            2 cm blobs pull the match towards where that scan sampled a wall (in
            a corridor, towards zero motion). 0 turns it off (the paper's
            distributions, eq. 7 and fusion).
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
            angle and keeps the best score; 0 turns it off. Above the fine
            level the turned starts are first solved on centroids of runs of
            scan points (voxels half the coarsest cell), and solved on every
            point only when they land above the best score so far.
        rotation_gate : float, default 0.9
            Over several levels, the multi-start runs only when the first stage's
            solve from the guess scores below this per scan point (eq. 1; a point's
            term is at most 1, and a scan drawn from its distributions scores about
            k / (k + 1)): a first stage that explains nearly every point is not in a
            wrong rotational basin. On real SICK pairs 0.9 kept all but 7 / 2 of 6189 /
            6054 successes from local / wide starts (none lost on held-out SICK,
            URG-04LX and simulated pairs) and took the median match of real URG-04LX
            scans of at least 500 points from about 0.21-0.27 to 0.18-0.22 ms
            (``benches/rotation_gate.py``, ``BENCHMARK.md``). ``inf``: always; 0:
            never. A one-level match (``levels=1``) always runs it: its first stage
            is its last.
        freeze_unconstrained : bool, default True
            From the second pyramid stage on, project Newton steps onto the
            pose directions the scan constrains well (point-to-plane information:
            curvature at least ``freeze_ratio`` of the strongest, a stricter test
            than the 2 % of ``MatchResult.unconstrained``): along a corridor's
            axis the pose stays where the guess and the coarse stages put it
            instead of being dragged by fine cells ("solution remapping").
        freeze_ratio : float, default 0.1
            The curvature ratio (in [0, 1]) below which ``freeze_unconstrained``
            freezes a direction (0.1 measured best of 0.005-0.2, BENCHMARK.md).
        levels : int, optional
            Pyramid levels to match on, coarse to fine (1 = the fine grid only,
            the paper's method; at most the grid's ``levels``). By default as
            many as keep the coarsest cell at most 0.64 m: 6 levels (2-64 cm)
            on a 2 cm grid, 2 on a 20 cm grid. Stage ``l``
            (from ``levels - 1`` down to 0) starts from the previous stage's
            pose and maximises the summed score of its level and the next
            coarser one (that one as its quadratic model, see
            ``coarse_model``), so the last stage includes the fine cells.
        skip_levels : sequence of int or None, default None
            Pyramid levels (1 to 11) the stages pass over: a skipped level is
            neither matched on nor prepared, and the stage below it pairs with
            the next matched coarser level. The coarsest matched level is
            matched whatever this says. ``None``: ``(1,)``, level 1 (4 cm on a
            2 cm grid); ``()``: every level. Skipping 4 cm
            kept the successes of the benchmark's scan-to-scan pairs (6173 /
            6050 of 7680 real SICK starts against 6182 / 6052 on every level,
            held-out 6151 / 6064 against 6139 / 6060; from starts up to
            ±1.2 m and ±30° as many or more) and matches 16-27 % faster; an
            insert then keeps one level's distributions fewer
            (``benches/SPEED_LOG.md``, session 18).
        coarse_model : bool, default True
            From the second stage on, score the coarser level of the stage by
            its second-order expansion about the stage's start (the same
            expansion a Newton step makes) instead of every point at every
            trial pose; the returned score and Hessian are computed exactly at
            the final pose. About 40 % fewer passes over the scan (median match
            0.22 against 0.31 ms on the real SICK pairs of
            ``benches/convergence.py``, 6189 against 6204 successes of 7680);
            ``False`` scores every level exactly.
        expansion_phases : sequence of float, optional
            The phased adjustment of the authors' earlier paper (ICRA 2008):
            solve with each ``k`` in turn (e.g. ``[100, 10, 1]``), each from the
            previous result; overrides ``expansion``.
        parallel : bool, default False
            Score scans of at least 2048 points on all cores (rayon's pool;
            ``RAYON_NUM_THREADS`` limits it), in fixed chunks of 512 points
            summed in order: the pose does not depend on the number of threads
            and differs from the one-thread result in the last bits. Off by
            default, as Python threads matching different scans, or
            ``match_many``, use the cores with less hand-over (the GIL is
            released). On 2 cores 2048 / 8192 / 32000 points matched
            1.31-1.39 / 1.76-1.85 / 1.65-1.79x faster than on one thread
            (``cargo bench``). Rayon's pool starts with the first such
            match, one thread per CPU the calling thread may run on, on those
            CPUs, and keeps them: make that match on a thread not pinned to one
            CPU, or every later one runs on that CPU alone.

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
    def match_many(
        self,
        scans: _Scans,
        guesses: _ArrayLike,
        *,
        threads: int | None = None,
        **options: Unpack[_MatchOptions],
    ) -> list[MatchResult]:
        """Match many scans against the map, each from its guess, on several threads.

        ``grid.match_many(scans, guesses, **options)[i]`` is, bit for bit,
        ``grid.match(scans[i], guesses[i], **options)``, whatever the number of
        threads: each scan is matched by one thread from start to end, and the
        scans only read the map. The GIL is released once for the whole batch;
        the calling thread matches scans beside helper threads started for the
        batch (a new thread goes to an idle core), each taking the next scan not
        yet taken, so one call keeps every core busy with no Python threads of
        the caller's: relocalisation from several hypotheses, loop-closure
        candidates, a log matched again against a finished map. Like :meth:`match`, it runs
        beside other readers of the map and waits for an :meth:`insert` to
        finish.

        Parameters
        ----------
        scans : sequence of array_like, shape (N_i, 2)
            Scan-frame points [m] of each scan, N_i >= 1 (a list of arrays, or
            one array of shape (K, N, 2)).
        guesses : array_like, shape (K, 3)
            Initial pose ``[x, y, theta]`` (m, m, rad) of each scan, one row per
            scan.
        threads : int, optional
            Threads that match: the calling thread and ``threads - 1`` helpers,
            at most one thread per two scans (a helper costs about 0.1 ms before
            its first scan is done, so a batch of 2 or 3 scans stays on the
            calling thread). ``None`` (default): one per CPU the calling
            thread may run on (``len(os.sched_getaffinity(0))`` on Linux, read
            at each call, and no more than the cgroup's CPU quota): a helper
            inherits the CPUs of the thread that starts it, so from a thread
            pinned to one CPU the batch stays on the calling thread; 1: one
            scan after the other on the calling thread (with the GIL
            released). A helper the system refuses to start leaves its share
            to the others.
        **options
            Any keyword option of :meth:`match`, with the same default.

        Returns
        -------
        list of MatchResult
            In the order of ``scans``; empty for an empty batch.

        Raises
        ------
        TypeError
            If ``scans`` is not a sequence of arrays (one ``(N, 2)`` array is one
            scan: use :meth:`match`), an option is not one of :meth:`match`'s or
            has the wrong type.
        ValueError
            On a number of guesses other than one per scan, ``threads < 1``, an
            option out of range, or a scan :meth:`match` would reject: the
            message names the first such scan (``"scan 3: points: ..."``). The
            inputs are checked before any scan is matched.
        RuntimeError
            If a helper thread failed (an internal error).
        """
    def evaluate(
        self,
        points: _ArrayLike,
        pose: _ArrayLike,
        *,
        expansion: float = 10.0,
        sigma_floor: float = 0.02,
        shape_cell: float = 0.32,
        neighbor_search: bool = True,
        fuse_minority: bool = True,
        pair_neighbors: bool = False,
        search_radius: int = 1,
    ) -> tuple[float, _F64Array, _F64Array, int]:
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
    def cells(self) -> tuple[_F64Array, _I64Array]:
        """Occupied cells, sorted by cell index.

        Returns
        -------
        centers : ndarray, shape (K, 2)
            Cell centres [m].
        counts : ndarray, shape (K,)
            Point counts ``M``.
        """
    def cell_states(self) -> tuple[_I64Array, _I64Array, _F64Array, _F64Array]:
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
        indices: _ArrayLike,
        counts: _ArrayLike,
        sums: _ArrayLike,
        scatters: _ArrayLike,
    ) -> NdtGrid:
        """A grid holding exactly the given cell states (see :meth:`cell_states`).

        Raises
        ------
        ValueError
            On an invalid cell size, shapes that disagree, or a cell with a count
            below 1, a non-finite sum, an index beyond +-2**30 or an index given
            twice (the message names the cell's position).
        """
    def cell_statistics(self) -> tuple[_I64Array, _I64Array, _F64Array, _F64Array]:
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
    def to_bytes(self) -> bytes:
        """The grid as the bytes of a grid file (exactly what :meth:`save` writes).

        Equal grids give equal bytes. Pickling (and :mod:`copy`) uses these bytes.

        Returns
        -------
        bytes
            Header (magic ``NDTGRID\\0``, kind, format version, payload length,
            CRC-32) and payload (cell size, pyramid levels, every cell's exact
            state).
        """
    @classmethod
    def from_bytes(cls, data: bytes) -> NdtGrid:
        """The grid of a grid file's bytes (see :meth:`to_bytes`).

        Parameters
        ----------
        data : bytes
            The bytes of a grid file.

        Returns
        -------
        NdtGrid
            The saved grid, bit for bit: equal :meth:`cell_states`, cell size and
            levels, and so equal :meth:`match` results.

        Raises
        ------
        ValueError
            If the bytes are not an ndtgrid file, are a mapper file, have an
            unsupported format version, are truncated or longer than their header
            says, fail the checksum, or hold an invalid payload; the message says
            which.
        """
    def save(self, path: str | os.PathLike[str]) -> None:
        """Save the grid to a file, atomically.

        The bytes of :meth:`to_bytes` go to a temporary file in the same directory,
        which is synced to disk and renamed over ``path``: the file is always either
        the old one or the new one, whole. The GIL is released while writing.

        Parameters
        ----------
        path : str or os.PathLike
            The file to write (``.ndtgrid`` by convention; replaced if it exists).

        Raises
        ------
        OSError
            If the file cannot be written (e.g. ``FileNotFoundError`` for a missing
            directory); the message names the file. ``path`` is then untouched and no
            temporary file is left.
        """
    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> NdtGrid:
        """Load a grid saved by :meth:`save`.

        Parameters
        ----------
        path : str or os.PathLike
            A grid file.

        Returns
        -------
        NdtGrid
            The saved grid, bit for bit (see :meth:`from_bytes`).

        Raises
        ------
        OSError
            If the file cannot be read (``FileNotFoundError``, ``IsADirectoryError``,
            ...); the exception's ``filename`` is ``path``.
        ValueError
            If the file is not a valid grid file (see :meth:`from_bytes`); the message
            starts with ``path``.
        """
    def __reduce__(self) -> tuple[Callable[[bytes], NdtGrid], tuple[bytes]]: ...

@final
class MapperOptions:
    """Options of :class:`Mapper`: the elimination of false detections of §V; frozen.

    Keyword-only; the defaults are the paper's values where it gives them. Every
    step can be switched off alone; ``outlier_filter=False`` switches all of them
    off (the unfiltered map). The clustering of step a-1 always runs while the
    filter is on, because b-1, b-2 and d need to know which clusters are small.

    Parameters
    ----------
    outlier_filter : bool, default True
        Master switch for all of §V.
    edge_removal : bool, default True
        Steps a-2 to a-4 (§V-B(1), "edge of object"): in each small cluster of a
        new scan, drop the points behind its centre of mass (mixed returns land
        behind a thin object's edges) and keep only its forefront cell (the cell
        holding the centre of mass of the remaining points).
    area1_confirmation : bool, default True
        Step b-1 (§V-B(2)): at each periodic check, delete the cells of small
        objects never observed from Area 1 (within ``reliable_range``).
    backshift_rejection : bool, default True
        Step b-2 (§V-B(2)): do not store a point of a small cluster in Area 2 when
        the map already holds a cell within ``backshift_window`` short of it along
        its beam (beyond the reliable range a thin object in front of a wall is
        measured shifted backward).
    observation_check : bool, default True
        Step c (§V-B(3), "surface of wall"): at each periodic check, delete cells
        observed in fewer than ``min_observations`` scans once they have had
        ``check_interval`` scans to be seen.
    radial_confirmation : bool, default True
        Step d (§V-B(4)): walk each new beam from the sensor to its hit and remove
        the map cells it passed through (free space now): cells of small objects
        only within the reliable range, big ones everywhere (which also removes
        objects that moved).
    min_range : float, default 0.0
        Ranges below it are invalid [m].
    max_range : float, default inf
        Ranges at or above it are invalid, "no return" [m].
    reliable_range : float, default 0.5
        Area 1 / Area 2 boundary [m] (the paper: 0.5 m for 2 cm objects and a
        URG-04LX).
    cluster_gap : float, default 0.05
        a-1: consecutive points at most this far apart [m], plus
        ``cluster_spacing_factor`` times the spacing of adjacent beams at their
        range, belong to one cluster.
    cluster_spacing_factor : float, default 2.0
        a-1: see ``cluster_gap``.
    small_object_size : float, default 0.05
        a-1: a cluster whose extent across the beam is at most this [m] is a
        small (sub-grid) object.
    behind_com_margin : float, default 0.0
        a-3: points more than this [m] behind the centre of mass are dropped.
    backshift_window : float, default 0.10
        b-2: how far short of a new point a former cell rejects it [m] (the
        paper measured a 5 cm shift).
    check_interval : int, default 3
        b-1/c: the periodic check runs every this many scans (the paper: 3).
    min_observations : int, default 2
        c: fewest scans a cell must have been observed in.
    observation_support : bool, default True
        c: keep a rarely seen cell that has an established 8-neighbour (seen in
        at least ``min_observations`` scans): a sparsely hit far wall is not
        speckle. Not in the paper.
    clear_margin : float, default 0.03
        d: the walk stops this far [m] short of the hit (or
        ``clear_margin_relative`` times the range if more), divided by
        ``tan(a)`` at grazing angles ``a < 45 deg`` between beam and surface.
    clear_margin_relative : float, default 0.015
        d: see ``clear_margin`` (three standard deviations of a URG-04LX beyond
        1 m).
    pass_radius : float, default 0.005
        d: a cell counts as passed only if the beam passes within this distance
        [m] of the mean of its points; a small object's cell needs beams on both
        sides of it in one scan.

    Raises
    ------
    ValueError
        If a length is negative or not finite, ``max_range <= min_range``, or an
        interval or count is 0.
    TypeError
        For an unknown option.
    """

    def __new__(
        cls,
        *,
        outlier_filter: bool = True,
        edge_removal: bool = True,
        area1_confirmation: bool = True,
        backshift_rejection: bool = True,
        observation_check: bool = True,
        radial_confirmation: bool = True,
        min_range: float = 0.0,
        max_range: float = ...,
        reliable_range: float = 0.5,
        cluster_gap: float = 0.05,
        cluster_spacing_factor: float = 2.0,
        small_object_size: float = 0.05,
        behind_com_margin: float = 0.0,
        backshift_window: float = 0.10,
        check_interval: int = 3,
        min_observations: int = 2,
        observation_support: bool = True,
        clear_margin: float = 0.03,
        clear_margin_relative: float = 0.015,
        pass_radius: float = 0.005,
    ) -> Self: ...
    @property
    def outlier_filter(self) -> bool: ...
    @property
    def edge_removal(self) -> bool: ...
    @property
    def area1_confirmation(self) -> bool: ...
    @property
    def backshift_rejection(self) -> bool: ...
    @property
    def observation_check(self) -> bool: ...
    @property
    def radial_confirmation(self) -> bool: ...
    @property
    def min_range(self) -> float: ...
    @property
    def max_range(self) -> float: ...
    @property
    def reliable_range(self) -> float: ...
    @property
    def cluster_gap(self) -> float: ...
    @property
    def cluster_spacing_factor(self) -> float: ...
    @property
    def small_object_size(self) -> float: ...
    @property
    def behind_com_margin(self) -> float: ...
    @property
    def backshift_window(self) -> float: ...
    @property
    def check_interval(self) -> int: ...
    @property
    def min_observations(self) -> int: ...
    @property
    def observation_support(self) -> bool: ...
    @property
    def clear_margin(self) -> float: ...
    @property
    def clear_margin_relative(self) -> float: ...
    @property
    def pass_radius(self) -> float: ...
    def as_dict(self) -> dict[str, Any]:
        """Every option by name, in the order above."""
    def replace(self, **changes: Any) -> MapperOptions:
        """A copy with some options changed (like :func:`dataclasses.replace`)."""
    def __reduce__(self) -> tuple[Callable[..., MapperOptions], tuple[Any]]:
        """Pickle (and :mod:`copy`) by value: the class's ``_restore`` and the fields."""

@final
class SmallObject:
    """A small (sub-grid scale) object detected by :class:`Mapper`; frozen.

    Attributes
    ----------
    center : ndarray, shape (2,)
        Centre of mass of the object's points [m]: ``sum m / sum M`` over its
        cells (eq. 6 sums), as the paper evaluates its Fig. 8.
    cells : ndarray, shape (K, 2)
        Centres of its cells [m], sorted by cell index. Small-object cells that
        touch (8-neighbourhood) form one object.
    num_points : int
        Points in its cells.
    """

    @property
    def center(self) -> _F64Array: ...
    @property
    def cells(self) -> _F64Array: ...
    @property
    def num_points(self) -> int: ...
    def __reduce__(self) -> tuple[Callable[..., SmallObject], tuple[Any]]:
        """Pickle (and :mod:`copy`) by value: the class's ``_restore`` and the fields."""

@final
class RemovalCounts:
    """What each §V step of a :class:`Mapper` removed so far; frozen.

    Steps a-3, a-4 and b-2 drop points of a new scan before they reach the map:
    for them both the points and the cells they would have created (distinct
    cells of the dropped points not in the map after their scan) are counted.
    Steps b-1, c and d delete cells of the map. Counts are cumulative: a cell
    deleted, observed again and deleted again counts twice.

    Attributes
    ----------
    behind_com_points, behind_com_cells : int
        a-3: behind the centre of mass of a small cluster.
    forefront_points, forefront_cells : int
        a-4: outside the forefront cell of a small cluster.
    area1_cells : int
        b-1: small-object cells never observed from Area 1.
    backshift_points, backshift_cells : int
        b-2: small-cluster points in Area 2 behind a former cell.
    observation_cells : int
        c: cells observed in too few scans.
    confirmation_cells : int
        d: cells passed through by a newer beam.
    """

    @property
    def behind_com_points(self) -> int: ...
    @property
    def behind_com_cells(self) -> int: ...
    @property
    def forefront_points(self) -> int: ...
    @property
    def forefront_cells(self) -> int: ...
    @property
    def area1_cells(self) -> int: ...
    @property
    def backshift_points(self) -> int: ...
    @property
    def backshift_cells(self) -> int: ...
    @property
    def observation_cells(self) -> int: ...
    @property
    def confirmation_cells(self) -> int: ...
    def as_dict(self) -> dict[str, int]:
        """Every counter by name, in step order (a-3, a-4, b-1, b-2, c, d)."""
    def __reduce__(self) -> tuple[Callable[..., RemovalCounts], tuple[Any]]:
        """Pickle (and :mod:`copy`) by value: the class's ``_restore`` and the fields."""

@final
class Mapper:
    """An :class:`NdtGrid` fed scan by scan through the elimination of §V.

    The map a robot navigates with and matches against: laser scans go in as
    ranges and angles, the false detections of sub-grid objects (mixed returns
    behind edges, thin objects in front of walls shifted backward), wall speckle
    and objects that have moved are kept out or removed, and the small objects
    (chair legs, poles) come out with their centres.

    Parameters
    ----------
    cell_size : float, default 0.02
        Side of the square cells [m] (the paper: 2 cm), at least 1 mm.
    outlier_filter : bool, default True
        ``False`` stores every valid point and removes nothing (for comparison).
    **options
        Any field of :class:`MapperOptions` by keyword.

    Raises
    ------
    ValueError
        If ``cell_size`` or an option is out of range.
    TypeError
        For an unknown option.

    Notes
    -----
    :attr:`grid` is the same map, not a copy: matching against it sees every
    insert and removal. Inserting into it directly bypasses the filter (such
    cells count as established, big objects). Thread safety: many readers,
    one exclusive writer: any number of threads may read (``grid.match``,
    :meth:`occupied_cells`, ...) while no scan is being inserted;
    :meth:`insert_scan` and :meth:`run_checks` run alone (inserts from several
    threads are serialized, each scan counted once). The GIL is released while
    the core works. A failed call leaves the map and the filter unchanged.

    Examples
    --------
    >>> import numpy as np, ndtgrid
    >>> mapper = ndtgrid.Mapper(cell_size=0.02)
    >>> angles = np.radians(np.arange(-90.0, 90.5, 0.5))
    >>> mapper.insert_scan(np.full(angles.shape, 2.0), angles, [0.0, 0.0, 0.0])
    >>> mapper.occupied_cells().shape[1], len(mapper.grid) == len(mapper)
    (2, True)
    """

    def __new__(
        cls, cell_size: float = 0.02, *, outlier_filter: bool = True, **options: Any
    ) -> Self: ...
    @property
    def grid(self) -> NdtGrid:
        """The map matched against: an :class:`NdtGrid` sharing this mapper's cells."""
    @property
    def options(self) -> MapperOptions:
        """The options in force."""
    @property
    def cell_size(self) -> float:
        """Cell size [m]."""
    @property
    def scan_count(self) -> int:
        """Scans inserted so far (a scan without a valid beam is not counted)."""
    def __len__(self) -> int:
        """Number of occupied cells."""
    def insert_scan(self, ranges: _ArrayLike, angles: _ArrayLike, pose: _ArrayLike) -> None:
        """Add one laser scan through the elimination of §V.

        Per scan: a-1 cluster the valid beams in beam order; a-2/a-3 in small
        clusters drop the points behind the centre of mass; a-4 keep only their
        forefront cell; b-2 drop small-cluster points in Area 2 lying behind a
        former cell along their beam; store the rest (eq. 6); d remove the cells
        the kept beams passed through; every ``check_interval``-th scan, b-1 and
        c delete cells (see :class:`MapperOptions`).

        Parameters
        ----------
        ranges : array_like, shape (B,)
            Ranges [m]. Beams whose range is 0, negative, NaN, infinite, below
            ``min_range`` or at or above ``max_range`` are skipped; a scan with
            no valid beam (``B = 0`` included) changes nothing, not even
            :attr:`scan_count`.
        angles : array_like, shape (B,)
            Beam angles in the sensor frame [rad], in beam order (clustering
            follows it); must be finite.
        pose : array_like, shape (3,)
            Sensor pose ``[x, y, theta]`` (m, m, rad) in the map frame.

        Raises
        ------
        TypeError
            If an argument is not array-like or holds non-real numbers.
        ValueError
            On a wrong shape, lengths that differ, a non-finite angle or pose, or
            a hit whose cell index would overflow. Nothing changes on error.
        """
    def occupied_cells(self) -> _F64Array:
        """Centres of the cells the map keeps as occupied, shape (K, 2) [m], sorted by index."""
    def small_objects(self) -> list[SmallObject]:
        """The detected small objects, sorted by their smallest cell index."""
    def removal_counts(self) -> RemovalCounts:
        """What each step removed so far."""
    def run_checks(self) -> int:
        """Run the periodic checks (b-1, then c) now, e.g. after the last scan.

        Cells too young for step c are left alone.

        Returns
        -------
        int
            Cells deleted.
        """
    def to_bytes(self) -> bytes:
        """The mapper as the bytes of a mapper file (exactly what :meth:`save` writes).

        A mapper file holds the grid and the whole state of the §V filter: options,
        per-cell observation records, scan counter, removal counters. Equal mappers
        give equal bytes. Pickling (and :mod:`copy`) uses these bytes; the copy has a
        grid of its own.
        """
    @classmethod
    def from_bytes(cls, data: bytes) -> Mapper:
        """The mapper of a mapper file's bytes (see :meth:`to_bytes`).

        Parameters
        ----------
        data : bytes
            The bytes of a mapper file.

        Returns
        -------
        Mapper
            The saved mapper: inserting the same scans into it and into the saved one
            gives the same maps, bit for bit.

        Raises
        ------
        ValueError
            If the bytes are not an ndtgrid file, are a grid file, have an
            unsupported format version, are truncated or longer than their header
            says, fail the checksum, or hold an invalid payload (options, cells or
            filter records); the message says which.
        """
    def save(self, path: str | os.PathLike[str]) -> None:
        """Save the mapper (grid and filter state) to a file, atomically.

        See :meth:`NdtGrid.save`: temporary file beside ``path``, synced, renamed over
        it; the GIL is released while writing.

        Raises
        ------
        OSError
            If the file cannot be written; the message names the file. ``path`` is then
            untouched and no temporary file is left.
        """
    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> Mapper:
        """Load a mapper saved by :meth:`save`; it goes on exactly as the saved one.

        Raises
        ------
        OSError
            If the file cannot be read; the exception's ``filename`` is ``path``.
        ValueError
            If the file is not a valid mapper file (see :meth:`from_bytes`); the
            message starts with ``path``.
        """
    def __reduce__(self) -> tuple[Callable[[bytes], Mapper], tuple[bytes]]: ...

def default_mapper_options() -> dict[str, Any]:
    """The core's defaults for :class:`MapperOptions`."""

def default_match_options() -> dict[str, Any]:
    """The core's defaults for :meth:`NdtGrid.match`."""

def preset_match_options(name: str) -> dict[str, Any]:
    """The core's options of ``"paper"`` (``MatchOptions::paper``) or ``"original_ndt"``.

    ``ndtgrid.presets.PAPER`` and ``ORIGINAL_NDT`` applied to the defaults give these.

    Raises
    ------
    ValueError
        For another name.
    """

def compose(a: _ArrayLike, b: _ArrayLike) -> _F64Array:
    """``a o b``: pose ``b`` (given in frame ``a``) in ``a``'s parent frame, shape (3,)."""

def inverse(p: _ArrayLike) -> _F64Array:
    """The inverse motion of ``p``, shape (3,)."""

def between(a: _ArrayLike, b: _ArrayLike) -> _F64Array:
    """``a^-1 o b``: the motion from ``a`` to ``b`` in ``a``'s frame, shape (3,)."""

def vector_extension() -> str | None:
    """The vector extension of the core's kernels on this processor.

    The score terms, the scan's cell keys and the moments each have an AVX-512, an
    AVX2 and a NEON build besides a generic one, and the widest the processor supports
    runs (picked at run time).

    Returns
    -------
    str or None
        ``"AVX-512"``, ``"AVX2"`` or ``"NEON"``; ``None`` for the generic build.
    """

def ranges_to_points(
    ranges: _ArrayLike,
    angles: _ArrayLike,
    *,
    min_range: float = 0.0,
    max_range: float = ...,
) -> _F64Array:
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

@final
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
    multi_start : bool
        The kept match ran the matcher's rotational multi-start (see
        ``coarse_rotation_gate`` of :class:`ndtgrid.OdometryConfig`).
    inserted : bool
        The scan was added to the map.
    converged, iterations, num_matched
        Of the match (False, 0, 0 without one).
    num_points : int
        Valid points of the scan.
    """

    @property
    def pose(self) -> _F64Array: ...
    @property
    def prediction(self) -> _F64Array: ...
    @property
    def matched(self) -> bool: ...
    @property
    def accepted(self) -> bool: ...
    @property
    def multi_start(self) -> bool: ...
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
    def __reduce__(self) -> tuple[Callable[..., OdometryStep], tuple[Any]]:
        """Pickle (and :mod:`copy`) by value: the class's ``_restore`` and the fields."""

@final
class OdometryLoop:
    """The core's scan-to-map odometry loop (wrapped by :class:`ndtgrid.Odometry`).

    Thread safety: one lock, taken with the GIL released (also by the getters,
    which wait for a running :meth:`step`). Calls from several threads neither
    crash nor deadlock, but steps from two threads interleave in the order
    the lock gives: feed a loop from one thread, read it from any.

    Keyword arguments left at ``None`` take the core's defaults
    (:func:`default_odometry_config`); see :class:`ndtgrid.OdometryConfig` for
    their meaning and units.

    Raises
    ------
    ValueError
        If a setting is out of range (the message names it).
    """

    def __new__(
        cls,
        cell_size: float = 0.02,
        *,
        min_range: float | None = None,
        max_range: float | None = None,
        insert_distance: float | None = None,
        insert_angle: float | None = None,
        map_window: int | None = None,
        match_insert_distance: float | None = None,
        match_insert_angle: float | None = None,
        match_map_window: int | None = None,
        min_match_ratio: float | None = None,
        bootstrap_insertions: int | None = None,
        rotation_search: float | None = None,
        rotation_step: float | None = None,
        prior_gap_distance: float | None = None,
        prior_gap_angle: float | None = None,
        expansion: float | None = None,
        sigma_floor: float | None = None,
        shape_cell: float | None = None,
        neighbor_search: bool | None = None,
        fuse_minority: bool | None = None,
        search_radius: int | None = None,
        max_iterations: int | None = None,
        translation_tolerance: float | None = None,
        rotation_tolerance: float | None = None,
        max_step_cells: float | None = None,
        max_step_rotation: float | None = None,
        levels: int | None = None,
        skip_levels: Sequence[int] | None = None,
        coarse_rotation_search: float | None = None,
        coarse_rotation_gate: float | None = None,
        freeze_unconstrained: bool | None = None,
        freeze_ratio: float | None = None,
        coarse_model: bool | None = None,
        outlier_filter: bool | None = None,
        edge_removal: bool | None = None,
        backshift_rejection: bool | None = None,
        observation_check: bool | None = None,
        radial_confirmation: bool | None = None,
        match_filtered_map: bool | None = None,
        background_mapper: bool | None = None,
        build_map: bool | None = None,
    ) -> Self: ...
    def step(
        self, ranges: _ArrayLike, angles: _ArrayLike, odom: _ArrayLike | None = None
    ) -> OdometryStep:
        """Process one scan (ranges (B,) [m], angles (B,) [rad], odom (3,) or None).

        Raises
        ------
        TypeError, ValueError
            On a wrong shape or type, lengths that differ, a non-finite angle or
            odom; the loop is unchanged after an error. The GIL is released.
        """
    @property
    def poses(self) -> _F64Array:
        """Pose of every scan so far, shape (T, 3)."""
    @property
    def insertions(self) -> int:
        """Scans added to the map so far."""
    @property
    def grid_insertions(self) -> int:
        """Scans the grid the loop matches against took so far."""
    def __len__(self) -> int:
        """Cells in the map now."""
    def grid(self) -> NdtGrid:
        """A copy of the map."""
    def wait_for_mapper(self) -> None:
        """Wait until a background mapper has taken in every inserted scan."""
    def mapper(self) -> Mapper:
        """A copy of the mapper (grid and §V filter state), once a background mapper
        has taken in every inserted scan; ``RuntimeError`` when ``build_map`` is off."""
    def config(self) -> dict[str, Any]:
        """The settings in force, as keyword arguments (plus ``cell_size``)."""

def default_odometry_config() -> dict[str, Any]:
    """The core's default :class:`OdometryLoop` settings (with ``cell_size``)."""

@final
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

    def __new__(cls, resolution: float = 0.05) -> Self: ...
    @property
    def resolution(self) -> float:
        """Cell size [m]."""
    def __len__(self) -> int:
        """Cells crossed by at least one beam."""
    def add_scan(self, points: _ArrayLike, pose: _ArrayLike) -> None:
        """Trace the beams from the sensor at ``pose`` (3,) to the scan-frame ``points`` (N, 2) [m].

        Raises
        ------
        TypeError, ValueError
            On a wrong shape, a non-finite value or a coordinate beyond the
            lattice; nothing changes after an error.
        """
    def raster(
        self, occupied: _ArrayLike, *, max_cells: int = 100_000_000
    ) -> tuple[npt.NDArray[np.int8], _F64Array]:
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
