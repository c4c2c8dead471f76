"""Scan-to-map odometry: match each scan to the map built so far, then add it to the map.

The loop runs in the Rust core (``ndtgrid._core.OdometryLoop``); this module gives it a
typed configuration with units and the Python surface of ``docs/API.md``.
"""

from __future__ import annotations

import dataclasses
import math
import os
import weakref
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ndtgrid._core import Mapper, NdtGrid, OdometryLoop, OdometryStep

__all__ = ["Odometry", "OdometryConfig", "OdometryStep"]

F64 = npt.NDArray[np.float64]


@dataclass(frozen=True)
class OdometryConfig:
    """Settings of :class:`Odometry` (units: metres, radians).

    Defaults were chosen by measurement on the Freiburg benchmark logs
    (``benches/datasets.py``; ``BENCHMARK.md`` gives the runs and the numbers).

    Attributes
    ----------
    min_range : float, default 0.0
        Beams shorter than this are skipped [m].
    max_range : float, default 30.0
        Beams at or beyond this are skipped [m]: the "no return" readings of a SICK
        (81.83 m) and far, sparse returns.
    insert_distance : float, default 0.1
        A scan is added to the map when the pose moved this far since the last added
        scan [m] ...
    insert_angle : float, default 5 degrees
        ... or turned this much [rad].
    map_window : int, default 200
        Memory bound: the map keeps the cells hit by the last ``map_window`` added scans (a
        cell hit again stays, with all its points), so at most ``map_window * B`` cells for
        ``B``-beam scans however long the run; 0 keeps every cell (memory then grows with
        the mapped area, and with the drift when a place is revisited).
    match_insert_distance : float, default 0.15
        The grid the loop matches against (:meth:`Odometry.grid`) has a policy of its own:
        it takes a scan when the pose moved this far since the last scan it took [m] ...
        The map above (the mapper's) is the one people use: sub-grid objects need every
        view the §V elimination can get. With ``match_map_window`` 130 and matches up to
        32 cm cells (``levels``), measured on the five benchmark logs against the map's
        own 0.1 m, 5 degrees, 200 and 64 cm: relation errors within 1 mm with the logs'
        odometry, lower on three logs without it, and a third fewer inserts and window
        removals for the matching grid (``benches/SPEED_LOG.md``, session 14).
    match_insert_angle : float, default 7.5 degrees
        ... or turned this much [rad].
    match_map_window : int, default 130
        The matching grid keeps the cells hit by the last ``match_map_window`` scans it
        took (0: every cell).
    min_match_ratio : float, default 0.3
        A match is used when at least this fraction of the scan's valid points found a
        distribution; otherwise the pose is the prediction. In [0, 1].
    bootstrap_insertions : int, default 2
        While the map holds fewer than this many inserted scans, a converged match is used
        even below ``min_match_ratio`` (0: never). A map of one sparse scan leaves most
        points without a distribution even at the right pose (1-degree SICK beams on 2 cm
        cells), and without odometry the loop would then never move far enough to insert
        a second scan: matching on every level (``skip_levels=()``), ACES without odometry
        stayed at the origin with 0 and tracked with 2 (``BENCHMARK.md``). With the 4 cm
        level passed over (the default) its first match is accepted anyway, and 0 and 2
        give the same run; the rule stays for maps that need it.
    rotation_search : float, default 0 (off)
        Before matching, the score of eq. (1) is evaluated at the prediction turned by
        ``+-rotation_step, +-2 rotation_step, ...`` up to this [rad], and Newton starts from
        the best: a 2 cm map's basin is narrow in rotation, and wheel odometry is worst in
        turns. Off by default: the match's own rotational multi-start covers the same turns
        (on the five benchmark logs ``10 degrees`` gave the same relation errors at 23-31 %
        more time per scan).
    rotation_step : float, default 1 degree
        Step of that search [rad]; at least ``rotation_search / 1000``.
    prior_gap_distance : float, default 0.1
        When the odometry prior and the constant-velocity prior (the last pose increment)
        differ by this translation [m] ...
    prior_gap_angle : float, default 5 degrees
        ... or this rotation [rad], the scan is matched from both and the match with the
        higher score of eq. (1) is kept (odometry can stall, then jump). The constant-
        velocity prior is also tried whenever the match from the odometry prior fails.
        ``inf`` never, 0 always.
    expansion : float, default 30.0
        ``k`` of eq. (8). The paper uses 10; on the benchmark logs (1-degree SICK beams,
        few points per 2 cm cell) 30 gave lower relation errors (``BENCHMARK.md``).
    sigma_floor : float, default 0.005
        Smallest standard deviation [m] of a cell's distribution before the expansion
        (see :meth:`ndtgrid.NdtGrid.match`, whose scan-to-scan default is 0.01): the loop
        matches against a map of many scans, whose cells are well sampled (simulated
        demo: 0.36 cm RMS pose error with 5 mm, 0.94 cm with 2 cm).
    shape_cell : float, default 0.0
        Cells finer than this [m] take the covariance of their pyramid ancestor of this
        size (see :meth:`ndtgrid.NdtGrid.match`, whose scan-to-scan default is 0.32); off
        in the loop, whose map of many scans gives fine cells their own shape.
    neighbor_search : bool, default True
        §IV-A(1) neighbour search.
    fuse_minority : bool, default True
        §IV-A(3) fusion of cells with fewer than 3 points.
    search_radius : int, default 1
        Neighbour-search radius [cells].
    max_iterations : int, default 50
        Newton steps per scan at most.
    translation_tolerance : float, default 3e-4
        A match stops when Newton's next step is shorter than this [m] (and turns less
        than ``rotation_tolerance``) on the fine level; each coarser level scales both
        by its cell size. :meth:`NdtGrid.match` stops at 1e-4 m; the loop at 0.3 mm,
        for about a tenth fewer instructions, with relation errors on the five benchmark
        logs within the loop's own run-to-run spread (benches/SPEED_LOG.md, session 16).
    rotation_tolerance : float, default 1e-4
        The rotation of that test [rad].
    max_step_cells : float, default 2.0
        Largest translation per Newton step [cells].
    max_step_rotation : float, default 0.05
        Largest rotation per Newton step [rad].
    levels : int, optional
        Pyramid levels the matcher runs coarse to fine (see ``NdtGrid.match``); by
        default as many as keep the coarsest cell at most 0.32 m (5 on 2 cm cells; a match
        alone goes up to 0.64 m): from a motion prior the 64 cm stage adds little, and
        without odometry it made the benchmark logs' matches worse (``benches/SPEED_LOG.md``,
        session 14).
    skip_levels : tuple of int, default (1,)
        Pyramid levels the matcher passes over (``NdtGrid.match(skip_levels=...)``;
        ``()``: every level). The loop skips the 4 cm level: 32, 16, 8 and 2 cm cells,
        the last stage pairing 2 cm with the 8 cm level's model. That level was a quarter
        of the distributions the matching grid's updates compute and a quarter of a
        scan's evaluations: 17 % fewer of the loop's instructions, with relation errors
        on the five benchmark logs within the loop's own run-to-run spread
        (``benches/SPEED_LOG.md``, session 17).
    coarse_rotation_search : float, default 0.15
        The matcher's rotational multi-start on its coarsest level [rad]
        (``NdtGrid.match(rotation_search=...)``); 0 turns it off.
    coarse_rotation_gate : float, default 0.8
        When that multi-start runs. It is the costliest part of a match and from a good
        prior rarely changes it, so a scan is first matched without it, and again with it
        (that match kept, :attr:`OdometryStep.multi_start`) only when the first match
        fails ``min_match_ratio`` or its score of eq. (1) per point is below this fraction
        of the median of the last 32 accepted matches (and for the first 8). ``inf``: on
        every scan; 0: only after a failed match. On the five benchmark logs 0.8 gave
        mean relation errors equal to ``inf``'s or lower in 17 % less time on Intel, and
        without odometry kept the rotation that turning it off lost (``BENCHMARK.md``).
    freeze_unconstrained : bool, default True
        Keep the prediction along directions the scan does not constrain (a
        corridor's axis) instead of letting fine cells drag the pose.
    freeze_ratio : float, default 0.02
        A direction is frozen when its curvature is below this fraction of the strongest
        (``NdtGrid.match`` uses 0.1 between two scans; against the loop's map of many
        scans 0.1 raised the relation error on three of the five benchmark logs).
    coarse_model : bool, default True
        Score the coarser pyramid level of each coarse-to-fine stage by its quadratic
        model (``NdtGrid.match(coarse_model=...)``); ``False`` scores it exactly.
    outlier_filter : bool, default True
        Insert scans through the paper's §V elimination (sub-grid objects, wall
        speckle, moved objects) with :class:`~ndtgrid.MapperOptions`' defaults;
        ``False`` inserts every valid point.
    edge_removal, backshift_rejection, observation_check, radial_confirmation : bool
        The §V steps a, b, c, d (see :class:`~ndtgrid.MapperOptions`). Step b is off
        by default here: it trusts Area 2 (beyond a URG-04LX's 0.5 m reliable range)
        only where Area 1 confirms it, and with a SICK in a large building nearly
        everything is Area 2 (first 2000 Intel scans: 0.0448 m relation error with
        it, 0.0327 m without, 0.0330 m with no elimination).
    match_filtered_map : bool, default False
        Match each scan against the mapper's filtered map (the paper's way) instead of
        a map of every inserted point. Off by default: on the five benchmark logs
        every filtered variant matched worse (MIT Killian: 0.067-0.084 m relation
        error against 0.048 m); the elimination serves the map people and planners
        use (:attr:`Odometry.mapper`).
    background_mapper : bool, default True
        Update the mapper on a helper thread behind the loop: matching goes on while
        the §V elimination of the last inserted scan runs, and :attr:`Odometry.mapper`
        waits for it. ``False``: on the loop's own thread, 8 inserted scans at a time
        (:attr:`Odometry.mapper` first takes in the rest). Poses and mapper are the
        same bit for bit either way; the default uses a second core (Intel log on 2
        cores: BENCHMARK.md, "Speed"). The helper starts with the :class:`Odometry`
        and, on Linux, may run only on the CPUs the thread that makes it may run on
        (a thread inherits them): make the :class:`Odometry` before pinning the
        loop's thread to one CPU, or the helper shares that CPU (921 simulated
        scans: 0.087-0.090 s against 0.054-0.069 s, benches/SPEED_LOG.md, session
        33). Ignored with ``match_filtered_map`` (the mapper then takes each scan at
        once).
    build_map : bool, default True
        Build the map (:attr:`Odometry.mapper`) at all. ``False``: poses only, as a
        scan-to-map odometry such as KISS-ICP gives them. The loop keeps the grid it
        matches against (:meth:`Odometry.grid`) and nothing else: no helper thread, no
        §V elimination; ``insert_distance``, ``insert_angle``, ``map_window`` and the
        §V settings go unused, and :attr:`Odometry.mapper` raises ``RuntimeError``. The
        poses are the same bit for bit (they never depend on the map unless
        ``match_filtered_map``, which needs it: ``ValueError``). On the Intel log it
        used 50-55 % of the default's CPU time, both threads counted, and 86-103 % of
        its wall time (``benches/SPEED_LOG.md``, session 28).
    """

    min_range: float = 0.0
    max_range: float = 30.0
    insert_distance: float = 0.1
    insert_angle: float = math.radians(5.0)
    map_window: int = 200
    match_insert_distance: float = 0.15
    match_insert_angle: float = math.radians(7.5)
    match_map_window: int = 130
    min_match_ratio: float = 0.3
    bootstrap_insertions: int = 2
    rotation_search: float = 0.0
    rotation_step: float = math.radians(1.0)
    prior_gap_distance: float = 0.1
    prior_gap_angle: float = math.radians(5.0)
    expansion: float = 30.0
    sigma_floor: float = 0.005
    shape_cell: float = 0.0
    neighbor_search: bool = True
    fuse_minority: bool = True
    search_radius: int = 1
    max_iterations: int = 50
    translation_tolerance: float = 3e-4
    rotation_tolerance: float = 1e-4
    max_step_cells: float = 2.0
    max_step_rotation: float = 0.05
    levels: int | None = None
    skip_levels: tuple[int, ...] = (1,)
    coarse_rotation_search: float = 0.15
    coarse_rotation_gate: float = 0.8
    freeze_unconstrained: bool = True
    freeze_ratio: float = 0.02
    coarse_model: bool = True
    outlier_filter: bool = True
    edge_removal: bool = True
    backshift_rejection: bool = False
    observation_check: bool = True
    radial_confirmation: bool = True
    match_filtered_map: bool = False
    background_mapper: bool = True
    build_map: bool = True


