"""A key for ``functools`` caches whose arguments are fixed by a key but are not hashable."""

from __future__ import annotations

from collections.abc import Hashable
from dataclasses import dataclass, field
from typing import Any

__all__ = ["Keyed"]


@dataclass(frozen=True)
class Keyed:
    """``value`` (an arm model with arrays, a closure) that compares and hashes by ``key``
    alone, so a function cached with :func:`functools.lru_cache` can take it; the caller
    promises that equal keys mean equal values."""

    key: Hashable
    value: Any = field(compare=False, hash=False)
