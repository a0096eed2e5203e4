"""Every cache of the process, in one registry: what a warm tool keeps between builds.

A warm tool (the language server, the studio, a :class:`~aou_dsl.driver.session.Session`,
a pool worker) builds again and again in one process, and keeps what is slow to make: the
parser, loaded arms, each motion episode's IK and time law, the checks' scenes. Each such
cache is made here, by :func:`cached` (a function's results, least recently used first
out) or :func:`table` (a bounded map a module fills itself), and registered by name, so
that every one can be found, measured (:func:`stats`) and emptied (:func:`clear`);
``tests/unit/test_layers.py`` fails on a ``functools`` cache anywhere else in the package.

Every cache has a size: memory stays bounded by the sizes given where each is made
(:func:`stats` gives each one's bytes, about; the largest hold arms, scenes and per-row
memos, a few megabytes each).

A cache never lies: its key holds everything its result depends on. A result that
depends on a file (a robot description, its URDF, the meshes) is keyed by the file's
content, through :func:`file_digest`: a ``stat`` of the file per look-up, and its bytes
hashed again only when the ``stat`` changed (or the file was written so recently that a
later write could leave the same ``stat``).
"""

from __future__ import annotations

import functools
import hashlib
import os
import stat
import sys
import threading
import time
import types
from collections import OrderedDict
from collections.abc import Callable, Hashable, Iterable
from dataclasses import dataclass, field
from typing import Any, TypeVar

__all__ = ["CacheStats", "Keyed", "cached", "caches", "clear", "file_digest", "files_key",
           "stats", "table"]

F = TypeVar("F", bound=Callable[..., Any])

#: A file whose modification time is within this of when it was hashed is hashed again
#: at its next look-up: a file system's clock may not tell two writes that close apart
#: (the same size, modification time and inode after both) [ns].
RACY_NS = 2_000_000_000
#: The most files whose digests are kept.
FILES_KEPT = 4096
#: The deepest :func:`_size_of` walks into a cached value.
_SIZE_DEPTH = 8


@dataclass(frozen=True)
class Keyed:
    """``value`` (an arm model with arrays, a closure) that compares and hashes by ``key``
    alone, so a function cached with :func:`cached` can take it; the caller promises
    that equal keys mean equal values."""

    key: Hashable
    value: Any = field(compare=False, hash=False)


@dataclass(frozen=True)
class CacheStats:
    """One cache's use since it was made or last cleared, and what it holds now."""

    name: str
    hits: int
    misses: int
    entries: int
    maxsize: int
    bytes: int

    def to_json(self) -> dict[str, Any]:
        return {"hits": self.hits, "misses": self.misses, "entries": self.entries,
                "maxsize": self.maxsize, "bytes": self.bytes}


class Table:
    """A bounded map of results, least recently used first out, counting its hits and
    misses; made by :func:`table` or :func:`cached`, which register it."""

    def __init__(self, name: str, maxsize: int):
        if maxsize < 1:
            raise ValueError(f"cache {name}: a size of at least 1")
        self.name = name
        self.maxsize = maxsize
        self.hits = 0
        self.misses = 0
        self._data: OrderedDict[Hashable, Any] = OrderedDict()
        self._lock = threading.Lock()

    def __len__(self) -> int:
        return len(self._data)

    def get(self, key: Hashable, default: Any = None) -> Any:
        """The value kept for ``key`` (now the most recently used), else ``default``."""
        try:
            value = self._data[key]
        except KeyError:
            self.misses += 1
            return default
        self.hits += 1
        try:
            self._data.move_to_end(key)
        except KeyError:  # dropped by another thread meanwhile
            pass
        return value

    def put(self, key: Hashable, value: Any) -> None:
        """Keep ``value`` for ``key``; the least recently used go past :attr:`maxsize`."""
        with self._lock:
            self._data[key] = value
            self._data.move_to_end(key)
            while len(self._data) > self.maxsize:
                self._data.popitem(last=False)

    def clear(self) -> None:
        """Forget every value and the counts."""
        with self._lock:
            self._data.clear()
            self.hits = self.misses = 0

    def values(self) -> list[Any]:
        with self._lock:
            return list(self._data.values())

    def stats(self) -> CacheStats:
        with self._lock:
            items = list(self._data.items())
        seen: set[int] = set()
        size = sum(_size_of(k, seen) + _size_of(v, seen) for k, v in items)
        return CacheStats(self.name, self.hits, self.misses, len(items), self.maxsize, size)


class _Registry:
    """The caches of the process by name (one object: the module holds no other state)."""

    def __init__(self) -> None:
        self.tables: dict[str, Table] = {}
        self.lock = threading.Lock()

    def add(self, t: Table) -> Table:
        with self.lock:
            if t.name in self.tables:
                raise ValueError(f"two caches named {t.name}")
            self.tables[t.name] = t
        return t


_REGISTRY = _Registry()


def table(name: str, maxsize: int) -> Table:
    """A new registered :class:`Table` named ``name`` (``module.purpose``)."""
    return _REGISTRY.add(Table(name, maxsize))


