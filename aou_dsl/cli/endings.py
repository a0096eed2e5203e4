"""How a command ends other than with its diagnostics: Ctrl-C, a missing extra, an
internal error.

Ctrl-C is remembered: an interrupt that lands inside a library's import can come out as
another error (NumPy turns a ``KeyboardInterrupt`` met while its C extension loads into
an ``ImportError``), which would be reported as an internal error with exit 2. While a
command runs, :class:`CtrlC` notes every SIGINT before raising ``KeyboardInterrupt`` as
Python does, so the command line can say "interrupted" and exit 130 whatever the
interrupt became on its way up."""

from __future__ import annotations

import signal
import sys
import threading
from types import FrameType, TracebackType

from .args import EXIT_INTERRUPTED, EXIT_USAGE

__all__ = ["CtrlC", "extra_missing", "internal"]


class CtrlC:
    """``with CtrlC() as ctrl_c: ...``; ``ctrl_c.seen`` is true once SIGINT arrived.

    Only the main thread may set a signal handler: elsewhere, and where SIGINT is
    ignored (a worker), nothing is changed and ``seen`` stays false."""

    def __init__(self) -> None:
        self.seen = False
        self._previous: object = None
        self._installed = False

    def _on_sigint(self, signum: int, frame: FrameType | None) -> None:
        self.seen = True
        raise KeyboardInterrupt

    def __enter__(self) -> CtrlC:
        if threading.current_thread() is threading.main_thread() and \
                signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            self._previous = signal.signal(signal.SIGINT, self._on_sigint)
            self._installed = True
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if self._installed:
            signal.signal(signal.SIGINT, self._previous)  # type: ignore[arg-type]
            self._installed = False


def extra_missing(command: str, exc: ImportError) -> str | None:
    """The optional extra whose module ``exc`` misses, for ``command`` (None: not one)."""
    if not exc.name:
        return None
    if command in ("plot", "render", "variants"):
        return "media"
    if command == "studio":
        return "studio"
    top = exc.name.split(".")[0]
    if top == "mujoco":  # --track
        return "track"
    if top in ("distributed", "dask"):  # compile --cluster
        return "cluster"
    if command == "study" and top in ("scipy", "statsmodels"):
        return "study"
    if command == "study" and top in ("matplotlib", "imageio", "imageio_ffmpeg", "PIL"):
        return "media"  # its videos and the report's figures
    return "dmp" if top in ("movement_primitives", "pytransform3d") else None


def internal(exc: BaseException, debug: bool, ctrl_c: CtrlC) -> int:
    """An error nothing else explains: one line and exit 2 (``debug``: the traceback);
    "interrupted" and 130 when Ctrl-C was pressed (the error came from it)."""
    if ctrl_c.seen:
        print("aouc: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    if debug:
        raise exc
    print(f"aouc: internal error: {type(exc).__name__}: {exc} (rerun with --debug for the "
          "traceback, and please report it)", file=sys.stderr)
    return EXIT_USAGE
