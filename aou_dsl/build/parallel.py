"""Many builds at once: ``aouc compile --jobs N`` on this machine's cores, and the same
map on a Dask distributed cluster for sweeps beyond one machine.

:func:`build_many` yields one :class:`~aou_dsl.build.builder.BuildResult` per input path, in the
order of the inputs, whatever order they finish in; each result is the one
:func:`aou_dsl.build.builder.build_file` gives for that path (the documents are the same bytes).

- ``jobs=1``: one file after another, in this process.
- ``jobs=N``: a pool of N worker processes (:class:`BuildPool`), started once and kept
  warm (the compiler, the checks and the measurement imported, the default robot
  loaded, before the first file). This process lints the files (a millisecond each)
  and hands them out a window at a time, the longest motions first, so that no worker
  idles at the end while another builds a long one. Interrupting is this process's
  alone: the workers ignore SIGINT (Ctrl-C); a ``KeyboardInterrupt`` or any exception
  that leaves a pool's ``with`` block, or closing a ``build_many`` that started its own
  pool, cancels the builds not started and stops the workers at once
  (:meth:`BuildPool.terminate`).

The parent's own share is what caps the speed-up, so it is kept small: a document's
samples come back as the trajectory's arrays (one buffer each, not a float at a time),
and with ``encode=`` the workers also encode the documents, so that writing them
(:func:`write_result`) is copying bytes.
- ``cluster=``: a ``distributed.Client`` or a scheduler address (``"tcp://host:8786"``);
  the files are read here and their text sent, so the workers need aou (the same
  version) but not the inputs. A robot file a behaviour names must exist at the same
  path on the workers.

Dask is imported only when a cluster is given (the optional extra ``cluster``).
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable, Iterator
from typing import TYPE_CHECKING, Any

from ..core.diagnostics import AouError

if TYPE_CHECKING:
    from ..lang.linter import FileResult
    from .builder import BuildResult

__all__ = ["BuildPool", "build_many", "build_text", "default_jobs", "encoded", "warm",
           "write_result"]

#: Files linted and handed out at once, per worker, the longest motions first: a
#: short file last keeps no core idle at the end while another builds a long one.
_WINDOW = 8
#: How long a pool waits for its workers to warm up before it hands out files [s].
_START_TIMEOUT = 120.0
#: How long stopping a pool waits for a worker to end after it was told to [s].
_STOP_TIMEOUT = 2.0


def default_jobs() -> int:
    """The cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def build_many(paths: Iterable[str], options: dict[str, Any] | None = None, jobs: int = 1,
               *, cluster: Any = None, pool: BuildPool | None = None,
               encode: str | None = None) -> Iterator[BuildResult]:
    """Build every path with ``build_file(path, **options)``; results in input order.

    Args:
        paths: ``.aou`` files.
        options: keyword options of :func:`aou_dsl.build.builder.build_lint` (``robot``,
            ``rate``, ``check``, ``scene``).
        jobs: worker processes on this machine (1: none, build here).
        cluster: a ``distributed.Client`` or a scheduler address; then ``jobs`` is
            ignored and the cluster's workers build.
        pool: a :class:`BuildPool` to use (kept open) instead of starting one.
        encode: a file format (``json``, ``csv``, ``npz``, ``yaml``): the workers also
            encode each document in it, for :func:`write_result` (the writing that is
            left to this process is then copying bytes).
    """
    paths = list(paths)
    opts = dict(options or {})
    if cluster is not None:
        yield from _on_cluster(paths, opts, cluster, encode)
    elif pool is not None:
        yield from pool.map(paths, opts, encode=encode)
    elif jobs <= 1 or len(paths) <= 1:
        from .builder import build_file

        for p in paths:
            yield build_file(p, **opts)
    else:
        robot = opts.get("robot")
        with BuildPool(min(jobs, len(paths)), robots=(robot or "panda",)) as own:
            yield from own.map(paths, opts, encode=encode)


def build_text(text: str, path: str, options: dict[str, Any], encode: str | None = None
               ) -> BuildResult:
    """One build, in a worker: the same as ``build_file(path)`` of a file holding
    ``text`` (and its document encoded in ``encode``, see :func:`encoded`)."""
    from .builder import build_source

    return _pack(build_source(text, path, **options), encode)


def _build_linted(lint: FileResult, options: dict[str, Any], encode: str | None
                  ) -> BuildResult:
    """One build of a file the parent has linted (``build_lint`` of it)."""
    from .builder import build_lint

    return _pack(build_lint(lint, **options), encode)


# --- what goes back to the parent --------------------------------------------------------

#: The attribute a worker puts the encoded document in: ``(format, bytes)``.
_ENCODED = "_encoded"
def _pack(res: BuildResult, encode: str | None) -> BuildResult:
    """In the worker: the result ready to go back; its document also encoded in
    ``encode`` when asked (a byte format), so that the parent only writes bytes. The
    document's lists of samples stay behind: the parent makes them again from the
    trajectory's arrays when it needs them, which travel as raw bytes (lists pickle
    float by float, which made reading the results back most of the parent's work)."""
    if encode is not None and res.document is not None:
        from ..compiler.output import FOLDER_FORMATS
        from ..compiler.output import encode as encode_doc

        if encode not in FOLDER_FORMATS:
            setattr(res, _ENCODED, (encode, encode_doc(res.document, encode)))
    res.drop_samples()
    return res


