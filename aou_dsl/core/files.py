"""Writing output files: checked before the work, atomic when written.

Every file aou writes (trajectories, figures, videos, behaviour files) appears whole or
not at all: it is written to a temporary name beside the target and renamed over it
when complete, and an input is never overwritten. The folders missing on the way to it
are made first (and removed again if the write fails).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator, Sequence
from typing import Any

from .diagnostics import AouError, Span, diag

__all__ = ["atomic", "check_format", "check_output", "decode", "read_bytes", "read_text",
           "write_atomic"]


def check_output(path: str, formats: Sequence[str] = ()) -> str:
    """Check, before any long work, that ``path`` can be written: its extension is one of
    ``formats`` (when given), and its folder exists and is writable or can be made (the
    folders missing on the way are made when the file is written, by :func:`atomic`).
    Returns the extension.

    Raises:
        AouError: I502 naming what is wrong.
    """
    where = Span.whole_file(path)
    ext = os.path.splitext(path)[1].lower().lstrip(".")
    if formats and ext not in formats:
        raise AouError(diag("I502", f"cannot write `{path}`: expected a file ending in "
                            f"{', '.join('.' + f for f in formats)}", where))
    folder = os.path.dirname(os.path.abspath(path))
    while not os.path.lexists(folder):  # the nearest folder that exists must take a new one
        folder = os.path.dirname(folder)
    if not os.path.isdir(folder):
        raise AouError(diag("I502", f"cannot write `{path}`: `{folder}` is a file, not a "
                            "folder", where))
    if not os.access(folder, os.W_OK):
        raise AouError(diag("I502", f"cannot write `{path}`: the folder `{folder}` is not "
                            "writable", where))
    return ext


def check_format(path: str | None, fmt: str | None, known: Sequence[str]) -> None:
    """Refuse an output file whose extension names a known format other than ``fmt``
    (``--format csv -o x.json`` would write CSV into a file every reader takes for JSON).
    A folder, an unknown extension or no ``fmt`` pass.

    Raises:
        AouError: I502 naming both formats.
    """
    if not path or not fmt or path.endswith(os.sep) or os.path.isdir(path):
        return
    stem, ext = os.path.splitext(path)
    ext = ext.lower().lstrip(".")
    if ext in known and ext != fmt:
        raise AouError(diag(
            "I502", f"refusing to write {fmt} into `{path}`, whose extension names {ext}",
            Span.whole_file(path), hint=f"name it `{stem}.{fmt}`, or leave out --format "
            f"to write {ext}"))


@contextlib.contextmanager
def atomic(path: str, *, inputs: Sequence[str] = ()) -> Iterator[str]:
    """A temporary file name beside ``path`` to write to; renamed over ``path`` when the
    block ends without an exception, removed otherwise. The folders missing on the way
    to ``path`` are made first, and removed again when nothing was written.

    Raises:
        AouError: I502 when the file cannot be written or would overwrite an input.
    """
    where = Span.whole_file(path)
    target = os.path.realpath(path)
    if any(os.path.exists(i) and os.path.realpath(i) == target for i in inputs):
        raise AouError(diag("I502", f"refusing to overwrite the input `{path}`", where,
                            hint="choose another output with -o"))
    ext = os.path.splitext(path)[1]
    made = _make_folders(os.path.dirname(target), where)
    try:
        fd, tmp = tempfile.mkstemp(prefix=".aouc-", suffix=ext or ".tmp",
                                   dir=os.path.dirname(target) or ".")
        os.close(fd)
    except OSError as exc:
        _remove_folders(made)
        raise AouError(diag("I502", f"cannot write `{path}`: {exc.strerror}", where)) from None
    done = False
    try:
        yield tmp
        os.chmod(tmp, 0o644)  # mkstemp makes files private; outputs are ordinary files
        os.replace(tmp, target)
        done = True
    except OSError as exc:
        raise AouError(diag("I502", f"cannot write `{path}`: {exc.strerror}", where)) from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if not done:
            _remove_folders(made)


def _make_folders(folder: str, where: Span) -> list[str]:
    """Make ``folder`` and the folders missing above it; the ones made, deepest first."""
    made = []
    while folder and not os.path.lexists(folder):
        made.append(folder)
        folder = os.path.dirname(folder)
    try:
        for f in reversed(made):
            os.mkdir(f)
    except OSError as exc:
        _remove_folders(made)
        raise AouError(diag("I502", f"cannot write `{where.path}`: cannot make the folder "
                            f"`{exc.filename}`: {exc.strerror}", where)) from None
    return made


def _remove_folders(made: list[str]) -> None:
    """Remove the folders :func:`_make_folders` made (deepest first), if still empty:
    a failed write leaves nothing behind."""
    for f in made:
        with contextlib.suppress(OSError):
            os.rmdir(f)


def write_atomic(path: str, data: bytes, *, inputs: Sequence[str] = ()) -> None:
    """Write ``data`` to ``path`` atomically; never over one of ``inputs``."""
    with atomic(path, inputs=inputs) as tmp, open(tmp, "wb") as fh:
        fh.write(data)


def read_text(path: str, what: str = "") -> str:
    """The text of an input file (UTF-8; a leading byte-order mark, as Windows editors
    save one, is dropped, so the first line's columns count from its first character).

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


#: Byte-order marks of encodings other than UTF-8: a file saved as "Unicode" by Notepad.
_OTHER_BOMS = {b"\xff\xfe\x00\x00": "UTF-32", b"\x00\x00\xfe\xff": "UTF-32",
               b"\xff\xfe": "UTF-16", b"\xfe\xff": "UTF-16"}


def decode(data: bytes, path: str, what: str = "") -> str:
    """``data`` as UTF-8 text without a leading byte-order mark.

    Raises:
        AouError: I501 for text in another encoding, saying where it stops being UTF-8.
    """
    name = f"{what + ' ' if what else ''}`{path}`"
    for bom, encoding in _OTHER_BOMS.items():
        if data.startswith(bom):
            raise AouError(diag("I501", f"cannot read {name}: it is saved as {encoding}, "
                                "not UTF-8", Span.whole_file(path),
                                hint="save it as UTF-8 (in Notepad: Save as, Encoding UTF-8)"))
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        start = data.rfind(b"\n", 0, exc.start) + 1
        col = len(data[start:exc.start].decode("utf-8", "replace").removeprefix("\ufeff")) + 1
        raise AouError(diag("I501", f"cannot read {name}: not UTF-8 text (byte "
                            f"0x{data[exc.start]:02x} at line {line})",
                            Span.point(path, line, col),
                            hint="save it as UTF-8, or check that it is a text file"),
                       ) from None


def _read(path: str, what: str, text: bool) -> Any:
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise AouError(diag("I501", f"cannot read {what + ' ' if what else ''}`{path}`: "
                            f"{reason}", Span.whole_file(path))) from None
    return decode(data, path, what) if text else data
