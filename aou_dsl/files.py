"""Writing output files: checked before the work, atomic when written.

Every file aou writes (trajectories, figures, videos, behaviour files) appears whole or
not at all: it is written to a temporary name beside the target and renamed over it
when complete, and an input is never overwritten.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator, Sequence
from typing import Any

from .diagnostics import AouError, Span, diag

__all__ = ["read_text", "atomic", "check_output", "write_atomic"]


def check_output(path: str, formats: Sequence[str] = ()) -> str:
    """Check, before any long work, that ``path`` can be written: its folder exists and
    its extension is one of ``formats`` (when given). Returns the extension.

    Raises:
        AouError: I502 naming what is wrong.
    """
    where = Span.whole_file(path)
    ext = os.path.splitext(path)[1].lower().lstrip(".")
    if formats and ext not in formats:
        raise AouError(diag("I502", f"cannot write `{path}`: expected a file ending in "
                            f"{', '.join('.' + f for f in formats)}", where))
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise AouError(diag("I502", f"cannot write `{path}`: the folder `{folder}` does not "
                            "exist", where, hint="create it first"))
    if not os.access(folder, os.W_OK):
        raise AouError(diag("I502", f"cannot write `{path}`: the folder is not writable",
                            where))
    return ext


@contextlib.contextmanager
def atomic(path: str, *, inputs: Sequence[str] = ()) -> Iterator[str]:
    """A temporary file name beside ``path`` to write to; renamed over ``path`` when the
    block ends without an exception, removed otherwise.

    Raises:
        AouError: I502 when the file cannot be written or would overwrite an input.
    """
    where = Span.whole_file(path)
    target = os.path.realpath(path)
    if any(os.path.exists(i) and os.path.realpath(i) == target for i in inputs):
        raise AouError(diag("I502", f"refusing to overwrite the input `{path}`", where,
                            hint="choose another output with -o"))
    ext = os.path.splitext(path)[1]
    try:
        fd, tmp = tempfile.mkstemp(prefix=".aouc-", suffix=ext or ".tmp",
                                   dir=os.path.dirname(target) or ".")
        os.close(fd)
    except OSError as exc:
        raise AouError(diag("I502", f"cannot write `{path}`: {exc.strerror}", where)) from None
    try:
        yield tmp
        os.chmod(tmp, 0o644)  # mkstemp makes files private; outputs are ordinary files
        os.replace(tmp, target)
    except OSError as exc:
        raise AouError(diag("I502", f"cannot write `{path}`: {exc.strerror}", where)) from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_atomic(path: str, data: bytes, *, inputs: Sequence[str] = ()) -> None:
    """Write ``data`` to ``path`` atomically; never over one of ``inputs``."""
    with atomic(path, inputs=inputs) as tmp, open(tmp, "wb") as fh:
        fh.write(data)


def read_text(path: str, what: str = "") -> str:
    """The text of an input file (UTF-8).

    Raises:
        AouError: I501 naming the file (and ``what`` it is) and the reason.
    """
    return _read(path, what, text=True)


def read_bytes(path: str, what: str = "") -> bytes:
    """The bytes of an input file.

    Raises:
        AouError: I501 naming the file (and ``what`` it is) and the reason.
    """
    return _read(path, what, text=False)


def _read(path: str, what: str, text: bool) -> Any:
    try:
        with open(path, "rb") as fh:
            data = fh.read()
        return data.decode("utf-8") if text else data
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise AouError(diag("I501", f"cannot read {what + ' ' if what else ''}`{path}`: "
                            f"{reason}", Span.whole_file(path))) from None
