"""Many builds at once: ``aouc compile --jobs N`` on this machine's cores, and the same
map on a Dask distributed cluster for sweeps beyond one machine.

:func:`build_many` yields one :class:`~aou_dsl.build.BuildResult` per input path, in the
order of the inputs, whatever order they finish in; each result is the one
:func:`aou_dsl.build.build_file` gives for that path (the documents are the same bytes).

- ``jobs=1``: one file after another, in this process.
- ``jobs=N``: a pool of N worker processes (:class:`BuildPool`), started once and kept
  warm (the compiler, the checks and the measurement imported, the default robot
  loaded, before the first file), each given the next file as it finishes one.
- ``cluster=``: a ``distributed.Client`` or a scheduler address (``"tcp://host:8786"``);
  the files are read here and their text sent, so the workers need aou (the same
  version) but not the inputs. A robot file a behaviour names must exist at the same
  path on the workers.

Dask is imported only when a cluster is given (the optional extra ``cluster``).
"""

from __future__ import annotations

import os
from collections import deque
from collections.abc import Iterable, Iterator
from typing import TYPE_CHECKING, Any

from .diagnostics import AouError

if TYPE_CHECKING:
    from .build import BuildResult

__all__ = ["BuildPool", "build_many", "build_text", "default_jobs", "warm"]

#: Files handed to the pool ahead of the one being yielded, per worker: enough to keep
#: every worker busy, few enough that results waiting their turn stay few.
_AHEAD = 4
#: How long a pool waits for its workers to warm up before it hands out files [s].
_START_TIMEOUT = 120.0


def default_jobs() -> int:
    """The cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def build_many(paths: Iterable[str], options: dict[str, Any] | None = None, jobs: int = 1,
               *, cluster: Any = None, pool: BuildPool | None = None
               ) -> Iterator[BuildResult]:
    """Build every path with ``build_file(path, **options)``; results in input order.

    Args:
        paths: ``.aou`` files.
        options: keyword options of :func:`aou_dsl.build.build_lint` (``robot``,
            ``rate``, ``check``, ``scene``).
        jobs: worker processes on this machine (1: none, build here).
        cluster: a ``distributed.Client`` or a scheduler address; then ``jobs`` is
            ignored and the cluster's workers build.
        pool: a :class:`BuildPool` to use (kept open) instead of starting one.
    """
    paths = list(paths)
    opts = dict(options or {})
    if cluster is not None:
        yield from _on_cluster(paths, opts, cluster)
    elif pool is not None:
        yield from pool.map(paths, opts)
    elif jobs <= 1 or len(paths) <= 1:
        from .build import build_file

        for p in paths:
            yield build_file(p, **opts)
    else:
        with BuildPool(min(jobs, len(paths))) as own:
            yield from own.map(paths, opts)


def _read(path: str) -> tuple[str | None, BuildResult | None]:
    """The file's text, or (when it cannot be read) its finished result."""
    from .build import build_lint
    from .linter import FileResult, read_source

    try:
        return read_source(path), None
    except AouError as err:
        return None, build_lint(FileResult(path, err.diagnostics))


def build_text(text: str, path: str, options: dict[str, Any]) -> BuildResult:
    """One build, in a worker: the same as ``build_file(path)`` of a file holding
    ``text``."""
    from .build import build_source

    return build_source(text, path, **options)


#: A small behaviour built once by each worker before its first file: the parser, the
#: robot, the compiler's caches, the checks' scene and the measurement all warm.
_WARM = "approach\npause 1.25s x2\nretreat 0.06m a=0.12\n"


def warm(robots: tuple[str, ...] = ("panda",)) -> None:
    """A worker's start: one thread for numerical libraries (the pool already uses every
    core), then a small behaviour built for each of ``robots``."""
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    from .build import build_source

    for r in robots:  # a robot this behaviour does not suit is simply less warm
        build_source(_WARM, "<warm-up>", robot=r)


def _start(robots: tuple[str, ...], ready) -> None:
    try:
        warm(robots)
    finally:
        ready.wait()


class BuildPool:
    """Worker processes kept warm between maps (``with BuildPool(4) as pool: ...``).

    The workers start at once and each imports the build's stages and loads the default
    robot before it takes a file; :meth:`map` can be called again and again (a sweep
    that compiles in rounds pays the start once). Scripts that make a pool need the
    ``if __name__ == "__main__":`` guard: each worker is a fresh interpreter.
    """

    def __init__(self, jobs: int | None = None, *, robots: tuple[str, ...] = ("panda",)):
        import multiprocessing
        import threading
        from concurrent.futures import ProcessPoolExecutor

        self.jobs = jobs or default_jobs()
        # "spawn": a fresh interpreter per worker (no copy of this process's threads or
        # physics clients).
        ctx = multiprocessing.get_context("spawn")
        ready = ctx.Barrier(self.jobs + 1)
        self._pool = ProcessPoolExecutor(max_workers=self.jobs, mp_context=ctx,
                                         initializer=_start, initargs=(robots, ready))
        for _ in range(self.jobs):  # one task each makes the pool start every worker
            self._pool.submit(os.getpid)
        try:  # until every worker has built its warm-up behaviour
            ready.wait(timeout=_START_TIMEOUT)
        except threading.BrokenBarrierError:  # a slow or failed start: go on regardless
            pass

    def map(self, paths: Iterable[str], options: dict[str, Any] | None = None
            ) -> Iterator[BuildResult]:
        """``build_file(path, **options)`` of every path, in input order."""
        from concurrent.futures import Future

        opts = dict(options or {})
        pending: deque[BuildResult | Future] = deque()
        todo = iter(paths)
        for p in todo:
            pending.append(_submit(self._pool, p, opts))
            if len(pending) >= self.jobs * _AHEAD:
                break
        while pending:
            head = pending.popleft()
            yield head.result() if isinstance(head, Future) else head
            for p in todo:
                pending.append(_submit(self._pool, p, opts))
                break

    def close(self) -> None:
        self._pool.shutdown(wait=True, cancel_futures=True)

    def __enter__(self) -> BuildPool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _submit(pool, path: str, options: dict[str, Any]):
    text, done = _read(path)
    return done if done is not None else pool.submit(build_text, text, path, options)


def _on_cluster(paths: list[str], options: dict[str, Any], cluster: Any
                ) -> Iterator[BuildResult]:
    try:
        from distributed import Client, Future
    except ImportError:  # pragma: no cover - the extra is installed with the tests
        raise ImportError("building on a cluster needs Dask distributed: "
                          "pip install 'aou-dsl[cluster]'") from None
    client = cluster if isinstance(cluster, Client) else Client(cluster)
    try:
        futures = []
        for p in paths:
            text, done = _read(p)
            futures.append(done if done is not None else
                           client.submit(build_text, text, p, options, pure=False))
        for f in futures:
            yield f.result() if isinstance(f, Future) else f
    finally:
        if client is not cluster:
            client.close()
