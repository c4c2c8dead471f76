"""Shared pytest helpers for tests that pin threads to CPUs."""

from __future__ import annotations

import pytest

from ndtgrid.bench import pinnable_cpus

#: Two CPUs this process may run on, to pin threads to (as ``ndtgrid bench`` pins its
#: threads), or ``None`` where threads cannot be pinned (not Linux) or one CPU is allowed.
TWO_CPUS = pinnable_cpus(2)

#: Skips a test that pins threads where :data:`TWO_CPUS` is ``None``.
needs_two_cpus = pytest.mark.skipif(
    TWO_CPUS is None, reason="needs os.sched_setaffinity and two CPUs"
)
