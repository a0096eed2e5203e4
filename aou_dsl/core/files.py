"""Writing output files: checked before the work, atomic when written.

Every file aou writes (trajectories, figures, videos, behaviour files) appears whole or
not at all: it is written to a temporary name beside the target and renamed over it
when complete, and an input is never overwritten. The folders missing on the way to it
are made first (and removed again if the write fails).

The output rule, one for every command that writes (:func:`guard_output`): an output
may not be, or link to, any file the command reads (:mod:`aou_dsl.robot.files_read` lists them:
the ``.aou`` file, its robot file, the URDF, every mesh, the trajectory); it may not be
a device, a FIFO or a socket; a bag is written only into a new or empty folder or over
a bag aou wrote; and where a command is asked to (``synth``, ``variants``, ``robot
-o``), an existing file is replaced only when aou wrote it (:func:`is_own_output`) or
with ``--force``.

A temporary file carries the writer's process id (``.aouc-PID-...``); one left by a
process that was killed is removed by the next write into that folder. A file written
from bytes has no name at all until it is complete (Linux's ``O_TMPFILE``).
"""

from __future__ import annotations

import contextlib
import os
import re
import stat
import tempfile
from collections.abc import Iterator, Sequence
from typing import Any

from .codes import I501, I502, I506
from .diagnostics import AouError, Span, diag
from .output_folders import is_aou_bag, is_aou_dmp
from .read_set import ReadSet

__all__ = ["apart_from", "atomic", "check_format", "check_output", "decode", "guard_output",
           "is_own_output", "make_folders", "read_bytes", "read_text", "same_file", "sweep_stale",
           "temp_prefix", "write_atomic"]


def check_output(path: str, formats: Sequence[str] = (), *, reads: Sequence[str] = (),
                 force: bool = True) -> str:
    """Check, before any long work, that ``path`` can be written: its extension is one of
    ``formats`` (when given), and its folder exists and is writable or can be made (the
    folders missing on the way are made when the file is written, by :func:`atomic`),
    and it obeys the output rule against ``reads`` (:func:`guard_output`). Returns the
    extension.

    Raises:
        AouError: I502 naming what is wrong, or the codes of :func:`guard_output`.
    """
    guard_output(path, reads, force=force)
    where = Span.whole_file(path)
    ext = os.path.splitext(path)[1].lower().lstrip(".")
    if formats and ext not in formats:
        raise AouError(diag(I502, f"cannot write `{path}`: expected a file ending in "
                            f"{', '.join('.' + f for f in formats)}", where))
    folder = os.path.dirname(os.path.abspath(path))
    while not os.path.lexists(folder):  # the nearest folder that exists must take a new one
        folder = os.path.dirname(folder)
    if not os.path.isdir(folder):
        raise AouError(diag(I502, f"cannot write `{path}`: `{folder}` is a file, not a "
                            "folder", where))
    if not os.access(folder, os.W_OK):
        raise AouError(diag(I502, f"cannot write `{path}`: the folder `{folder}` is not "
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
            I502, f"refusing to write {fmt} into `{path}`, whose extension names {ext}",
            Span.whole_file(path), hint=f"name it `{stem}.{fmt}`, or leave out --format "
            f"to write {ext}"))


def same_file(path: str, other: str) -> bool:
    """Whether writing ``path`` would write ``other``: the same path, a link to it (or
    through a linked folder), or a hard link of it."""
    return _clash(path, other) is not None


def _clash(path: str, read: str) -> str | None:
    """How ``path`` would write over the input ``read`` (None: it would not)."""
    found = ReadSet((read,)).clash(path)
    return None if found is None else found[0]


def _special(mode: int) -> str | None:
    """What a file that is neither a regular file nor a folder is, in words."""
    for test, name in ((stat.S_ISCHR, "character device"), (stat.S_ISBLK, "block device"),
                       (stat.S_ISFIFO, "FIFO (named pipe)"), (stat.S_ISSOCK, "socket")):
        if test(mode):
            return name
    return None


def apart_from(path: str, outputs: Sequence[str], what: str, flag: str) -> None:
    """Refuse (I502) a second output ``path`` (given by ``flag``, holding ``what``) that
    is, or links to, one of the command's ``outputs`` of ``-o``: one would overwrite
    the other."""
    from .diagnostics import AouError, Span, diag

    for out in outputs:
        if same_file(path, out):
            raise AouError(diag(I502, f"refusing to write {what} into `{path}`: -o writes "
                                f"the output there (`{out}`)", Span.whole_file(path),
                                hint=f"give {flag} a path of its own"))


