"""A batch on this machine's cores that is never slower than one process: this process
builds too, and workers join as soon as they can take a file.

On Linux (:func:`~aou_dsl.driver.pool.can_fork`) this process lints every file and,
when at least three files compile, loads the libraries and the robots the files name
(:func:`~aou_dsl.driver.pool.preload`) and forks ``jobs - 1`` workers before it builds
anything: they start warm in milliseconds, sharing what was loaded, and no build waits
for another process's first one. A batch of two files that compile (or copies of two
texts) is built here to the end: a worker would add its start and save nothing.
Elsewhere the workers are fresh interpreters that import, load and build a small
behaviour first (about a second on a quiet machine, more than a small batch gains), so
this process does not wait for them. Either way it builds the files itself, shortest
first, and each worker that is ready takes the longest files not yet taken, holding two
at a time (the one it builds and the next), the next one handed to it the moment it
sends a result back (not when this process is between two of its own builds); a batch
that ends before any worker is ready was built as ``--jobs 1`` builds it. Files with
the same text go to one process together: after the first, a copy costs what a warm
rebuild costs, in that process only.
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
    from .delivery import Outputs
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
    """The groups of files not yet taken, longest motion first: this process takes from
    the short end, the workers from the long end. Files with one text are one group,
    built by one process, so a copy costs what a rebuild in a warm process costs (the
    compiler's caches are per process). A worker's next group is handed out by the
    pool's thread as its last results come back (a done-callback), so no worker waits
    for this process to finish a build of its own."""

    def __init__(self, lints: list[FileResult], groups: list[tuple[int, ...]],
                 options: BuildOptions, encode: str | None, pool: BuildPool,
                 outputs: Outputs | None = None):
        self.lints, self.options, self.encode, self.pool = lints, options, encode, pool
        self.outputs = outputs
        self.rule = outputs.rule() if outputs is not None else None  # what a worker needs
        self.todo = deque(groups)
        self.lock = threading.Lock()
        self.sent: dict[tuple[int, ...], Future] = {}

    def shortest(self) -> tuple[int, ...] | None:
        with self.lock:
            return self.todo.pop() if self.todo else None

    def feed(self, last: Future | None = None) -> None:
        """Hand a worker the longest group left (after ``last``, its previous one or its
        start, unless that one failed or was cancelled: the pool is being stopped)."""
        from .pool import build_group

        if last is not None and (last.cancelled() or last.exception() is not None):
            return
        with self.lock:
            if not self.todo:
                return
            group = self.todo.popleft()
            try:
                dests = None if self.outputs is None else [self.outputs.dests[k] for k in group]
                f = self.pool.submit(build_group, [self.lints[k] for k in group],
                                     self.options, self.encode, dests, self.rule)
            except RuntimeError:  # the pool is stopped or broken: this process builds it
                self.todo.appendleft(group)
                return
            self.sent[group] = f
        f.add_done_callback(self.feed)

    def start(self) -> None:
        """Feed each worker the moment it has warmed up (its start's future is done then,
        in the pool's thread), not when this process is between two of its builds; and
        twice: each group's end feeds the next, so a worker always has one group waiting
        while it builds another, and takes it the moment it has sent its result back
        rather than after this process has read the result and handed out another (a
        worker waited about 4 ms for that between two files, a tenth of a build). At the
        end this process may wait for one group more than it would have."""
        for f in self.pool.started:
            f.add_done_callback(self.feed)
            f.add_done_callback(self.feed)

    def pending(self) -> list[Future]:
        with self.lock:
            return [f for f in self.sent.values() if not f.done()]

    def received(self) -> list[BuildResult]:
        """Every result that has come back from a worker."""
        return [r for _, f in self.finished() if not f.cancelled() and f.exception() is None
                for r in f.result()]

    def finished(self) -> list[tuple[tuple[int, ...], Future]]:
        with self.lock:
            return [(g, f) for g, f in self.sent.items() if f.done()]


def _groups(lints: list[FileResult]) -> list[tuple[int, ...]]:
    """The files' indices grouped by text (a file lint refuses is a group of its own),
    each group in input order, the groups longest motion first."""
    from .pool import _cost

    by_text: dict[object, list[int]] = {}
    for k, lint in enumerate(lints):
        key = lint.source if _buildable(lint) and lint.source is not None else k
        by_text.setdefault(key, []).append(k)
    return sorted((tuple(g) for g in by_text.values()), key=lambda g: -_cost(lints[g[0]]))


def shared_map(paths: list[str], options: BuildOptions, jobs: int,
               encode: str | None = None, outputs: Outputs | None = None
               ) -> Iterator[BuildResult]:
    """Build ``paths`` on this process and ``jobs - 1`` workers; results in input order.

    Where workers are forked, a batch of at most two groups that compile is built here
    to the end, as ``jobs=1`` builds it (a worker would only add its start to the time);
    a larger one loads what a build needs and forks the workers before building here.

    Args:
        paths: ``.aou`` files.
        options: how to build; the workers receive it whole.
        jobs: processes in all, this one included (at least 2).
        encode: a byte format the results' documents are also encoded in (as
            :func:`~aou_dsl.driver.parallel.build_many` says).
        outputs: where the documents go: each is written by the process that built it
            (:mod:`~aou_dsl.driver.delivery`); None: by the caller.
    """
    from ..lang.linter import lint_file
    from .pool import BuildPool, can_fork

    lints = [lint_file(p) for p in paths]
    session = Session(options)
    groups = _groups(lints)
    results: list[BuildResult | None] = [None] * len(lints)
    if can_fork() and sum(_buildable(lints[g[0]]) for g in groups) < 3:
        # two files at most to compile: a worker would only add its start
        for group in groups:
            for k in group:
                results[k] = _build_here(lints[k], session, options, encode, None, k)
        yield from (r for r in results if r is not None)
        return
    # Forked before this process builds anything: once the libraries and robots are
    # loaded here (the workers share them), every build can go to either process.
    pool = BuildPool(jobs - 1, robots=_robots(lints, options), options=options, wait=False)
    queue = _Queue(lints, groups, options, encode, pool, outputs)
    try:
        queue.start()
        yield from _run(queue, session, results)
    finally:
        pool.terminate()  # workers still warming up are not waited for
        if outputs is not None:  # what was written and never named (interrupted)
            from .delivery import discard

            discard([*results, *queue.received()], outputs)


def _run(queue: _Queue, session: Session, results: list[BuildResult | None]
         ) -> Iterator[BuildResult]:
    """This process's side: its own builds, the workers' results gathered, every result
    (those already in ``results`` too) yielded in input order as soon as those before it
    are."""
    done = 0
    while done < len(results):
        group = queue.shortest()
        if group is not None:
            for k in group:
                results[k] = _build_here(queue.lints[k], session, queue.options, queue.encode,
                                         queue.outputs, k)
        else:
            wait(queue.pending(), timeout=_POLL, return_when=FIRST_COMPLETED)
        for got, f in queue.finished():
            if results[got[0]] is None:
                for k, res in zip(got, f.result(), strict=True):
                    results[k] = res
        while done < len(results) and (ready := results[done]) is not None:
            yield ready
            done += 1


def _build_here(lint: FileResult, session: Session, options: BuildOptions,
                encode: str | None, outputs: Outputs | None, k: int) -> BuildResult:
    """The build of file ``k`` in this process, with ``outputs`` written at once beside
    its output, to be named in input order (not when the results before it in input
    order have come back)."""
    from .builder import build_lint
    from .delivery import delivered, pack

    if not _buildable(lint) or lint.source is None:
        return build_lint(lint, options)  # refused by lint (or unread): nothing to compile
    res = session.build_linted(lint)  # as --jobs 1 builds it, the lint not made again
    if outputs is None:
        return pack(res, encode)
    return delivered(res, outputs.dests[k], outputs, encode)
