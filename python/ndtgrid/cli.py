"""The ``ndtgrid`` command line."""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from ndtgrid import __version__


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``ndtgrid`` command.

    Returns
    -------
    argparse.ArgumentParser
        Parser with ``--version`` and the subcommands.
    """
    parser = argparse.ArgumentParser(
        prog="ndtgrid",
        description="High-resolution 2D NDT scan matching and grid mapping.",
    )
    parser.add_argument("--version", action="version", version=f"ndtgrid {__version__}")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` when omitted.

    Returns
    -------
    int
        Exit status.
    """
    parser = build_parser()
    parser.parse_args(argv)
    parser.print_help()
    return 0
