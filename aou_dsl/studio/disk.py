"""The studio's file on disk: read it, and Save into it without ever losing a file.

The file the studio opened is the one it writes: its real path is fixed when it is
opened (a path given through a symbolic link writes where the link led then). Save
refuses, with a diagnostic said in the page, when

- the path now leads elsewhere, or is now a symbolic link, a folder or a special file
  (checked without following a link, again right before the new file replaces it);
- the file no longer holds the bytes the motion shown was made from: it was edited
  (in an editor, by another program) since the studio read it, and writing would throw
  that edit away. The page's Reload takes the file's text instead.

The new text goes into a temporary file beside the old one, with its mode (and, where
allowed, its owner), and is renamed over it: the file is the old one or the new one,
never half of either.
"""

from __future__ import annotations

import contextlib
import os
import stat

from ..core.codes import I501, I502
from ..core.diagnostics import AouError, Span, diag
from ..core.files import decode, temp_prefix
from ..core.inputs import what_it_is

__all__ = ["MAX_BYTES", "Disk"]

#: The largest file the studio reads [bytes] (a behaviour is a few hundred).
MAX_BYTES = 16 * 1024 * 1024


class Disk:
    """The file at ``path``, as the studio opened it."""

    def __init__(self, path: str) -> None:
        self.path = path
        self.target = os.path.realpath(path)

    def read(self) -> bytes:
        """The file's bytes now.

        Raises:
            AouError: I501 when it cannot be read (gone, a link now, a folder, a FIFO,
                larger than :data:`MAX_BYTES`).
        """
        data = self._current(I501, "read")
        if data is None:
            raise self._error(I501, "read", "it no longer exists")
        return data

    def text(self, data: bytes) -> str:
        """``data`` read as the studio's text (I501 when it is not UTF-8)."""
        return decode(data, self.path)

    def save(self, data: bytes, expect: bytes) -> None:
        """Replace the file by ``data``, if it still holds ``expect``.

        Raises:
            AouError: I502 naming why nothing was written.
        """
        if os.path.realpath(self.path) != self.target:
            raise self._error(I502, "save into", "the path now leads to another file "
                              f"({os.path.realpath(self.path)})")
        now = self._current(I502, "save into")
        if now is None:
            raise self._error(I502, "save into", "it no longer exists")
        if now != expect:
            raise self._error(I502, "save into", "the file changed on disk since the "
                              "studio read it; saving would lose that edit. Reload takes "
                              "the file's text (the values set here go)")
        folder, name = os.path.split(self.target)
        try:
            dfd = os.open(folder or ".", os.O_RDONLY | os.O_DIRECTORY)
            try:
                self._replace(dfd, name, data)
            finally:
                os.close(dfd)
        except OSError as exc:  # a folder one may not write in, a full disk, ...
            raise self._error(I502, "save into", exc.strerror or str(exc)) from None

    def _replace(self, dfd: int, name: str, data: bytes) -> None:
        before = self._plain(os.stat(name, dir_fd=dfd, follow_symlinks=False))
        tmp = f"{temp_prefix()}{os.urandom(6).hex()}.save"
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600,
                     dir_fd=dfd)
        try:
            try:
                with os.fdopen(fd, "wb", closefd=False) as fh:
                    fh.write(data)
                    fh.flush()
                    os.fsync(fh.fileno())
                os.fchmod(fd, stat.S_IMODE(before.st_mode))
                with contextlib.suppress(OSError):  # another user's file: its owner stays
                    os.fchown(fd, before.st_uid, before.st_gid)     # unless we may not
            finally:
                os.close(fd)
            # Right before the rename: still the very file checked, a plain file (a link
            # swapped in since is refused; the rename never follows one).
            last = self._plain(os.stat(name, dir_fd=dfd, follow_symlinks=False))
            if (last.st_dev, last.st_ino) != (before.st_dev, before.st_ino):
                raise self._error(I502, "save into", "the file was replaced while saving")
            os.replace(tmp, name, src_dir_fd=dfd, dst_dir_fd=dfd)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp, dir_fd=dfd)
            raise

    def _plain(self, st: os.stat_result) -> os.stat_result:
        """``st`` when it is a plain file's (else I502 naming what it is)."""
        if not stat.S_ISREG(st.st_mode):
            raise self._error(I502, "save into", f"it is now {_kind(st.st_mode)}")
        return st

    def _current(self, code: str, doing: str) -> bytes | None:
        """The bytes at the opened path, without following a link (None: no file)."""
        try:
            fd = os.open(self.target, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
        except FileNotFoundError:
            return None
        except OSError as exc:
            try:
                st = os.lstat(self.target)
            except OSError:
                raise self._error(code, doing, exc.strerror or str(exc)) from None
            raise self._error(code, doing, f"it is now {_kind(st.st_mode)}") from None
        try:
            st = os.fstat(fd)
            if not stat.S_ISREG(st.st_mode):
                raise self._error(code, doing, f"it is now {_kind(st.st_mode)}")
            if st.st_size > MAX_BYTES:
                raise self._error(code, doing, f"it is larger than {MAX_BYTES} bytes "
                                  "(MAX_BYTES)")
            chunks = []
            size = 0
            while chunk := os.read(fd, 1 << 16):
                size += len(chunk)
                if size > MAX_BYTES:
                    raise self._error(code, doing, f"it is larger than {MAX_BYTES} "
                                      "bytes (MAX_BYTES)")
                chunks.append(chunk)
            return b"".join(chunks)
        finally:
            os.close(fd)

    def _error(self, code: str, doing: str, why: str) -> AouError:
        return AouError(diag(code, f"cannot {doing} `{self.path}`: {why}",
                             Span.whole_file(self.path)))


def _kind(mode: int) -> str:
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    if stat.S_ISREG(mode):
        return "a file"
    return what_it_is(mode)
