"""The command line: a thin ``main(argv) -> int`` over the library."""

from .commands import main

__all__ = ["main"]
