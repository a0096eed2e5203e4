"""The worker pool: processes kept warm between maps, and what a build sends back.

A :class:`BuildPool` starts its workers at once, in one of two ways:

- forked (Linux, where this process runs no other thread): this process first loads what
  a build needs (:func:`preload`: the libraries, each robot's model), then forks, so a
  worker starts in milliseconds with all of it loaded and no second core is spent
  importing the same libraries again;
- spawned (elsewhere, or when asked): each worker is a fresh interpreter that imports
  the build's stages and builds a small behaviour (:func:`~aou_dsl.driver.session.warm`)
  before it takes a file.

Either way a worker ignores SIGINT (this process stops it). A build's result goes back
with its document's samples left behind (the arrays travel as raw bytes) and, when asked,
its document already encoded.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterable, Iterator
from typing import TYPE_CHECKING, Any

from ..core.options import BuildOptions
from .delivery import delivered, encoded, pack
from .session import warm

if TYPE_CHECKING:
    from ..lang.linter import FileResult
    from .builder import BuildResult
    from .delivery import Outputs

__all__ = ["BuildPool", "build_group", "can_fork", "default_jobs", "encoded", "preload"]

#: Files linted and handed out at once, per worker, the longest motions first: a
#: short file last keeps no core idle at the end while another builds a long one.
_WINDOW = 8
#: How long a pool waits for its workers to warm up before it hands out files [s].
_START_TIMEOUT = 120.0
#: How long stopping a pool waits for a worker to end after it was told to [s].
_STOP_TIMEOUT = 2.0
#: The modules a build imports as it goes (the compiler, the checks, the measurement and
#: the libraries under them), imported by :func:`preload`. One missing here is imported
#: by each worker when its first build needs it: slower, never different.
_STAGES = ("aou_dsl.driver.builder", "aou_dsl.compiler.pipeline", "aou_dsl.compiler.output",
           "aou_dsl.compiler.branches", "aou_dsl.safety.replay", "aou_dsl.safety.controllers",
           "aou_dsl.measuring.measured", "aou_dsl.lang.declared", "aou_dsl.robot.rows",
           "aou_dsl.fit.amplitude", "aou_dsl.fit.every_change", "aou_dsl.fit.reach",
           "scipy.interpolate")


def default_jobs() -> int:
    """The cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def can_fork() -> bool:
    """Whether workers may be forked from this process: on Linux, and only while this
    process runs no other thread (a fork copies one thread; a lock another thread held
    would stay held in the worker for ever)."""
    import multiprocessing
    import sys
    import threading

    return (sys.platform.startswith("linux") and threading.active_count() == 1
            and "fork" in multiprocessing.get_all_start_methods())


def preload(robots: Iterable[str], options: BuildOptions | None = None) -> None:
    """Load here what a build loads before its first file, without building: the
    build's modules and libraries (TOPP-RA as the compiler imports it, without
    matplotlib; PyBullet, quietly) and, for each robot, its model, its arm and the scene
    its checks replay in (the URDF file written, the PyBullet world loaded, as the
    replay keeps them). None of it starts a thread, so a worker forked after it starts
    warm: its copy of the scene is its own world (PyBullet's DIRECT mode lives in the
    process's memory). A robot that cannot be loaded is left for the build, which says
    why."""
    import importlib

    from ..compiler.topp import import_toppra
    from ..robot.bullet import import_pybullet
    from ..robot.load import load_arm, load_robot
    from ..safety.replay import check_scene

    for name in _STAGES:
        importlib.import_module(name)  # safe: a name of the fixed list _STAGES
    import_toppra()
    import_pybullet()
    opts = options or BuildOptions()
    for robot in dict.fromkeys(robots):
        try:
            load_robot(robot, opts.package_dirs)
            load_arm(robot, None, opts.package_dirs)
            if opts.check:
                check_scene(robot, opts.scene)
        except Exception:  # noqa: BLE001,S112 - the build of a file naming it says why
            continue


#: The room of the pipe that brings the workers' results back [bytes]: the most a user
#: may give a pipe on Linux unless the system allows more.
_RESULT_PIPE = 1 << 20


