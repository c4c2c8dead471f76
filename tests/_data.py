"""Shared pytest helpers: where the real data sets live and how to skip without them."""

from __future__ import annotations

from pathlib import Path

import pytest

#: The ``shared`` directory next to the repository checkout (data, docs, paper).
SHARED = Path(__file__).resolve().parents[1].parent / "shared"
#: Real logs and their SOURCE.md notes; not part of the repository.
REAL = SHARED / "data" / "real"


def require_real(relpath: str) -> Path:
    """Return the path of a real data file under ``../shared/data/real``, or skip the test.

    Parameters
    ----------
    relpath : str
        Path relative to ``../shared/data/real``, e.g.
        ``"radish-gfs-corrected/intel-corrected.log.gz"``.

    Returns
    -------
    pathlib.Path
        The absolute path of the file, which exists.
    """
    path = REAL / relpath
    if not path.exists():
        pytest.skip(f"needs ../shared/data/real/{relpath} (absent here)")
    return path
