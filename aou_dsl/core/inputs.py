"""Reading what a user gives aou: regular files only, and only so much of them.

Every file aou reads on a user's behalf (a ``.aou`` file, a robot file, a trajectory or a
recording) is read here. A FIFO, a device or a socket is refused before a byte is read
(reading one may never end: ``/dev/zero``, a pipe no one writes to). A regular file is
read up to a bound per kind; a larger one is refused with a code that names the bound
and the environment variable that raises it:

- a ``.aou`` file: 1 MB (V132);
- a robot file (URDF, robot description): 16 MB (V132);
- a mesh a URDF names: 64 MB (V132; PyBullet reads it, after :func:`check_size`);
- a trajectory or recording: 256 MB, and 2,000,000 samples (R410);
- a study file: 1 MB (E701); a study's results: 256 MB (E703).

``AOU_MAX_INPUT_MB`` raises (or lowers) the size bound of every kind;
``AOU_MAX_SAMPLES`` the samples of a recording.
"""

from __future__ import annotations

import os
import stat

from .codes import E701, E703, I501, I504, R410, V132
from .diagnostics import AouError, Span, diag

__all__ = ["ENV_BYTES", "ENV_SAMPLES", "LIMITS", "check_regular", "check_size", "input_limit",
           "max_samples", "read_input", "read_input_text", "size_text", "too_many_samples",
           "what_it_is"]

_MB = 1 << 20
#: kind -> (bound [bytes], the code of a file over it, what a file of the kind is).
LIMITS: dict[str, tuple[int, str, str]] = {
    "behaviour": (1 * _MB, V132, "a .aou file"),
    "robot": (16 * _MB, V132, "a robot file"),
    "mesh": (64 * _MB, V132, "a mesh file"),
    "recording": (256 * _MB, R410, "a trajectory or recording"),
    "study": (1 * _MB, E701, "a study file"),
    "results": (256 * _MB, E703, "a study's results"),
}
#: Most samples of a recording read by default.
MAX_SAMPLES = 2_000_000
ENV_BYTES = "AOU_MAX_INPUT_MB"
ENV_SAMPLES = "AOU_MAX_SAMPLES"


def _env_number(name: str, default: float) -> float:
    """The positive number in the environment variable ``name``, else ``default``.

    Raises:
        AouError: I504 for a value that is not a positive number.
    """
    text = os.environ.get(name, "").strip()
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 < value < 1e12:
        raise AouError(diag(I504, f"{name}={text!r} is not a positive number",
                            Span.whole_file(f"<environment {name}>"),
                            hint=f"unset it, or give a number, e.g. {name}=512"))
    return value


def input_limit(kind: str) -> int:
    """The most bytes read of a file of ``kind`` (a key of :data:`LIMITS`)."""
    default = LIMITS[kind][0]
    return int(_env_number(ENV_BYTES, default / _MB) * _MB)


def max_samples() -> int:
    """The most samples read of a recording."""
    return int(_env_number(ENV_SAMPLES, MAX_SAMPLES))


def what_it_is(mode: int) -> str:
    """What a file that is not a regular one is, in words (``a FIFO (a named pipe)``)."""
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (a named pipe)"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _not_regular(path: str, what: str, mode: int) -> AouError:
    name = f"{what + ' ' if what else ''}`{path}`"
    return AouError(diag(I501, f"cannot read {name}: it is {what_it_is(mode)}, not a "
                         "regular file", Span.whole_file(path),
                         hint="aou reads inputs from regular files only: save the data "
                              "to a file first"))


def _cannot(path: str, what: str, exc: OSError) -> AouError:
    reason = exc.strerror or str(exc)
    return AouError(diag(I501, f"cannot read {what + ' ' if what else ''}`{path}`: {reason}",
                         Span.whole_file(path)))


def check_regular(path: str, what: str = "") -> None:
    """Refuse (I501) a path that is missing or not a regular file (links followed)."""
    try:
        mode = os.stat(path).st_mode
    except OSError as exc:
        raise _cannot(path, what, exc) from None
    if not stat.S_ISREG(mode):
        raise _not_regular(path, what, mode)


def size_text(n: float) -> str:
    """``n`` bytes in words: `3.2 MB`, `10,240 bytes`."""
    return f"{n / _MB:.1f} MB" if n >= 0.1 * _MB else f"{int(n):,} bytes"


def _too_large(path: str, kind: str, size: int | None) -> AouError:
    limit, code, noun = LIMITS[kind]
    bound = input_limit(kind)
    found = f" ({size_text(size)})" if size is not None else ""
    return AouError(diag(code, f"`{path}` is larger{found} than aou reads of {noun} "
                         f"({size_text(bound)})", Span.whole_file(path),
                         hint=f"if the file is right, raise the bound: set {ENV_BYTES} "
                              f"(in MB, e.g. {ENV_BYTES}={max(2 * bound // _MB, 1)})",
                         limit=bound, default=limit, variable=ENV_BYTES))


def check_size(path: str, kind: str, what: str = "") -> None:
    """Refuse a file another library is to read (a mesh PyBullet loads) when it is not a
    regular file, or larger than the bound of ``kind``.

    Raises:
        AouError: I501 when it is missing or not a regular file; the code of ``kind``
            (V132, R410) when it is larger than the bound.
    """
    check_regular(path, what)
    try:
        size = os.stat(path).st_size
    except OSError as exc:
        raise _cannot(path, what, exc) from None
    if size > input_limit(kind):
        raise _too_large(path, kind, size)


def read_input(path: str, kind: str, what: str = "") -> bytes:
    """The bytes of the regular file ``path``, at most the bound of ``kind``.

    The file is opened without waiting (a FIFO swapped in after the check does not
    block) and checked again once open.

    Raises:
        AouError: I501 when it is missing, unreadable or not a regular file; V132 or
            R410 (by ``kind``) when it is larger than the bound.
    """
    check_regular(path, what)
    bound = input_limit(kind)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | \
        getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        raise _cannot(path, what, exc) from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise _not_regular(path, what, info.st_mode)
        if info.st_size > bound:
            raise _too_large(path, kind, info.st_size)
        with os.fdopen(fd, "rb", closefd=False) as fh:
            data = fh.read(bound + 1)
    except OSError as exc:
        raise _cannot(path, what, exc) from None
    finally:
        os.close(fd)
    if len(data) > bound:  # it grew while being read
        raise _too_large(path, kind, None)
    return data


def read_input_text(path: str, kind: str, what: str = "") -> str:
    """:func:`read_input` decoded as UTF-8 (a leading byte-order mark dropped).

    Raises:
        AouError: as :func:`read_input`; I501 for text that is not UTF-8.
    """
    from .files import decode

    return decode(read_input(path, kind, what), path, what)


def too_many_samples(path: str, found: int | str, source: str = "") -> AouError:
    """R410 for a recording of more samples than :func:`max_samples`; ``found`` says how
    many, ``source`` what says so."""
    bound = max_samples()
    found = f"{found:,}" if isinstance(found, int) else found
    return AouError(diag(R410, f"`{path}` has {found} samples{source}; aou reads at most "
                         f"{bound:,}", Span.whole_file(path),
                         hint=f"if the recording is right, raise the bound: set "
                              f"{ENV_SAMPLES} (e.g. {ENV_SAMPLES}={2 * bound}), or "
                              "resample it", limit=bound, variable=ENV_SAMPLES))
