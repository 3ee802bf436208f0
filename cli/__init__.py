"""The ``jik`` command (:func:`jik.cli.command.main`, also ``python -m jik``): its subcommands are
the modules of this package."""

from .command import main

__all__ = ["main"]
