"""Plot the soak run of ``cargo bench --bench soak`` (issue 6): memory and cells per scan.

Usage: ``python benches/soak_plot.py [target/soak.csv] [out/soak.png]``.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main() -> None:
    src = Path(sys.argv[1] if len(sys.argv) > 1 else "target/soak.csv")
    dst = Path(sys.argv[2] if len(sys.argv) > 2 else "out/soak.png")
    rows = list(csv.DictReader(src.open()))
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), sharex="col")
    for col, phase in enumerate(("mapper", "odometry")):
        sel = [r for r in rows if r["phase"] == phase]
        if not sel:
            continue
        scans = [int(r["scans"]) for r in sel]
        mem, cells = axes[0][col], axes[1][col]
        mem.plot(scans, [int(r["rss_kib"]) / 1024 for r in sel], ".-", label="resident (VmRSS)")
        mem.plot(scans, [int(r["peak_kib"]) / 1024 for r in sel], "--", label="peak (VmHWM)")
        if phase == "odometry":
            poses = [int(r["poses"]) * 24 / 2**20 for r in sel]
            mem.plot(scans, poses, ":", label="pose history (24 B/scan)")
            rest = [int(r["rss_kib"]) / 1024 - p for r, p in zip(sel, poses)]
            mem.plot(scans, rest, "-.", label="resident - pose history")
        mem.set_ylabel("MiB")
        mem.set_ylim(bottom=0)
        mem.set_title(f"{phase}: {scans[-1]:,} scans")
        mem.legend(loc="lower right")
        cells.plot(scans, [int(r["cells"]) for r in sel], label="grid cells")
        cells.plot(scans, [int(r["filter_records"]) for r in sel], label="filter records")
        cells.set_ylim(bottom=0)
        cells.set_xlabel("scans")
        cells.legend(loc="lower right")
    fig.tight_layout()
    dst.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(dst, dpi=110)
    print(f"wrote {dst}")


if __name__ == "__main__":
    main()