#: Every live :class:`Odometry`, so that a fork waits for their mappers first.
_LIVE: weakref.WeakSet[Odometry] = weakref.WeakSet()


def _settle_mappers() -> None:
    """Before ``os.fork``: wait until every background mapper has taken in its scans.

    A forked child keeps only the forking thread; a scan still held by a mapper's
    helper thread would be missing from the child's copy of the mapper.
    """
    for odo in list(_LIVE):
        odo._loop.wait_for_mapper()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(before=_settle_mappers)


class Odometry:
    """A scan-to-map odometry loop (in the Rust core).

    Per scan: predict the pose (the odometry increment since the last scan when both have
    odometry, else the last pose increment: constant velocity per scan), search the
    rotation around the prediction, match the scan against the map from there (Newton on
    eq. 1 with §IV-A), fall back to (or, when the two priors disagree, compare with) the
    constant-velocity prior, and add the scan to the map when the pose moved
    ``insert_distance`` or turned ``insert_angle`` since the last added scan (the grid it
    matches against takes a scan every ``match_insert_distance`` or
    ``match_insert_angle``). The first scan sits at its odometry pose (or the origin) and
    starts the map. The map keeps the last ``map_window`` added scans' cells, the
    matching grid the last ``match_map_window`` of its own (memory bound).

    Parameters
    ----------
    cell_size : float, default 0.02
        Side of the map's cells [m] (the paper: 2 cm).
    config : OdometryConfig, optional
        The other settings, with units; defaults as documented there.

    Raises
    ------
    ValueError
        If a setting is out of range (the message names it).

    Notes
    -----
    Thread safety: calls from several threads neither crash nor deadlock (the core
    holds one lock, taken with the GIL released), but the loop is sequential: steps
    from two threads interleave in whatever order the lock gives, and
    :attr:`last_step` is the last step of either. Feed one loop from one thread and
    read it (:attr:`poses`, :attr:`mapper`, :meth:`grid`) from any. ``step`` takes no
    timestamps; an odometry jump is taken as motion, and when the match from it fails
    the constant-velocity prior is tried. A scan with no valid beam gives the
    predicted pose (recorded) and changes no map. Memory: the map is bounded by
    ``map_window``; the pose history grows by 24 bytes a scan by design.

    ``odo.mapper`` is the §V outlier elimination of :class:`~ndtgrid.Mapper` run on every
    inserted scan; scans are matched against a plain :class:`~ndtgrid.NdtGrid` of every
    inserted point (a copy: :meth:`grid`) unless ``match_filtered_map``. Every map change
    goes through one function of the core (``Odometry::insert_points``, behind
    ``update_map``). With ``background_mapper`` (the default) the mapper is updated on a
    helper thread; ``os.fork`` first waits for it (``os.register_at_fork``), so a forked
    child holds the whole mapper and goes on updating it in line.

    Examples
    --------
    >>> import numpy as np, ndtgrid
    >>> odo = ndtgrid.Odometry(cell_size=0.02)
    >>> angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    >>> pose = odo.step(np.full(181, 2.0), angles)
    >>> odo.poses.shape
    (1, 3)
    """

    def __init__(self, cell_size: float = 0.02, config: OdometryConfig | None = None) -> None:
        self._config = OdometryConfig() if config is None else config
        if not isinstance(self._config, OdometryConfig):
            raise TypeError(
                f"config: expected an OdometryConfig, got {type(self._config).__name__}"
            )
        self._loop = OdometryLoop(cell_size, **dataclasses.asdict(self._config))
        self._last: OdometryStep | None = None
        _LIVE.add(self)

    @property
    def cell_size(self) -> float:
        """Side of the map's cells [m]."""
        return float(self._loop.config()["cell_size"])

    @property
    def config(self) -> OdometryConfig:
        """The settings."""
        return self._config

    def step(
        self, ranges: npt.ArrayLike, angles: npt.ArrayLike, odom: npt.ArrayLike | None = None
    ) -> F64:
        """Process one scan and return its pose.

        Parameters
        ----------
        ranges : array_like, shape (B,)
            Ranges [m]; invalid ones (0, NaN, inf, outside ``[min_range, max_range)``) are
            skipped.
        angles : array_like, shape (B,)
            Beam angles in the sensor frame [rad].
        odom : array_like, shape (3,), optional
            Odometry pose ``[x, y, theta]`` of the sensor at this scan (m, m, rad), used
            only through its increment since the previous scan with odometry.

        Returns
        -------
        ndarray, shape (3,)
            Pose ``[x, y, theta]`` of the scan in the map frame.

        Raises
        ------
        TypeError, ValueError
            On a wrong shape or type, lengths that differ, or a non-finite angle or odom;
            the loop is unchanged after an error.
        """
        step = self._loop.step(ranges, angles, odom)
        self._last = step
        pose: F64 = step.pose
        return pose

    @property
    def last_step(self) -> OdometryStep | None:
        """What the last :meth:`step` did (prediction, match, insertion), or ``None``."""
        return self._last

    @property
    def poses(self) -> F64:
        """Pose of every scan so far, shape (T, 3)."""
        poses: F64 = self._loop.poses
        return poses

    @property
    def insertions(self) -> int:
        """Scans added to the map so far (0 without ``build_map``)."""
        return int(self._loop.insertions)

    @property
    def grid_insertions(self) -> int:
        """Scans the grid the loop matches against took so far."""
        return int(self._loop.grid_insertions)

    def __len__(self) -> int:
        """Cells in the map now."""
        return len(self._loop)

    def grid(self) -> NdtGrid:
        """A copy of the map the scans are matched against.

        Returns
        -------
        NdtGrid
            The loop's matching grid as it is now (later steps do not change it).
        """
        grid: NdtGrid = self._loop.grid()
        return grid

    @property
    def mapper(self) -> Mapper:
        """The :class:`~ndtgrid.Mapper` the loop builds (its grid and §V filter state).

        A copy as of this access: later steps do not change it, and changing it does
        not change the loop. With ``background_mapper`` (the default) this first waits
        until the helper thread has taken in every inserted scan.

        Raises
        ------
        RuntimeError
            If the loop builds no map (``OdometryConfig(build_map=False)``).
        """
        mapper: Mapper = self._loop.mapper()
        return mapper

    def __repr__(self) -> str:
        return (
            f"Odometry(cell_size={self.cell_size}, scans={self.poses.shape[0]}, "
            f"insertions={self.insertions}, cells={len(self)})"
        )
