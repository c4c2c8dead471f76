"""Progress bars on stderr for the command line's long work."""

from __future__ import annotations

import sys
import time
from collections.abc import Iterable, Iterator
from typing import TypeVar

T = TypeVar("T")


def progress(
    items: Iterable[T], quiet: bool, desc: str, unit: str = "scan", total: int | None = None
) -> Iterator[T]:
    """``items`` with a progress bar on stderr.

    Parameters
    ----------
    items : iterable
        What is worked through.
    quiet : bool
        No bar at all.
    desc : str
        The bar's label (e.g. ``"mapping"``).
    unit : str, default "scan"
        What one item is.
    total : int, optional
        How many items there are, for a generator (a sized ``items`` tells tqdm itself).

    Yields
    ------
    object
        The items, in order. With tqdm installed (the ``progress`` extra) the bar is
        tqdm's; without it a plain counter every 500 items.
    """
    if quiet:
        yield from items
        return
    try:
        from tqdm import tqdm  # type: ignore[import-untyped,unused-ignore]
    except ImportError:
        start = time.perf_counter()
        n = 0
        for n, item in enumerate(items, start=1):
            if n % 500 == 0:
                rate = n / max(time.perf_counter() - start, 1e-9)
                print(f"\r{desc}: {n} {unit}s ({rate:.0f} {unit}s/s)", end="", file=sys.stderr)
            yield item
        print(f"\r{desc}: {n} {unit}s", file=sys.stderr)
        return
    yield from tqdm(items, unit=unit, desc=desc, total=total, file=sys.stderr)
