"""What a build sends back to the process that reports it, and its document written where
it was built.

A worker's result goes back with its document's samples left behind (the arrays travel
as raw bytes) and, when asked, its document already encoded (:func:`pack`).

``aouc compile --jobs N`` knows before any work where each input's document goes
(:class:`Outputs`). Left to this process, writing would be a serial share of the batch:
every document a worker built would come back encoded through a pipe (about 3 MB for a
checked motion of a minute) to be written here, and this process's own builds, yielded
in input order after the workers' earlier ones, would be written last, one after
another, while the workers wait. So the process that builds a document also writes it
(:func:`stage`), into a temporary file beside its output, and this process only names it
(:func:`name`), in input order: the outputs of a batch still appear one after another
in the order of the inputs (an interrupted batch leaves those of its first inputs), each
checked by the output rule as it is named, and naming a file is a rename.

A document is staged only where its output's folder exists already: only this process
makes folders (two processes making one folder at once would refuse each other, and a
failed write removes only the folders its own process made); the first output of a new
folder is written by this process as before. A staged file that is never named (the
batch was interrupted, or the output rule refused its name) is removed
(:func:`discard`), and one left by a worker ended while writing it is swept with the
temporary files of processes that no longer run. Folder formats (ROS 2 bags, DMP
folders) are written by the command, as before.
"""

from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..core.diagnostics import AouError
from ..core.read_set import ReadSet

if TYPE_CHECKING:
    from .builder import BuildResult

__all__ = ["Outputs", "delivered", "discard", "encoded", "name", "pack", "stage"]


@dataclass(frozen=True)
class Outputs:
    """Where each input's document goes (``dests``, by input index; None: not written),
    in which byte format (``fmt``: json, csv, npz, yaml or csv with derivatives), and the
    files the command reads (``reads``: no output may be one of them), indexed once
    (:class:`~aou_dsl.core.read_set.ReadSet`) before any work."""

    dests: tuple[str | None, ...]
    fmt: str
    reads: ReadSet

    def __post_init__(self) -> None:
        from ..compiler.output import FOLDER_FORMATS

        if self.fmt in FOLDER_FORMATS:
            raise ValueError(f"{self.fmt} outputs are folders, written by the command")
        if not isinstance(self.reads, ReadSet):
            object.__setattr__(self, "reads", ReadSet(self.reads))

    def rule(self) -> Outputs:
        """The format and the files read without the destinations: what goes to a worker
        with each file (its destination beside it), the same size whatever the batch."""
        return Outputs((), self.fmt, self.reads)


def stage(res: BuildResult, dest: str | None, outputs: Outputs) -> None:
    """Write ``res``'s document (a successful build's) into a temporary file beside
    ``dest`` and keep its name on ``res`` (``staged``), for :func:`name`; nothing when
    ``dest``'s folder does not exist yet (this process writes that output itself). An
    error here is left to the writing in this process, which says it."""
    import tempfile

    from ..compiler.output import encode
    from ..core.files import temp_prefix

    if dest is None or not res.ok or res.header is None:
        return
    folder = os.path.dirname(os.path.realpath(dest))
    doc = _encodable(res)
    if doc is None or not os.path.isdir(folder):
        return
    data = encode(doc, outputs.fmt)
    try:
        fd, tmp = tempfile.mkstemp(prefix=temp_prefix(), suffix=".part", dir=folder)
    except OSError:
        return
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o644)  # mkstemp makes files private; outputs are ordinary files
    except OSError:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        return
    res.staged = tmp


def name(dest: str, res: BuildResult, reads: ReadSet) -> None:
    """Give the file :func:`stage` wrote for ``res`` its name ``dest``, after the output
    rule (:func:`~aou_dsl.core.files.guard_output`) allows it now; the staged file is
    removed when it does not.

    Raises:
        AouError: I502 when the rule refuses ``dest`` or the file cannot be renamed.
    """
    from ..core.codes import I502
    from ..core.diagnostics import Span, diag
    from ..core.files import guard_output

    tmp, res.staged = res.staged, None
    if tmp is None:
        raise ValueError(f"{res.path}: nothing was staged")
    try:
        guard_output(dest, reads)
        os.replace(tmp, os.path.realpath(dest))
    except OSError as exc:
        raise AouError(diag(I502, f"cannot write `{dest}`: {exc.strerror}",
                            Span.whole_file(dest))) from None
    finally:
        with contextlib.suppress(OSError):
            if os.path.lexists(tmp):
                os.unlink(tmp)


def delivered(res: BuildResult, dest: str | None, outputs: Outputs, encode: str | None
              ) -> BuildResult:
    """``res`` written beside ``dest`` (:func:`stage`) and ready to go back
    (:func:`pack`): encoded too only when it could not be written here."""
    stage(res, dest, outputs)
    return pack(res, None if res.staged else encode)


def discard(results: list, outputs: Outputs) -> None:
    """Remove the files staged for ``results`` that were never named, and those a
    worker that no longer runs was writing when it ended (its workers must have ended)."""
    from ..core.files import sweep_stale

    for res in results:
        tmp = getattr(res, "staged", None)
        if tmp is not None:
            res.staged = None
            with contextlib.suppress(OSError):
                os.unlink(tmp)
    for folder in {os.path.dirname(os.path.realpath(d)) for d in outputs.dests if d}:
        sweep_stale(folder)


#: The attribute a worker puts the encoded document in: ``(format, bytes)``.
_ENCODED = "_encoded"


def pack(res: BuildResult, encode: str | None) -> BuildResult:
    """In the worker: the result ready to go back; its document also encoded in
    ``encode`` when asked (a byte format, from the trajectory's arrays), so that the
    parent only writes bytes. The
    document's lists of samples stay behind: the parent makes them again from the
    trajectory's arrays when it needs them, which travel as raw bytes (lists pickle
    float by float, which made reading the results back most of the parent's work)."""
    if encode is not None:
        from ..compiler.output import FOLDER_FORMATS
        from ..compiler.output import encode as encode_doc

        doc = _encodable(res) if encode not in FOLDER_FORMATS else None
        if doc is not None:
            setattr(res, _ENCODED, (encode, encode_doc(doc, encode)))
    res.drop_samples()
    return res


def encoded(res: BuildResult, fmt: str) -> bytes:
    """The bytes of ``res.document`` in ``fmt`` (a byte format): those a worker encoded
    (``build_many(..., encode=fmt)``), else encoded here."""
    from ..compiler.output import encode

    done = getattr(res, _ENCODED, None)
    if done is not None and done[0] == fmt:
        return done[1]
    doc = _encodable(res)
    if doc is None:
        raise ValueError(f"{res.path}: the build failed, there is no document")
    return encode(doc, fmt)


def _encodable(res: BuildResult) -> dict | None:
    """A build's document to encode, its samples as the trajectory's arrays (the same
    bytes as its lists, written without making them); None when the build failed."""
    from ..compiler.output import array_document

    tr = res.compiled.trajectory if res.compiled is not None else None
    if res.header is None or tr is None:
        return res.document
    return array_document(res.header, tr)
