"""A batch on this machine's cores that is never slower than one process: this process
builds too, and workers join as soon as they can take a file.

On Linux (:func:`~aou_dsl.build.pool.can_fork`) this process lints every file, loads what
the builds need (the libraries and the robots the files name; ``--jobs 1`` loads the same
at its first build) and forks ``jobs - 1`` workers, which start warm in milliseconds.
Elsewhere the workers are fresh interpreters that import, load and build a small
behaviour first (about a second on a quiet machine, more than a small batch gains), so
this process does not wait for them. Either way it builds the files itself, shortest
first, and each worker that is ready takes the longest file not yet taken, one at a
time; a batch that ends before any worker is ready was built as ``--jobs 1`` builds it.
Results come back in the order of the inputs, each the same as ``build_file`` of its
path.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from concurrent.futures import FIRST_COMPLETED, Future, wait
from typing import TYPE_CHECKING

from ..core.options import BuildOptions
from .session import Session

if TYPE_CHECKING:
    from ..lang.linter import FileResult
    from .builder import BuildResult

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
    from .builder import build_lint
    from .pool import BuildPool, _build_linted, _cost, _pack

    lints = [lint_file(p) for p in paths]
    results: list[BuildResult | None] = [None] * len(lints)
    todo = deque(sorted(range(len(lints)), key=lambda k: -_cost(lints[k])))
    session = Session(options)
    running: dict[Future, int] = {}
    done = 0
    pool = BuildPool(jobs - 1, robots=_robots(lints, options), options=options, wait=False)
    try:
        while todo or running:
            for f in [f for f in running if f.done()]:
                results[running.pop(f)] = f.result()
            while todo and len(running) < pool.warmed:  # a warm, idle worker: the longest
                k = todo.popleft()
                running[pool.submit(_build_linted, lints[k], options, encode)] = k
            if todo:  # this process: the shortest
                k = todo.pop()
                lint = lints[k]
                if _buildable(lint) and lint.source is not None:
                    results[k] = _pack(session.build(lint.source, lint.path), encode)
                else:  # refused by lint (or unread): nothing to compile
                    results[k] = build_lint(lint, options)
            elif running:
                wait(list(running), timeout=_POLL, return_when=FIRST_COMPLETED)
            while done < len(results) and (ready := results[done]) is not None:
                yield ready
                done += 1
    finally:
        pool.terminate()  # workers still warming up are not waited for
