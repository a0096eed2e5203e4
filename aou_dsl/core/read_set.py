"""The files a command reads, indexed once for the output rule of a whole batch.

:func:`aou_dsl.core.files.guard_output` asks of every output which input it is, links to
or is a hard link of, and (for a bag) which input it holds. Asked of every input in
turn, that is outputs x inputs questions: a batch of a thousand files, a million. A
:class:`ReadSet` answers each in one look-up: it is the tuple of the paths (any code
that iterates the reads still can), with each input's resolved path (``realpath``), its
identity on the file system (device and inode, what ``os.path.samefile`` compares) and
the folders above its resolved path, each mapped to the first input, in the order
given, that has it. The first input an output clashes with is therefore the one the
question asked of every input in turn finds, and the refusal names it the same way.

The identities are taken when the set is made, once per batch, before any work: a
command makes it from the files it is about to read.
"""

from __future__ import annotations

import os
from collections.abc import Iterable

__all__ = ["ReadSet"]


class ReadSet(tuple[str, ...]):
    """The paths a command reads, in order, with their identities indexed."""

    _real: dict[str, int]
    _inode: dict[tuple[int, int], int]
    _unresolved: int | None
    _holders: dict[str, int] | None

    def __new__(cls, paths: Iterable[str]) -> ReadSet:
        self = super().__new__(cls, paths)
        self._real = {}
        self._inode = {}
        self._unresolved = None  # the first path realpath refuses (a NUL in it)
        self._holders = None  # built for the first bag asked about
        for i, read in enumerate(self):
            try:
                real = os.path.realpath(read)
            except (OSError, ValueError):
                if self._unresolved is None:
                    self._unresolved = i
                continue
            self._real.setdefault(real, i)
            try:
                st = os.stat(read)
            except (OSError, ValueError):
                continue
            self._inode.setdefault((st.st_dev, st.st_ino), i)
        return self

    def __reduce__(self) -> tuple:
        """Pickled with its index as taken: a worker that unpickles it compares the
        identities the command took before any work, without looking at every input on
        the file system again for every file it is sent."""
        return (_restored, (tuple(self), self._real, self._inode, self._unresolved,
                            self._holders))

    def clash(self, path: str) -> tuple[str, str] | None:
        """How writing ``path`` would write over an input, and which (the first in
        order): ``("is", read)``, ``("links to", read)``, ``("is a hard link of",
        read)``; None when it would not."""
        try:
            real = os.path.realpath(path)
        except (OSError, ValueError):
            return None
        first = self._real.get(real)
        try:
            st = os.stat(path)
        except (OSError, ValueError):
            hard = None
        else:
            hard = self._inode.get((st.st_dev, st.st_ino))
        if first is not None and (hard is None or first <= hard):
            read = self[first]
            try:
                same = os.path.abspath(path) == os.path.abspath(read)
            except ValueError:
                return None
            return ("is" if same else "links to"), read
        if hard is not None:
            return "is a hard link of", self[hard]
        return None

    def held_by(self, real: str) -> str | None:
        """The first input whose resolved path lies inside the resolved folder ``real``,
        None when there is none.

        Raises:
            ValueError: for an input ``realpath`` refuses, met before any held input,
                as resolving every input in turn meets it.
        """
        if self._holders is None:
            holders: dict[str, int] = {}
            for real_read, i in self._real.items():
                cut = real_read.find(os.sep, 1)
                while cut != -1:
                    if holders.get(real_read[:cut], i + 1) > i:
                        holders[real_read[:cut]] = i
                    cut = real_read.find(os.sep, cut + 1)
            self._holders = holders
        first = self._holders.get(real)
        if self._unresolved is not None and (first is None or self._unresolved < first):
            os.path.realpath(self[self._unresolved])  # raises as the loop over inputs did
        return None if first is None else self[first]


def _restored(paths: tuple[str, ...], real: dict[str, int], inode: dict[tuple[int, int], int],
              unresolved: int | None, holders: dict[str, int] | None) -> ReadSet:
    """A :class:`ReadSet` as it was pickled (:meth:`ReadSet.__reduce__`)."""
    self = tuple.__new__(ReadSet, paths)
    self._real, self._inode = real, inode
    self._unresolved, self._holders = unresolved, holders
    return self