def guard_output(path: str, reads: Sequence[str] = (), *, force: bool = True,
                 bag: bool = False, flag: str = "-o") -> None:
    """The output rule: refuse ``path`` when it is, or links to, one of the files the
    command ``reads``; when it is a device, a FIFO or a socket; for a ``bag`` (a folder),
    when it holds one of ``reads`` or anything but a bag aou wrote; and unless ``force``,
    when it is an existing file aou did not write (:func:`is_own_output`). ``flag`` is
    the option that named ``path`` (``--tracked``, ``--sarif``): the hint names it.

    Raises:
        AouError: I502 naming the clash (an input, a special file, a folder holding
            other files, a folder where a file goes or the reverse), I506 for an existing
            file aou did not write (without ``force``).
    """
    where = Span.whole_file(path)
    known = reads if isinstance(reads, ReadSet) else ReadSet(reads)
    found = known.clash(path)
    if found is not None:
        how, read = found
        raise AouError(diag(I502, f"refusing to write `{path}`: it {how} `{read}`, "
                            "which this command reads", where,
                            hint=f"choose another output with {flag}", input=read))
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return  # a new file (or a dangling link, replaced by the file)
    kind = _special(mode)
    if kind is not None:
        raise AouError(diag(I502, f"refusing to write `{path}`: it is a {kind}, not a "
                            "regular file", where, hint=f"choose a file name with {flag}"))
    if bag:
        _guard_bag(path, known, where, stat.S_ISDIR(mode))
    elif stat.S_ISDIR(mode):
        raise AouError(diag(I502, f"cannot write `{path}`: it is a folder", where))
    elif not force and not is_own_output(path):
        raise AouError(diag(I506, f"refusing to replace `{path}`: aou did not write it",
                            where, hint="choose another output with -o, or give --force "
                            "to replace it"))


def _guard_bag(path: str, reads: ReadSet, where: Span, folder: bool) -> None:
    if not folder:
        raise AouError(diag(I502, f"cannot write the bag `{path}`: it is a file, and a "
                            "bag is a folder", where, hint="choose another output with -o"))
    real = os.path.realpath(path)
    read = reads.held_by(real)
    if read is not None:
        raise AouError(diag(I502, f"refusing to write the bag `{path}`: it holds "
                            f"`{read}`, which this command reads", where,
                            hint="choose another output with -o", input=read))
    if os.listdir(real) and not (is_aou_bag(real) or is_aou_dmp(real)):
        raise AouError(diag(I502, f"refusing to write the bag `{path}`: the folder holds "
                            "files other than a bag aou wrote", where,
                            hint="a bag goes into a new or empty folder, or over a bag aou "
                            "wrote: choose another output with -o"))


#: The first line of a text file aou wrote carries this; a JSON document has this
#: ``generator``. aou's own outputs may be replaced without ``--force``.
OWN_MARK = re.compile(rb'\A(#[^\n]*written by `?aouc |\{\s*[^\n]{0,200}?"generator": ?"aouc )')


