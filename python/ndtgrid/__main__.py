"""``python -m ndtgrid``: the same as the ``ndtgrid`` command."""

from __future__ import annotations

import sys

from ndtgrid.cli import main

sys.exit(main())
