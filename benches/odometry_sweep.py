"""``ndtgrid.Odometry`` over the benchmark logs once per setting: time against accuracy.

Each setting is a set of ``OdometryConfig`` keyword arguments (the rest default, 2 cm
cells), e.g. ``"insert_distance=0.2 insert_angle=0.1745 map_window=100"`` (angles in
radians, as the config takes them) or ``"levels=4"``; the empty setting ``""`` is the
default configuration. For each log and setting this prints the time of the loop (the
mapper read at the end included), the scans added to the loop's map (and of them, taken
by its matching grid), the scans whose kept match ran the rotational multi-start, and the
relation error of ``benches/datasets.py``. Results are in benches/SPEED_LOG.md, sessions
14-24.

Run from the repository root::

    python benches/odometry_sweep.py --settings "" "levels=4"
    python benches/odometry_sweep.py --datasets intel aces --settings "" "map_window=100"
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from datasets import DATA, DATASETS, Run, machine, run_ndtgrid

import ndtgrid
from ndtgrid.evaluation import RelationSummary, relation_errors
from ndtgrid.io import read_benchmark_index, read_benchmark_split


def setting(text: str) -> dict[str, Any]:
    """``"name=value name=value"`` as ``OdometryConfig`` keyword arguments (integers,
    floats, ``inf``, ``None``, ``true``/``false``, tuples of integers such as ``()`` or
    ``(1,3)``); checked by building a loop with them."""
    kwargs: dict[str, Any] = {}
    for item in text.split():
        name, sep, value = item.partition("=")
        if not sep:
            raise argparse.ArgumentTypeError(f"{item!r} is not name=value")
        low = value.lower()
        parsed: Any
        if low in ("none", "true", "false"):
            parsed = {"none": None, "true": True, "false": False}[low]
        elif value.startswith("("):
            try:
                parsed = tuple(int(v) for v in value.strip("()").split(",") if v)
            except ValueError as e:
                raise argparse.ArgumentTypeError(f"{item!r}: not a tuple of integers") from e
        else:
            try:
                parsed = int(value)
            except ValueError:
                try:
                    parsed = float(value)
                except ValueError as e:
                    raise argparse.ArgumentTypeError(f"{item!r}: not a number") from e
        kwargs[name] = parsed
    try:
        ndtgrid.Odometry(cell_size=0.02, config=ndtgrid.OdometryConfig(**kwargs))
    except (TypeError, ValueError) as e:
        raise argparse.ArgumentTypeError(f"setting {text!r}: {e}") from e
    return kwargs


def run(name: str, kwargs: dict[str, Any], odometry: bool) -> tuple[Run, RelationSummary]:
    """The loop over log ``name`` with these settings, and its relation error."""
    stem = DATASETS[name][0]
    scans = list(read_benchmark_split(DATA / f"{name}.tar.gz"))
    if not odometry:
        scans = [dataclasses.replace(s, odom=None) for s in scans]
    index = read_benchmark_index(DATA / f"{stem}__index.csv")
    ours = run_ndtgrid(scans, ndtgrid.OdometryConfig(**kwargs))
    return ours, relation_errors(ours.poses[index.raw_scan], index.corrected).summary()


def label(kwargs: dict[str, Any]) -> str:
    """A setting as the table shows it."""
    return " ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in kwargs.items())


def parser(description: str) -> argparse.ArgumentParser:
    """The options every sweep over the logs takes: ``--datasets``, ``--no-odometry``."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--datasets", nargs="+", default=list(DATASETS), choices=list(DATASETS))
    ap.add_argument("--no-odometry", action="store_true", help="drop the logs' odometry")
    return ap


def begin(args: argparse.Namespace, columns: list[str], align: list[str]) -> None:
    """Exits when the logs are absent; else prints the machine and the table's head,
    ``columns`` (with the two error columns appended) aligned as ``align``."""
    if not DATA.is_dir():
        sys.exit(f"no benchmark logs at {DATA} (../shared/data/real beside the project)")
    print(f"Machine: {machine()}; odometry {'off' if args.no_odometry else 'on'}\n")
    print("| " + " | ".join([*columns, "translation [m]", "rotation [deg]"]) + " |")
    print("|" + "|".join([*align, "---", "---"]) + "|")


def error_cells(e: RelationSummary) -> str:
    """The relation error's two table cells: translation and rotation, mean ± std (max)."""
    return (
        f"{e.translation_mean:.3f} ± {e.translation_std:.3f} (max {e.translation_max:.3f}) "
        f"| {e.rotation_mean:.2f} ± {e.rotation_std:.2f} (max {e.rotation_max:.2f})"
    )


def main() -> None:
    """Parse the options, run the sweep, print a Markdown table."""
    ap = parser(__doc__.split("\n")[0])
    ap.add_argument("--settings", nargs="+", type=setting, default=[{}])
    args = ap.parse_args()
    columns = ["log", "setting", "loop [s]", "added (matching grid)", "multi-starts"]
    begin(args, columns, ["---", "---", "---:", "---:", "---:"])
    for name in args.datasets:
        for kwargs in args.settings:
            ours, e = run(name, kwargs, not args.no_odometry)
            print(
                f"| {DATASETS[name][1]} | {label(kwargs) or 'default'} | {ours.seconds:.2f} "
                f"| {ours.insertions} ({ours.grid_insertions}) of {len(ours.poses)} "
                f"| {ours.multi_starts} "
                f"| {error_cells(e)} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
