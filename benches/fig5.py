"""The paper's Fig. 5 on real data: score landscapes and convergence maps.

The reference map holds the ``--map-scans`` corrected Intel scans before the
input scan (a single 1° SICK scan leaves almost every 2 cm cell with fewer
than 3 points, and its 2 cm landscapes are flat zero); the input is the next
scan, at its corrected pose.

Landscapes: E(p) of eq. (1) over ±40 cm offsets in x and y from the reference
pose, for the paper's five settings — (b) original NDT 2 cm, (c) original NDT
20 cm, (d) 2 cm with k = 10, (e) 2 cm, k = 10 and fusion, (f) 2 cm, k = 100
and fusion — with neighbour search as in the paper's proposed method for
(d)-(f). Convergence maps: from which offsets (θ offset 0) the paper's method
and our default reach the reference within 5 cm / 1°.

Run: ``python benches/fig5.py [--pair 120] [--out out/fig5]`` (needs matplotlib).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import ndtgrid
from ndtgrid.evaluation import corrected_pairs, pose_error
from ndtgrid.io import read_benchmark_index, read_carmen
from ndtgrid.presets import ORIGINAL_NDT, PAPER

REAL = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "real"
# evaluate() takes only the scoring options: the paper's distributions (each
# cell's own covariance, eq. 7, 5 mm floor; neighbour search 3 cells), not the
# default match()'s shaped cells.
PAPER_SCORE = {
    "sigma_floor": PAPER["sigma_floor"],
    "shape_cell": PAPER["shape_cell"],
    "search_radius": PAPER["search_radius"],
    "pair_neighbors": False,
}
EVAL_ORIGINAL = {
    **PAPER_SCORE,
    "expansion": ORIGINAL_NDT["expansion"],
    "neighbor_search": ORIGINAL_NDT["neighbor_search"],
    "fuse_minority": ORIGINAL_NDT["fuse_minority"],
}
PANELS = [
    ("(b) original NDT, 2 cm", 0.02, EVAL_ORIGINAL),
    ("(c) original NDT, 20 cm", 0.2, EVAL_ORIGINAL),
    ("(d) 2 cm, k = 10", 0.02, {**PAPER_SCORE, "expansion": 10.0, "fuse_minority": False}),
    ("(e) 2 cm, k = 10 + fusion", 0.02, {**PAPER_SCORE, "expansion": 10.0}),
    ("(f) 2 cm, k = 100 + fusion", 0.02, {**PAPER_SCORE, "expansion": 100.0}),
]
MAPS = [
    ("paper's method (k = 10, 2 cm)", PAPER),
    ("default match()", {}),
]


def main() -> None:
    """Compute and save the figures."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pair", type=int, default=120, help="index of the Intel pair")
    ap.add_argument("--map-scans", type=int, default=10, help="scans in the reference map")
    ap.add_argument("--half", type=float, default=0.4, help="half width [m]")
    ap.add_argument("--steps", type=int, default=41)
    ap.add_argument("--out", type=Path, default=Path("out/fig5"))
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    scans = list(read_carmen(REAL / "radish-gfs-corrected/intel-corrected.log.gz"))
    index = read_benchmark_index(REAL / "benchmark-scans-split/intel__intel-corrected__index.csv")
    pairs = list(corrected_pairs(scans, index, max_range=40.0))
    pair = pairs[args.pair]
    history = pairs[max(0, args.pair - args.map_scans + 1) : args.pair + 1]

    def reference(grid: ndtgrid.NdtGrid) -> ndtgrid.NdtGrid:
        for p in history:
            grid.insert(p.reference_points, p.reference_pose)
        return grid

    offsets = np.linspace(-args.half, args.half, args.steps)

    fig, axes = plt.subplots(2, 3, figsize=(13, 8.5))
    ax0 = axes[0, 0]
    ref = np.vstack(
        [
            p.reference_points
            @ np.array(
                [
                    [np.cos(p.reference_pose[2]), np.sin(p.reference_pose[2])],
                    [-np.sin(p.reference_pose[2]), np.cos(p.reference_pose[2])],
                ]
            )
            + p.reference_pose[:2]
            for p in history
        ]
    )
    c, s = np.cos(pair.true_pose[2]), np.sin(pair.true_pose[2])
    inp = pair.points @ np.array([[c, s], [-s, c]]) + pair.true_pose[:2]
    ax0.plot(ref[:, 0], ref[:, 1], "k.", ms=1, label=f"reference ({len(history)} scans)")
    ax0.plot(inp[:, 0], inp[:, 1], ".", color="0.6", ms=2, label="input scan")
    ax0.set_aspect("equal")
    ax0.legend(loc="upper right", fontsize=8)
    ax0.set_title(f"(a) Intel scan {args.pair + 1} on the map")
    for ax, (title, cell, options) in zip(axes.flat[1:], PANELS):
        grid = reference(ndtgrid.NdtGrid(cell))
        score = np.zeros((len(offsets), len(offsets)))
        for i, dy in enumerate(offsets):
            for j, dx in enumerate(offsets):
                pose = pair.true_pose + np.array([dx, dy, 0.0])
                score[i, j] = grid.evaluate(pair.points, pose, **options)[0]
        im = ax.imshow(
            score, origin="lower", cmap="viridis", extent=[-args.half * 100, args.half * 100] * 2
        )
        ax.set_title(title)
        ax.set_xlabel("x error [cm]")
        ax.set_ylabel("y error [cm]")
        fig.colorbar(im, ax=ax, shrink=0.8, label="E(p)")
    fig.tight_layout()
    fig.savefig(args.out / "fig5_landscapes.png", dpi=80)

    fig, axes = plt.subplots(1, len(MAPS), figsize=(5.5 * len(MAPS), 5))
    grid = reference(ndtgrid.NdtGrid(0.02))
    for ax, (title, options) in zip(np.atleast_1d(axes), MAPS):
        ok = np.zeros((len(offsets), len(offsets)))
        for i, dy in enumerate(offsets):
            for j, dx in enumerate(offsets):
                res = grid.match(pair.points, pair.true_pose + np.array([dx, dy, 0.0]), **options)
                et, er = pose_error(res.pose, pair.true_pose)
                ok[i, j] = et < 0.05 and er < np.radians(1.0)
        ax.imshow(
            ok,
            origin="lower",
            cmap="Greens",
            vmin=0,
            vmax=1,
            extent=[-args.half * 100, args.half * 100] * 2,
        )
        ax.set_title(f"{title}: {100 * ok.mean():.0f} % converge")
        ax.set_xlabel("initial x error [cm]")
        ax.set_ylabel("initial y error [cm]")
        print(f"{title}: {100 * ok.mean():.0f} % of starts within ±{args.half} m converge")
    fig.tight_layout()
    fig.savefig(args.out / "fig5_convergence.png", dpi=80)
    print(f"wrote {args.out}/fig5_landscapes.png and fig5_convergence.png")


if __name__ == "__main__":
    main()