def _widen(results: Any) -> None:
    """Give the pipe of the pool's results ``_RESULT_PIPE`` bytes of room (Linux; else,
    or if refused, it keeps its 64 KiB). A result (a checked motion's arrays, about a
    megabyte for hesitant) is written whole before the worker can take its next file,
    and through 64 KiB the writing waited for this process, busy with its own builds,
    to read each 64 KiB: about 3 ms a result, idle, of the worker's 10 between two
    files; with the room it writes and goes on."""
    import fcntl

    writer = getattr(results, "_writer", None)
    setting = getattr(fcntl, "F_SETPIPE_SZ", None)
    if writer is None or setting is None:
        return
    with contextlib.suppress(OSError, ValueError):  # not a pipe, or more than allowed
        fcntl.fcntl(writer.fileno(), setting, _RESULT_PIPE)


def _build_linted(lint: FileResult, options: BuildOptions, encode: str | None
                  ) -> BuildResult:
    """One build of a file the parent has linted (``build_lint`` of it)."""
    from .builder import build_lint

    return pack(build_lint(lint, options), encode)


def build_group(lints: list[FileResult], options: BuildOptions, encode: str | None,
                dests: list[str | None] | None = None, outputs: Outputs | None = None
                ) -> list[BuildResult]:
    """The builds of files the parent has linted, one after another in this worker (files
    with one text: after the first, each costs what a warm process's rebuild costs).
    With ``outputs`` (the format and the files read), each document is written here
    into a file beside its entry of ``dests`` (:func:`~aou_dsl.driver.delivery.stage`)
    for the parent to name; only one that could not be goes back encoded."""
    from .builder import build_lint

    if outputs is None or dests is None:
        return [_build_linted(lint, options, encode) for lint in lints]
    return [delivered(build_lint(lint, options), dest, outputs, encode)
            for lint, dest in zip(lints, dests, strict=True)]


# --- the pool -----------------------------------------------------------------------------

def _start(robots: tuple[str, ...], options: BuildOptions | None, ready, warmed) -> None:
    """A worker's initializer: SIGINT ignored (the parent stops its workers itself; a
    terminal's Ctrl-C reaches every process of the group), warm, then wait for the
    others, though not for ever: the parent may have gone on or stopped the pool."""
    import signal
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        warm(robots, options)
        with warmed.get_lock():
            warmed.value += 1
    finally:
        if ready is not None:
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


@contextlib.contextmanager
def _forking(forked: bool) -> Iterator[None]:
    """Around the fork of the workers: what this process has still to print is printed
    first (a worker's copy of it would be printed again when the worker ends), and in
    the workers the objects loaded so far are left out of the garbage collector's rounds
    (a worker that walked them would copy every page it touched, which its parent
    shares with it until then)."""
    import gc
    import sys

    if not forked:
        yield
        return
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, OSError, ValueError):
            stream.flush()
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def _cost(lint: FileResult) -> float:
    """How long a linted file's build will take, roughly: its planned motion [s]."""
    return lint.timeline.planned_duration if lint.timeline is not None else 0.0