def encoded(res: BuildResult, fmt: str) -> bytes:
    """The bytes of ``res.document`` in ``fmt`` (a byte format): those a worker encoded
    (``build_many(..., encode=fmt)``), else encoded here."""
    from ..compiler.output import encode

    done = getattr(res, _ENCODED, None)
    if done is not None and done[0] == fmt:
        return done[1]
    if res.document is None:
        raise ValueError(f"{res.path}: the build failed, there is no document")
    return encode(res.document, fmt)


def write_result(path: str, res: BuildResult, fmt: str, *, inputs: list[str] | tuple = ()
                 ) -> None:
    """``write_output(path, res.document, fmt, inputs=inputs)`` of a successful build,
    with the bytes a worker encoded when there are some.

    Raises:
        AouError: I502 when it cannot be written.
    """
    from ..compiler.output import FOLDER_FORMATS, write_output
    from ..core.files import write_atomic

    if fmt not in FOLDER_FORMATS:
        write_atomic(path, encoded(res, fmt), inputs=inputs)
    elif res.document is None:
        raise ValueError(f"{res.path}: the build failed, there is no document")
    else:
        write_output(path, res.document, fmt, inputs=inputs)


# --- the pool -----------------------------------------------------------------------------

#: A small behaviour built once by each worker before its first file: the parser, the
#: robot, the compiler's caches, the checks' scene and the measurement all warm.
_WARM = "approach\npause 1.25s x2\nretreat 0.06m a=0.12\n"


def warm(robots: tuple[str, ...] = ("panda",)) -> None:
    """A worker's start: one thread for numerical libraries (the pool already uses every
    core), then a small behaviour built for each of ``robots``."""
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    from .builder import build_source

    for r in robots:  # a robot this behaviour does not suit is simply less warm
        build_source(_WARM, "<warm-up>", robot=r)


def _start(robots: tuple[str, ...], ready) -> None:
    """A worker's initializer: SIGINT ignored (the parent stops its workers itself; a
    terminal's Ctrl-C reaches every process of the group), warm, then wait for the
    others, though not for ever: the parent may have gone on or stopped the pool."""
    import signal
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        warm(robots)
    finally:
        with contextlib.suppress(threading.BrokenBarrierError):
            ready.wait(timeout=_START_TIMEOUT)


@contextlib.contextmanager
def _sigint_held() -> Iterator[None]:
    """SIGINT held back in this thread, so also in the processes it starts meanwhile
    (they inherit the mask: a worker cannot be interrupted before its initializer
    ignores SIGINT); one that arrives meanwhile is delivered here at the end."""
    import signal

    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - not POSIX
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _cost(lint: FileResult) -> float:
    """How long a linted file's build will take, roughly: its planned motion [s]."""
    return lint.timeline.planned_duration if lint.timeline is not None else 0.0


