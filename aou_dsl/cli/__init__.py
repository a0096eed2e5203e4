"""The command line: a thin ``main(argv) -> int`` over the library, and ``run()``, the
``aouc`` command itself: ``main`` of the process's arguments, then the process ends with
its status (:func:`~.endings.leave`)."""

from typing import NoReturn

from .commands import main

__all__ = ["main", "run"]


def run() -> NoReturn:
    """``aouc``: :func:`main`, and the process ends with what it returns."""
    from .endings import leave

    leave(main())