def cached(maxsize: int) -> Callable[[F], F]:
    """``functools.lru_cache(maxsize)``, registered under the function's module and name:
    ``f.cache`` is its :class:`Table`, ``f.cache_clear()`` empties it. Arguments are
    the key (by equality and hash: pass files by :func:`file_digest`, not by name)."""

    def decorate(fn: F) -> F:
        t = table(f"{fn.__module__}.{fn.__qualname__}", maxsize)
        data = t._data
        miss = object()

        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            key = (args, tuple(kwargs.items())) if kwargs else args
            value = data.get(key, miss)
            if value is miss:
                t.misses += 1
                value = fn(*args, **kwargs)
                t.put(key, value)
                return value
            t.hits += 1
            try:
                data.move_to_end(key)
            except KeyError:  # dropped by another thread meanwhile
                pass
            return value

        wrapper.cache = t  # type: ignore[attr-defined]
        wrapper.cache_clear = t.clear  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return decorate


def caches() -> dict[str, Table]:
    """Every registered cache by name (those of the modules imported so far)."""
    with _REGISTRY.lock:
        return dict(_REGISTRY.tables)


def clear(names: Iterable[str] | None = None) -> None:
    """Empty every registered cache (or those named): the next build makes everything
    again, as a new process would."""
    for name, t in caches().items():
        if names is None or name in names:
            t.clear()


def stats() -> dict[str, CacheStats]:
    """Hits, misses, entries and bytes (about) of every registered cache."""
    return {name: t.stats() for name, t in sorted(caches().items())}


# --- File contents ----------------------------------------------------------------------

_DIGESTS = table("aou_dsl.core.memo.file_digest", FILES_KEPT)


def _stamp(path: str) -> tuple[int, int, int, int, int] | None:
    """A regular file's identity; None for anything else (reading a device, a FIFO or
    a folder to hash it may never end: the load that reads it says what it is). The
    status change time is in it: a copy that puts the old modification time back
    (``cp -p``, ``rsync -t``, ``tar``) cannot set that one."""
    try:
        st = os.stat(path)
    except (OSError, ValueError, TypeError):  # not there, a NUL in it, not a path
        return None
    if not stat.S_ISREG(st.st_mode):
        return None
    return st.st_size, st.st_mtime_ns, st.st_ino, st.st_dev, st.st_ctime_ns


def file_digest(path: str) -> str:
    """The SHA-256 of the file at ``path``, in hex ("" when it cannot be read): the
    bytes are hashed again only when the file's size, modification time, status change
    time or inode changed since, or when it had been written within :data:`RACY_NS` of its last
    hashing (a second write in the same clock tick keeps the ``stat``)."""
    stamp = _stamp(path)
    if stamp is None:
        return ""
    kept = _DIGESTS.get(path)
    if kept is not None and kept[0] == stamp and kept[2] - stamp[1] > RACY_NS:
        return kept[1]
    now = time.time_ns()
    try:
        h = hashlib.sha256()
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
    except OSError:
        return ""
    digest = h.hexdigest()
    _DIGESTS.put(path, (stamp, digest, now))
    return digest


def files_key(paths: Iterable[str]) -> tuple[tuple[str, str], ...]:
    """Each path with its :func:`file_digest`: a key for what was made from the files."""
    return tuple((p, file_digest(p)) for p in paths)


# --- Sizes ------------------------------------------------------------------------------

def _size_of(obj: Any, seen: set[int], depth: int = 0) -> int:
    """The bytes ``obj`` holds, about: containers, records and arrays walked (each object
    once), other objects by their own size."""
    if id(obj) in seen:
        return 0
    seen.add(id(obj))
    nbytes = getattr(obj, "nbytes", None)
    if isinstance(nbytes, int) and type(obj).__module__.startswith("numpy"):
        base = getattr(obj, "base", None)
        return sys.getsizeof(obj) + (0 if base is not None else nbytes)
    try:
        size = sys.getsizeof(obj)
    except TypeError:
        size = 0
    if depth >= _SIZE_DEPTH or isinstance(obj, (str, bytes, int, float, type,
                                                types.ModuleType, types.FunctionType)):
        return size  # a module or a function is the program's, not the cache's
    if isinstance(obj, dict):
        return size + sum(_size_of(k, seen, depth + 1) + _size_of(v, seen, depth + 1)
                          for k, v in list(obj.items()))
    if isinstance(obj, (list, tuple, set, frozenset)):
        return size + sum(_size_of(v, seen, depth + 1) for v in list(obj))
    if isinstance(obj, Table):
        return size + sum(_size_of(v, seen, depth + 1) for v in obj.values())
    inner = getattr(obj, "__dict__", None)
    if isinstance(inner, dict):
        size += _size_of(inner, seen, depth + 1)
    for slot in getattr(type(obj), "__slots__", ()):
        size += _size_of(getattr(obj, slot, None), seen, depth + 1)
    return size
