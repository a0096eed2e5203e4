"""Many builds at once: ``aouc compile --jobs N`` on this machine's cores, and the same
map on a Dask distributed cluster for sweeps beyond one machine.

:func:`build_many` yields one :class:`~aou_dsl.driver.builder.BuildResult` per input path, in the
order of the inputs, whatever order they finish in; each result is the one
:func:`aou_dsl.driver.builder.build_file` gives for that path (the documents are the same bytes).

- ``jobs=1``: one file after another, in this process.
- ``jobs=N``: this process and ``N - 1`` worker processes (:mod:`.batch`): this process
  builds from the shortest file while the workers start, and each worker that has warmed
  up takes the longest file left, so a batch is never slower than ``jobs=1`` for the
  workers' start. A :class:`~.pool.BuildPool` given as ``pool=`` is used instead: workers
  started once and kept warm between maps, handed files a window at a time, the longest
  motions first. Interrupting is this process's alone: the workers ignore SIGINT (Ctrl-C);
  a ``KeyboardInterrupt`` or any exception, or closing ``build_many``'s iterator, cancels
  the builds not started and stops the workers at once (:meth:`BuildPool.terminate`).

The parent's own share is what caps the speed-up, so it is kept small: a document's
samples come back as the trajectory's arrays (one buffer each, not a float at a time),
and with ``encode=`` the workers also encode the documents, so that writing them
(:func:`write_result`) is copying bytes; with ``outputs=`` the process that built a
document writes it beside its output, and the caller only names it
(:mod:`~aou_dsl.driver.delivery`).
- ``cluster=``: a ``distributed.Client`` or a scheduler address (``"tcp://host:8786"``);
  the files are read here and their text sent, so the workers need aou (the same
  version) but not the inputs. A robot file a behaviour names must exist at the same
  path on the workers.

Dask is imported only when a cluster is given (the optional extra ``cluster``).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from typing import TYPE_CHECKING, Any

from ..core.codes import I505
from ..core.diagnostics import AouError
from ..core.options import BuildOptions
from ..core.repeats import once_per_run
from .delivery import encoded, pack
from .pool import BuildPool, default_jobs
from .session import Session

if TYPE_CHECKING:
    from .builder import BuildResult
    from .delivery import Outputs

__all__ = ["BuildPool", "build_many", "build_text", "default_jobs", "encoded", "write_result"]

def build_many(paths: Iterable[str], options: BuildOptions | None = None, jobs: int = 1,
               *, cluster: Any = None, pool: BuildPool | None = None,
               encode: str | None = None, outputs: Outputs | None = None
               ) -> Iterator[BuildResult]:
    """Build every path with ``build_file(path, options)``; results in input order. A
    robot's own warnings (C313) come with the first file that meets them only.

    Args:
        paths: ``.aou`` files.
        options: how to build (:class:`~aou_dsl.core.options.BuildOptions`); it travels
            to the workers whole, ``package_dirs`` included.
        jobs: worker processes on this machine (1: none, build here).
        cluster: a ``distributed.Client`` or a scheduler address; then ``jobs`` is
            ignored and the cluster's workers build.
        pool: a :class:`BuildPool` to use (kept open) instead of starting one.
        encode: a file format (``json``, ``csv``, ``npz``, ``yaml``): the workers also
            encode each document in it, for :func:`write_result` (the writing that is
            left to this process is then copying bytes).
        outputs: where each document goes (:class:`~aou_dsl.driver.delivery.Outputs`):
            with ``jobs`` > 1 on this machine, the process that built a document writes
            it into a file beside its output and keeps that file's name on the result
            (``staged``) for the caller to name; elsewhere the caller writes them.
    """
    yield from once_per_run(_build_many(list(paths), options or BuildOptions(), jobs,
                                        cluster, pool, encode, outputs))


def _build_many(paths: list[str], opts: BuildOptions, jobs: int, cluster: Any,
                pool: BuildPool | None, encode: str | None, outputs: Outputs | None
                ) -> Iterator[BuildResult]:
    if cluster is not None:
        yield from _on_cluster(paths, opts, cluster, encode)
    elif pool is not None:
        yield from pool.map(paths, opts, encode=encode)
    elif jobs <= 1 or len(paths) <= 1:
        session = Session(opts)
        for p in paths:
            yield session.build_file(p)
    else:  # this process builds too; workers join as they warm up
        from .batch import shared_map

        yield from shared_map(paths, opts, min(jobs, len(paths)), encode, outputs)


def build_text(text: str, path: str, options: BuildOptions, encode: str | None = None
               ) -> BuildResult:
    """One build, in a worker: the same as ``build_file(path)`` of a file holding
    ``text`` (and its document encoded in ``encode``, see :func:`encoded`)."""
    from .builder import build_source

    return pack(build_source(text, path, options), encode)


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


def _on_cluster(paths: list[str], options: BuildOptions, cluster: Any,
                encode: str | None) -> Iterator[BuildResult]:
    try:
        from distributed import Client, Future
    except ImportError:  # pragma: no cover - the extra is installed with the tests
        raise ImportError("building on a cluster needs Dask distributed: "
                          "pip install '.[cluster]' in aou's folder (the one with "
                          "pyproject.toml)", name="distributed") from None
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
        return AouError(diag(I505, f"cannot connect to the cluster `{address}`: {why}",
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

