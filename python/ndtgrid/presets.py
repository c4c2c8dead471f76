"""Keyword presets of :meth:`ndtgrid.NdtGrid.match` for the methods the defaults grew from.

Examples
--------
>>> import ndtgrid
>>> from ndtgrid.presets import ORIGINAL_NDT, PAPER
>>> grid = ndtgrid.NdtGrid(0.02)
>>> sorted(PAPER)
['freeze_unconstrained', 'levels', 'rotation_search', 'search_radius', 'shape_cell', 'sigma_floor']
"""

from __future__ import annotations

from typing import Any

from ndtgrid._core import default_match_options, default_odometry_config, preset_match_options

__all__ = ["ORIGINAL_NDT", "PAPER", "SCAN_TO_MAP"]


def _differing(options: dict[str, Any]) -> dict[str, Any]:
    """The entries of ``options`` that differ from the core's match defaults."""
    default = default_match_options()
    return {name: value for name, value in options.items() if default[name] != value}


#: Takubo et al. (IROS 2009) alone (the core's ``MatchOptions::paper``): the fine grid
#: only, k = 10, neighbour search (3 cells) and minority fusion, no pyramid, no rotational
#: multi-start, no frozen directions; the covariance regularised only up to a 5 mm
#: standard deviation (about a URG-04LX's or a SICK's range noise; the paper states none),
#: not the default's 2 cm; each cell's own covariance (eq. 7), not its pyramid ancestor's.
PAPER: dict[str, Any] = _differing(preset_match_options("paper"))

#: Biber & Strasser's original NDT on the same grid (``MatchOptions::original_ndt``):
#: additionally k = 1, no neighbour search, no fusion.
ORIGINAL_NDT: dict[str, Any] = _differing(preset_match_options("original_ndt"))

#: The default match tuned for a map of many scans: the settings ``ndtgrid.Odometry``
#: matches with (its map is one of many scans, as is a ``Mapper``'s grid): the 5 mm sigma
#: floor, each fine cell's own covariance and freezing only below 2 % curvature. The
#: default's 2 cm floor, 32 cm cell shapes and 10 % freezing were chosen on sparse
#: single-scan maps; on the simulated sticks room (``benches/subgrid.py``, own poses) they
#: raise the stick error from 0.6 to 0.8 cm.
SCAN_TO_MAP: dict[str, Any] = {
    name: default_odometry_config()[name] for name in ("sigma_floor", "shape_cell", "freeze_ratio")
}
