"""One message per cause.

A statement repeated (``retreat 5mm a=2 x3``) is compiled once per repeat, and each
repeat may fail the same way: the user should read it once, with the count.
:func:`said_once` folds diagnostics of one code at one statement into one; the one kept
is the most telling (for a reached value, the lowest: the value that fits every repeat).
:func:`once_per_run` keeps a robot's own warnings (C313: limits from no source) to their
first appearance in a run of many files.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable, Iterator
from dataclasses import replace
from typing import Any

from .codes import C313
from .diagnostics import Diagnostic

__all__ = ["PER_RUN", "once_per_run", "said_once"]

#: Codes said of the robot, not of a file: once per robot in a run.
PER_RUN = frozenset({C313})


def _key(d: Diagnostic) -> tuple:
    s = d.span
    return (d.code, s.path, s.line, s.col, s.end_line, s.end_col, d.fields.get("check"),
            d.fields.get("key"))


def _rank(d: Diagnostic) -> float:
    """Which of a group to keep: the lowest value the arm reached, else the first."""
    achieved = d.fields.get("achieved")
    return float(achieved) if isinstance(achieved, int | float) else 0.0


def said_once(diagnostics: Iterable[Diagnostic]) -> list[Diagnostic]:
    """``diagnostics`` with the compiler's (C-codes) of one code at one span (and, for a
    failed check, one check) folded into one, in the order of their first; the one kept
    says how many repeats it stands for (``repeats`` in its fields). What lint says is
    kept as it is: each of its diagnostics has its own place."""
    groups: dict[tuple, list[Diagnostic]] = {}
    for i, d in enumerate(diagnostics):
        groups.setdefault(_key(d) if d.code.startswith("C") else (i,), []).append(d)
    out = []
    for group in groups.values():
        if len(group) == 1:
            out.append(group[0])
            continue
        best = min(group, key=_rank)
        fields: dict[str, Any] = {**best.fields, "repeats": len(group)}
        out.append(replace(best, message=f"{best.message} (at each of the {len(group)} "
                           "repeats of this statement; said once)", fields=fields))
    return out


def once_per_run(results: Iterable[Any]) -> Iterator[Any]:
    """Each result (with a ``diagnostics`` list) as it comes, without the :data:`PER_RUN`
    diagnostics an earlier result of the run already carried (the same code and
    message: one robot); a result that loses some is a shallow copy."""
    said: set[tuple[str, str]] = set()
    for res in results:
        keep = []
        for d in res.diagnostics:
            if d.code in PER_RUN:
                if (d.code, d.message) in said:
                    continue
                said.add((d.code, d.message))
            keep.append(d)
        if len(keep) == len(res.diagnostics):
            yield res
            continue
        out = copy.copy(res)  # a result a cache keeps is not changed
        out.diagnostics = keep
        yield out
