"""A batch on this machine's cores that is never slower than one process: this process
builds too, and workers join as soon as they can take a file.

On Linux (:func:`~aou_dsl.build.pool.can_fork`) this process lints every file, loads what
the builds need (the libraries and the robots the files name; ``--jobs 1`` loads the same
at its first build) and forks ``jobs - 1`` workers, which start warm in milliseconds.
Elsewhere the workers are fresh interpreters that import, load and build a small
behaviour first (about a second on a quiet machine, more than a small batch gains), so
this process does not wait for them. Either way it builds the files itself, shortest
first, and each worker that is ready takes the longest file not yet taken, one at a
time, the next one handed to it the moment it sends a result back (not when this
process is between two of its own builds); a batch that ends before any worker is
ready was built as ``--jobs 1`` builds it.
Results come back in the order of the inputs, each the same as ``build_file`` of its
path.
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, Future, wait
from typing import TYPE_CHECKING

from ..core.options import BuildOptions
from .session import Session

if TYPE_CHECKING:
    from ..lang.linter import FileResult
    from .builder import BuildResult
    from .pool import BuildPool

__all__ = ["shared_map"]

#: How long this process waits for a worker's build when it has nothing left to build [s]
#: before it looks again whether more workers are ready.
_POLL = 0.05


def _buildable(lint: FileResult) -> bool:
    return not (lint.behaviour is None or lint.timeline is None or lint.cv is None)


def _robots(lints: list[FileResult], options: BuildOptions) -> tuple[str, ...]:
    """The robots the builds will load: the options' one, else those the files name."""
    if options.robot:
        return (options.robot,)
    named = (lint.behaviour.settings.robot for lint in lints if lint.behaviour is not None)
    return tuple(dict.fromkeys(r for r in named if r)) or ("panda",)


class _Queue:
    """The files not yet taken, longest motion first: this process takes from the short
    end, the workers from the long end. A worker's next file is handed out by the pool's
    thread as its last result comes back (a done-callback), so no worker waits for this
    process to finish a build of its own."""

    def __init__(self, lints: list[FileResult], options: BuildOptions, encode: str | None,
                 pool: BuildPool):
        from .pool import _cost

        self.lints, self.options, self.encode, self.pool = lints, options, encode, pool
        self.todo = deque(sorted(range(len(lints)), key=lambda k: -_cost(lints[k])))
        self.lock = threading.Lock()
        self.sent: dict[int, Future] = {}
        self.chains = 0  # workers being fed

    def shortest(self) -> int | None:
        with self.lock:
            return self.todo.pop() if self.todo else None

    def feed(self, last: Future | None = None) -> None:
        """Hand a worker the longest file left (after ``last``, its previous one, unless
        that one failed or was cancelled: the pool is being stopped)."""
        from .pool import _build_linted

        if last is not None and (last.cancelled() or last.exception() is not None):
            return
        with self.lock:
            if not self.todo:
                return
            k = self.todo.popleft()
            try:
                f = self.pool.submit(_build_linted, self.lints[k], self.options, self.encode)
            except RuntimeError:  # the pool is stopped or broken: this process builds it
                self.todo.appendleft(k)
                return
            self.sent[k] = f
        f.add_done_callback(self.feed)

    def start_ready(self) -> None:
        """Begin feeding each worker that has become ready."""
        while self.chains < self.pool.warmed:
            self.chains += 1
            self.feed()

    def pending(self) -> list[Future]:
        with self.lock:
            return [f for f in self.sent.values() if not f.done()]

    def finished(self) -> list[tuple[int, Future]]:
        with self.lock:
            return [(k, f) for k, f in self.sent.items() if f.done()]


def shared_map(paths: list[str], options: BuildOptions, jobs: int,
               encode: str | None = None) -> Iterator[BuildResult]:
    """Build ``paths`` on this process and ``jobs - 1`` workers; results in input order.

    Args:
        paths: ``.aou`` files.
        options: how to build; the workers receive it whole.
        jobs: processes in all, this one included (at least 2).
        encode: a byte format the results' documents are also encoded in (as
            :func:`~aou_dsl.build.parallel.build_many` says).
    """
    from ..lang.linter import lint_file
    from .pool import BuildPool

    lints = [lint_file(p) for p in paths]
    pool = BuildPool(jobs - 1, robots=_robots(lints, options), options=options, wait=False)
    try:
        yield from _run(_Queue(lints, options, encode, pool), Session(options))
    finally:
        pool.terminate()  # workers still warming up are not waited for


def _run(queue: _Queue, session: Session) -> Iterator[BuildResult]:
    """This process's side: its own builds, the workers' results gathered, every result
    yielded in input order as soon as those before it are."""
    results: list[BuildResult | None] = [None] * len(queue.lints)
    done = 0
    while done < len(results):
        queue.start_ready()
        k = queue.shortest()
        if k is not None:
            results[k] = _build_here(queue, session, k)
        else:
            wait(queue.pending(), timeout=_POLL, return_when=FIRST_COMPLETED)
        for j, f in queue.finished():
            if results[j] is None:
                results[j] = f.result()
        while done < len(results) and (ready := results[done]) is not None:
            yield ready
            done += 1


def _build_here(queue: _Queue, session: Session, k: int) -> BuildResult:
    from .builder import build_lint
    from .pool import _pack

    lint = queue.lints[k]
    if _buildable(lint) and lint.source is not None:
        return _pack(session.build(lint.source, lint.path), queue.encode)
    return build_lint(lint, queue.options)  # refused by lint (or unread): nothing to compile