def is_own_output(path: str) -> bool:
    """Whether the existing regular file ``path`` is one aou wrote: its first line is a
    comment saying ``written by `aouc ...``` (behaviour files from ``synth`` and
    ``variants``, robot descriptions from ``robot -o``), or it is a JSON document whose
    ``generator`` is ``aouc ...`` (on its first line with content, within 200
    characters: trajectories from ``compile``, ``robot -o`` in JSON)."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(512)
    except OSError:
        return False
    return OWN_MARK.match(head) is not None


def temp_prefix() -> str:
    """The name a temporary file or folder of this process starts with."""
    return f".aouc-{os.getpid()}-"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True
    return True


def sweep_stale(folder: str, prefix: str = ".aouc-") -> None:
    """Remove the temporary files and folders (``PREFIX PID-...``) in ``folder`` left by
    processes that no longer run (killed while writing), when this user owns them."""
    import shutil

    pat = re.compile(re.escape(prefix) + r"(\d+)-")
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for e in entries:
        m = pat.match(e.name)
        if m is None or int(m.group(1)) == os.getpid() or _alive(int(m.group(1))):
            continue
        with contextlib.suppress(OSError):
            if e.stat(follow_symlinks=False).st_uid != os.getuid():
                continue
            if e.is_dir(follow_symlinks=False):
                shutil.rmtree(e.path, ignore_errors=True)
            else:
                os.unlink(e.path)


@contextlib.contextmanager
def atomic(path: str, *, inputs: Sequence[str] = ()) -> Iterator[str]:
    """A temporary file name beside ``path`` to write to; renamed over ``path`` when the
    block ends without an exception, removed otherwise. The folders missing on the way
    to ``path`` are made first, and removed again when nothing was written.

    Raises:
        AouError: I502 when the file cannot be written; the codes of :func:`guard_output`
            when it would write over one of ``inputs`` or a special file.
    """
    where = Span.whole_file(path)
    guard_output(path, inputs)
    target = os.path.realpath(path)
    ext = os.path.splitext(path)[1]
    made = make_folders(os.path.dirname(target), where)
    sweep_stale(os.path.dirname(target) or ".")
    try:
        fd, tmp = tempfile.mkstemp(prefix=temp_prefix(), suffix=ext or ".tmp",
                                   dir=os.path.dirname(target) or ".")
        os.close(fd)
    except OSError as exc:
        _remove_folders(made)
        raise AouError(diag(I502, f"cannot write `{path}`: {exc.strerror}", where)) from None
    done = False
    try:
        yield tmp
        os.chmod(tmp, 0o644)  # mkstemp makes files private; outputs are ordinary files
        os.replace(tmp, target)
        done = True
    except OSError as exc:
        raise AouError(diag(I502, f"cannot write `{path}`: {exc.strerror}", where)) from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if not done:
            _remove_folders(made)


def make_folders(folder: str, where: Span) -> list[str]:
    """Make ``folder`` and the folders missing above it; the ones made, deepest first.

    Raises:
        AouError: I502 naming the folder that cannot be made.
    """
    made = []
    while folder and not os.path.lexists(folder):
        made.append(folder)
        folder = os.path.dirname(folder)
    try:
        for f in reversed(made):
            os.mkdir(f)
    except OSError as exc:
        _remove_folders(made)
        raise AouError(diag(I502, f"cannot write `{where.path}`: cannot make the folder "
                            f"`{exc.filename}`: {exc.strerror}", where)) from None
    return made


def _remove_folders(made: list[str]) -> None:
    """Remove the folders :func:`make_folders` made (deepest first), if still empty:
    a failed write leaves nothing behind."""
    for f in made:
        with contextlib.suppress(OSError):
            os.rmdir(f)


def write_atomic(path: str, data: bytes, *, inputs: Sequence[str] = ()) -> None:
    """Write ``data`` to ``path`` atomically; never over one of ``inputs`` (nor against
    the rest of :func:`guard_output`). Where the file system allows, the data goes into
    a file without a name, named only when complete: a process killed while writing
    leaves nothing."""
    where = Span.whole_file(path)
    guard_output(path, inputs)
    target = os.path.realpath(path)
    folder = os.path.dirname(target) or "."
    made = make_folders(folder, where)
    sweep_stale(folder)
    try:
        if _write_unnamed(folder, target, data):
            made = []
            return
    except OSError as exc:
        raise AouError(diag(I502, f"cannot write `{path}`: {exc.strerror}", where)) from None
    finally:
        _remove_folders(made)
    with atomic(path, inputs=inputs) as tmp, open(tmp, "wb") as fh:
        fh.write(data)


def _link(fd: int, path: str) -> bool:
    """Give the unnamed file ``fd`` the name ``path``: ``linkat`` of ``/proc/self/fd/FD``
    following the link (Python's ``os.link`` does not follow it on Linux)."""
    import ctypes

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.linkat(-100, f"/proc/self/fd/{fd}".encode(), -100,  # AT_FDCWD
                           os.fsencode(path), 0x400) == 0  # AT_SYMLINK_FOLLOW
    except (OSError, AttributeError):
        return False


def _write_unnamed(folder: str, target: str, data: bytes) -> bool:
    """Write ``data`` into a file without a name in ``folder``, then name it ``target``;
    False (nothing done) where the file system cannot (no ``O_TMPFILE``, no ``/proc``)."""
    try:
        fd = os.open(folder, os.O_TMPFILE | os.O_WRONLY, 0o644)  # type: ignore[attr-defined]
    except (AttributeError, OSError):
        return False
    try:
        with os.fdopen(fd, "wb", closefd=False) as fh:
            fh.write(data)
        tmp = os.path.join(folder, f"{temp_prefix()}{os.urandom(6).hex()}.link")
        try:  # from before the link: a Ctrl-C just after it must not leave the name
            if not _link(fd, tmp):
                return False
            os.replace(tmp, target)
        finally:
            if os.path.lexists(tmp):
                os.unlink(tmp)
        return True
    finally:
        os.close(fd)


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
            raise AouError(diag(I501, f"cannot read {name}: it is saved as {encoding}, "
                                "not UTF-8", Span.whole_file(path),
                                hint="save it as UTF-8 (in Notepad: Save as, Encoding UTF-8)"))
    try:
        return data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        start = data.rfind(b"\n", 0, exc.start) + 1
        col = len(data[start:exc.start].decode("utf-8", "replace").removeprefix("\ufeff")) + 1
        raise AouError(diag(I501, f"cannot read {name}: not UTF-8 text (byte "
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
        raise AouError(diag(I501, f"cannot read {what + ' ' if what else ''}`{path}`: "
                            f"{reason}", Span.whole_file(path))) from None
    return decode(data, path, what) if text else data