class BuildPool:
    """Worker processes kept warm between maps (``with BuildPool(4) as pool: ...``).

    The workers start at once, warm: forked after this process has loaded the build's
    libraries and ``robots`` (``start="fork"``, the default where :func:`can_fork`), or
    each a fresh interpreter that loads them and builds a small behaviour before it
    takes a file (``start="spawn"``, the default elsewhere, and what a pool asked to
    fork does where it cannot; ask for it when this process holds what a copy must not
    share, such as a display or a connection). :attr:`started` holds one future per
    worker start, done once a worker is warm.
    :meth:`map` can be called again and again (a sweep that compiles in rounds pays the
    start once). Scripts that make a spawned pool need the
    ``if __name__ == "__main__":`` guard: each worker is a fresh interpreter.

    The workers ignore SIGINT: a ``KeyboardInterrupt`` is this process's, and leaving
    the ``with`` block by one (or by any exception) stops the workers at once
    (:meth:`terminate`); leaving it normally waits for the builds handed out.
    """

    def __init__(self, jobs: int | None = None, *, robots: tuple[str, ...] = ("panda",),
                 options: BuildOptions | None = None, wait: bool = True,
                 start: str | None = None):
        import multiprocessing
        import threading
        from concurrent.futures import ProcessPoolExecutor

        if start not in (None, "fork", "spawn"):
            raise ValueError(f"start must be 'fork' or 'spawn', not {start!r}")
        self.jobs = jobs or default_jobs()
        forked = (start or ("fork" if can_fork() else "spawn")) == "fork" and can_fork()
        self.start = "fork" if forked else "spawn"
        if forked:  # what the workers need, loaded once, here, before they are copies
            preload(robots, options)
            robots = ()  # nothing left to warm up in a worker
        ctx = multiprocessing.get_context(self.start)
        ready = ctx.Barrier(self.jobs + 1) if wait else None
        self._warmed = ctx.Value("i", 0)
        self._pool = ProcessPoolExecutor(max_workers=self.jobs, mp_context=ctx,
                                         initializer=_start,
                                         initargs=(robots, options, ready, self._warmed))
        # Once the workers are stopped, the pool's thread may still put an end-of-work
        # sentinel into the queue that hands out the builds, which nobody reads any more:
        # a pipe that cannot be written then is nothing to report (by default its feeder
        # thread prints a traceback; it takes this setting when it starts, at a submit).
        calls = getattr(self._pool, "_call_queue", None)
        if calls is not None and hasattr(calls, "_ignore_epipe"):
            calls._ignore_epipe = True
        _widen(getattr(self._pool, "_result_queue", None))
        try:
            with _sigint_held(), _forking(forked):  # the first task starts every worker
                #: Done as soon as a worker has warmed up (its first task runs then).
                self.started = [self._pool.submit(os.getpid) for _ in range(self.jobs)]
            # until every worker has built its warm-up behaviour; a slow or failed start
            # goes on regardless
            if ready is not None:
                with contextlib.suppress(threading.BrokenBarrierError):
                    ready.wait(timeout=_START_TIMEOUT)
        except BaseException:  # interrupted while the workers warm up
            self.terminate()
            raise

    def map(self, paths: Iterable[str], options: BuildOptions | None = None, *,
            encode: str | None = None) -> Iterator[BuildResult]:
        """``build_file(path, options)`` of every path, in input order.

        The files are linted here (a millisecond each), a window at a time; a file lint
        refuses is finished here, the others are handed out longest motion first, the
        next window while this one is built, so no worker waits between windows.
        """
        from concurrent.futures import Future

        opts = options or BuildOptions()
        todo = iter(paths)
        size = _WINDOW * self.jobs
        current = self._window(todo, size, opts, encode)
        while current:
            upcoming = self._window(todo, size, opts, encode)
            for got in current:
                yield got.result() if isinstance(got, Future) else got
            current = upcoming

    def _window(self, todo: Iterator[str], size: int, options: BuildOptions,
                encode: str | None) -> list:
        """The next ``size`` paths, each a finished result or a submitted build."""
        from ..lang.linter import lint_file
        from .builder import build_lint

        lints = [lint_file(p) for _, p in zip(range(size), todo, strict=False)]
        out: list = [None] * len(lints)
        for k in sorted(range(len(lints)), key=lambda k: -_cost(lints[k])):
            lint = lints[k]
            if lint.behaviour is None or lint.timeline is None or lint.cv is None:
                out[k] = build_lint(lint, options)  # refused: nothing to compile
            else:
                out[k] = self._pool.submit(_build_linted, lint, options, encode)
        return out

    @property
    def warmed(self) -> int:
        """How many workers have warmed up and can take a build at once."""
        return int(self._warmed.value)

    def submit(self, fn: Any, *args: Any) -> Any:
        """``fn(*args)`` in a worker: a ``concurrent.futures.Future``."""
        return self._pool.submit(fn, *args)

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
