"""PyBullet, imported quietly: its C library prints a banner on standard output that would
corrupt ``--format json`` output. Every module that uses PyBullet imports it from here."""

from __future__ import annotations

import contextlib
import os
import sys

__all__ = ["import_pybullet", "quiet"]


@contextlib.contextmanager
def quiet():
    """Keep PyBullet's C library from printing its banner ("pybullet build time: ...")
    on standard output or error: it would corrupt ``--format json`` output."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            os.dup2(null.fileno(), 2)
            yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in saved:
            os.close(fd)


_quiet = quiet


def import_pybullet():
    """Import PyBullet quietly (see :func:`quiet`)."""
    if "pybullet" not in sys.modules:
        with _quiet():
            import pybullet  # noqa: F401
    return sys.modules["pybullet"]
