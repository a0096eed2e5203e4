"""Compile diagnostics off the typing path.

A compile takes a tenth of a second to a few seconds, so it runs in one worker thread
(the robot models stay loaded there, in this process). Each document has a generation
that every edit raises: a compile asked for an older generation is skipped if it has
not started, and its result dropped if it has; only the newest text's diagnostics are
ever published. The diagnostics go out as soon as the build is done; the compiled
episodes' figures (for hover) are worked out after, in the same thread. A compile of
the text and robot last compiled (a save without an edit) reuses that result, unless a
file of the robot (its description, URDF, meshes) changed on disk since.
"""

from __future__ import annotations

import asyncio
import traceback
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor

from . import lsp_engine as engine
from .state import Document

__all__ = ["Compiles"]


class Compiles:
    """Schedules :func:`engine.build` for documents; ``done`` is called on the event
    loop with each fresh result."""

    def __init__(self, done: Callable[[Document], None], log: Callable[[str], None]):
        self._done = done
        self._log = log
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="aou-compile")
        self._timers: dict[str, asyncio.TimerHandle] = {}
        self._last: dict[str, tuple[str, str | None, tuple, engine.Built]] = {}

    def request(self, doc: Document, delay: float, robot: str | None) -> None:
        """Compile ``doc`` as it is now, after ``delay`` seconds without a newer edit."""
        loop = asyncio.get_running_loop()
        timer = self._timers.pop(doc.uri, None)
        if timer is not None:
            timer.cancel()
        gen = doc.generation
        if delay <= 0:
            self._start(loop, doc, gen, robot)
        else:
            self._timers[doc.uri] = loop.call_later(delay, self._start, loop, doc, gen, robot)

    def _start(self, loop: asyncio.AbstractEventLoop, doc: Document, gen: int,
               robot: str | None) -> None:
        self._timers.pop(doc.uri, None)
        if doc.generation != gen or doc.closed:
            return
        text, path = doc.text, doc.path
        last = self._last.get(doc.uri)
        files = engine.robot_files_key(doc.lint, robot)
        if last is not None and last[:3] == (text, robot, files):
            self._accept(doc, gen, last[3])
            return

        def job() -> engine.Built | None:
            if doc.generation != gen or doc.closed:  # superseded while queued
                return None
            first = engine.compile_only(text, path, robot)
            if first is not None:  # the compiler's diagnostics at once, the checks' after
                self._hand(loop, lambda: self._accept(doc, gen, first))
                if doc.generation != gen or doc.closed:
                    return None
            return engine.build(text, path, robot, first)

        def figures(built: engine.Built) -> engine.Built | None:
            return engine.shown(built) if doc.generation == gen and not doc.closed else None

        def then(built: engine.Built) -> None:
            self._last[doc.uri] = (text, robot, files, built)
            self._submit(loop, figures, built, lambda b: None)

        self._submit(loop, job, None, lambda b: self._accept(doc, gen, b, then))

    def _submit(self, loop, fn, arg, on_result: Callable) -> None:
        fut = self._pool.submit(fn, arg) if arg is not None else self._pool.submit(fn)
        fut.add_done_callback(lambda f: self._back(loop, f, on_result))

    def _back(self, loop: asyncio.AbstractEventLoop, fut: Future, on_result: Callable) -> None:
        """From the worker thread: hand the result to the event loop."""
        if not fut.cancelled():
            self._hand(loop, lambda: self._finish(fut, on_result))

    @staticmethod
    def _hand(loop: asyncio.AbstractEventLoop, fn: Callable[[], None]) -> None:
        """Run ``fn`` on the event loop, from the worker thread (not at exit)."""
        if loop.is_closed():
            return
        try:
            loop.call_soon_threadsafe(fn)
        except RuntimeError:  # the loop closed in between: the server is exiting
            pass

    def _finish(self, fut: Future, on_result: Callable) -> None:
        try:
            result = fut.result()
        except Exception:  # noqa: BLE001 - a failed compile must not stop the server
            self._log("aouc server: the compile failed: " + traceback.format_exc())
            return
        if result is not None:
            on_result(result)

    def _accept(self, doc: Document, gen: int, built: engine.Built,
                then: Callable[[engine.Built], None] | None = None) -> None:
        if doc.generation != gen or doc.closed:
            return
        doc.built, doc.built_generation = built, gen
        self._done(doc)
        if then is not None:
            then(built)

    def forget(self, uri: str) -> None:
        self._last.pop(uri, None)

    def shutdown(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)
