"""How a command ends other than with its diagnostics: Ctrl-C, a missing extra, an
internal error; and how the process ends once the command has (:func:`leave`).

Ctrl-C is remembered: an interrupt that lands inside a library's import can come out as
another error (NumPy turns a ``KeyboardInterrupt`` met while its C extension loads into
an ``ImportError``), which would be reported as an internal error with exit 2. While a
command runs, :class:`CtrlC` notes every SIGINT before raising ``KeyboardInterrupt`` as
Python does, so the command line can say "interrupted" and exit 130 whatever the
interrupt became on its way up."""

from __future__ import annotations

import atexit
import os
import signal
import sys
import threading
from types import FrameType, TracebackType
from typing import NoReturn

from .args import EXIT_INTERRUPTED, EXIT_USAGE

__all__ = ["CtrlC", "extra_missing", "internal", "leave"]


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


def leave(code: int) -> NoReturn:
    """End this process with exit status ``code``, as ``sys.exit`` would but without the
    interpreter's teardown: the exit handlers run (a robot's temporary folder removed,
    logs flushed, worker processes stopped), the standard streams are flushed, and then
    the process ends at once. The teardown would take apart every module the command
    loaded, one object at a time: about a tenth of a second once the compiler's
    libraries are in, which every ``aouc`` run waited for and nothing needed (each
    output is written, closed and renamed before the command returns).

    While another thread still runs (a server's), or when a stream cannot be flushed (a
    closed pipe), it ends as ``sys.exit`` does: Python's own teardown waits for the
    thread and says what could not be written."""
    if threading.active_count() == 1:
        try:
            atexit._run_exitfuncs()  # each handler once: they are cleared as they run
            sys.stdout.flush()
            sys.stderr.flush()
        except BaseException:  # noqa: BLE001 - Python's own exit says it, as usual
            raise SystemExit(code) from None
        os._exit(code)
    raise SystemExit(code)