class BuildPool:
    """Worker processes kept warm between maps (``with BuildPool(4) as pool: ...``).

    The workers start at once and each imports the build's stages and loads the default
    robot before it takes a file; :meth:`map` can be called again and again (a sweep
    that compiles in rounds pays the start once). Scripts that make a pool need the
    ``if __name__ == "__main__":`` guard: each worker is a fresh interpreter.

    The workers ignore SIGINT: a ``KeyboardInterrupt`` is this process's, and leaving
    the ``with`` block by one (or by any exception) stops the workers at once
    (:meth:`terminate`); leaving it normally waits for the builds handed out.
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
        # Once the workers are stopped, the pool's thread may still put an end-of-work
        # sentinel into the queue that hands out the builds, which nobody reads any more:
        # a pipe that cannot be written then is nothing to report (by default its feeder
        # thread prints a traceback; it takes this setting when it starts, at a submit).
        calls = getattr(self._pool, "_call_queue", None)
        if calls is not None and hasattr(calls, "_ignore_epipe"):
            calls._ignore_epipe = True
        try:
            with _sigint_held():  # one task each makes the pool start every worker
                for _ in range(self.jobs):
                    self._pool.submit(os.getpid)
            # until every worker has built its warm-up behaviour; a slow or failed start
            # goes on regardless
            with contextlib.suppress(threading.BrokenBarrierError):
                ready.wait(timeout=_START_TIMEOUT)
        except BaseException:  # interrupted while the workers warm up
            self.terminate()
            raise

    def map(self, paths: Iterable[str], options: dict[str, Any] | None = None, *,
            encode: str | None = None) -> Iterator[BuildResult]:
        """``build_file(path, **options)`` of every path, in input order.

        The files are linted here (a millisecond each), a window at a time; a file lint
        refuses is finished here, the others are handed out longest motion first, the
        next window while this one is built, so no worker waits between windows.
        """
        from concurrent.futures import Future

        opts = dict(options or {})
        todo = iter(paths)
        size = _WINDOW * self.jobs
        current = self._window(todo, size, opts, encode)
        while current:
            upcoming = self._window(todo, size, opts, encode)
            for got in current:
                yield got.result() if isinstance(got, Future) else got
            current = upcoming

    def _window(self, todo: Iterator[str], size: int, options: dict[str, Any],
                encode: str | None) -> list:
        """The next ``size`` paths, each a finished result or a submitted build."""
        from ..lang.linter import lint_file
        from .builder import build_lint

        lints = [lint_file(p) for _, p in zip(range(size), todo, strict=False)]
        out: list = [None] * len(lints)
        for k in sorted(range(len(lints)), key=lambda k: -_cost(lints[k])):
            lint = lints[k]
            if lint.behaviour is None or lint.timeline is None or lint.cv is None:
                out[k] = build_lint(lint, **options)  # refused: nothing to compile
            else:
                out[k] = self._pool.submit(_build_linted, lint, options, encode)
        return out

    @property
    def pids(self) -> list[int]:
        """The workers' process ids (to measure the CPU time they use)."""
        return sorted(self._pool._processes or {})  # type: ignore[attr-defined]

    def close(self) -> None:
        """Wait for the builds handed out, then end the workers."""
        try:
            self._pool.shutdown(wait=True, cancel_futures=True)
        except BaseException:  # interrupted while waiting
            self.terminate()
            raise

    def terminate(self) -> None:
        """Stop now: the builds not started are cancelled, the workers are ended even
        in the middle of a build (whose result is lost), and this returns once they
        have (within a few seconds)."""
        pool = self._pool
        procs = list((getattr(pool, "_processes", None) or {}).values())
        manager = getattr(pool, "_executor_manager_thread", None)
        results = getattr(pool, "_result_queue", None)
        pool.shutdown(wait=False, cancel_futures=True)
        for p in procs:
            with contextlib.suppress(OSError, ValueError):  # already ended
                p.terminate()
        for p in procs:
            with contextlib.suppress(ValueError):
                p.join(_STOP_TIMEOUT)
                if p.is_alive():
                    p.kill()
                    p.join(_STOP_TIMEOUT)
        # The pool's thread may be reading a result a worker was writing when it ended:
        # with this process's copy of the pipe's writing end closed, it reads the end of
        # the pipe instead of waiting for ever (and so does not hold up this process's exit).
        writer = getattr(results, "_writer", None)
        if writer is not None:
            writer.close()
        if manager is not None:
            manager.join(_STOP_TIMEOUT)

    def __enter__(self) -> BuildPool:
        return self

    def __exit__(self, kind: type[BaseException] | None, *exc: object) -> None:
        if kind is None:
            self.close()
        else:  # an interruption or an error: the builds still running are not wanted
            self.terminate()


def _on_cluster(paths: list[str], options: dict[str, Any], cluster: Any,
                encode: str | None) -> Iterator[BuildResult]:
    try:
        from distributed import Client, Future
    except ImportError:  # pragma: no cover - the extra is installed with the tests
        raise ImportError("building on a cluster needs Dask distributed: "
                          "pip install '.[cluster]' in aou's folder (the one with "
                          "pyproject.toml)") from None
    from ..lang.linter import FileResult, read_source
    from .builder import build_lint

    client = cluster if isinstance(cluster, Client) else _connect(Client, cluster)
    try:
        futures: list = []
        for p in paths:
            try:
                text = read_source(p)
            except AouError as err:  # I501: it cannot be read
                futures.append(build_lint(FileResult(p, err.diagnostics)))
                continue
            futures.append(client.submit(build_text, text, p, options, encode, pure=False))
        for f in futures:
            yield f.result() if isinstance(f, Future) else f
    finally:
        if client is not cluster:
            client.close()


def _connect(client: Any, address: str) -> Any:
    """A Dask client of the scheduler at ``address``, or an I505 saying why not. A TCP
    address is tried first with a plain socket, so that a port nobody listens on is
    said at once rather than after Dask's connection timeout."""
    import socket
    from urllib.parse import urlsplit

    from ..core.diagnostics import Span, diag

    def fail(why: str) -> AouError:
        return AouError(diag("I505", f"cannot connect to the cluster `{address}`: {why}",
                             Span.whole_file("<command line>"),
                             hint="give the scheduler's address, e.g. --cluster "
                                  "tcp://scheduler-host:8786 (`dask scheduler` prints it)"))

    text = str(address)
    parts = urlsplit(text if "://" in text else f"tcp://{text}")
    try:
        port = parts.port
    except ValueError:
        port = None
    if parts.scheme == "tcp":
        if not parts.hostname or port is None:
            raise fail("expected tcp://HOST:PORT")
        try:
            socket.create_connection((parts.hostname, port), timeout=5).close()
        except OSError as exc:
            raise fail(exc.strerror or str(exc) or type(exc).__name__) from None
    try:
        return client(text)
    except (OSError, ValueError, TypeError) as exc:
        raise fail(str(exc)) from None

