"""The studio's edits of a ``.aou`` text: new descriptor values written into the text.

Pure: text in, text out. Only the tokens that carry a changed value are rewritten, at
their source spans (a statement's ``a=0.05``, its ``1.67s``, its ``x5``); every other
byte (comments, blank lines, spacing, units of the values left alone) stays. The new
token is taken from the formatter's printer (each kind's ``format``), so a value is
written the way ``aouc synth`` and ``aouc variants`` write it: six significant digits in
the descriptor's unit. A value the statement leaves to its default (``approach`` with no
``a=``) is added after the statement's last argument, a count before the end.

Only the descriptor form has one statement per descriptor; :func:`settable` says which
descriptors a text sets, :func:`apply` rewrites them.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..core.codes import I504
from ..core.diagnostics import AouError, Span, diag
from ..lang.declared import source_of, written
from ..lang.descriptors import REGISTRY
from ..lang.ir import Behaviour
from ..lang.linter import lint_source
from ..lang.parse import KeyVal, Quantity, Statement, Word, parse
from ..lang.primitives import KINDS

__all__ = ["Edit", "apply", "settable", "synth_origin"]

#: The first line ``aouc synth`` writes for a state: its state and intensity.
_SYNTH = re.compile(r"# (\w+) at intensity ([0-9.]+), written by `aouc synth`")


@dataclass(frozen=True)
class Edit:
    """One rewrite: the text from ``start`` to ``end`` (offsets) becomes ``new``."""

    start: int
    end: int
    new: str


def settable(b: Behaviour) -> dict[str, float | int]:
    """The descriptors the file sets, in the descriptor's unit (as ``aouc measure``
    reports them): one statement each, so only descriptor-form files have any."""
    if b.form != "descriptor":
        return {}
    values = written(b)
    out: dict[str, float | int] = {}
    for name in REGISTRY:
        v = values[name]
        if source_of(b, name) is not None and v is not None:
            out[name] = v
    return out


def synth_origin(text: str) -> tuple[str, float] | None:
    """``(state, intensity)`` of a file ``aouc synth`` wrote for a state (its first
    line says so), else None: such a file can be written again at another intensity."""
    found = _SYNTH.match(text)
    if found is None or "\n# C-V point (" in text:  # a blend: its point is not kept
        return None
    return found.group(1), float(found.group(2))


def apply(text: str, changes: Mapping[str, float], path: str = "<studio>") -> str:
    """``text`` with the descriptors of ``changes`` (name -> value in the descriptor's
    unit) rewritten; values equal to the file's leave it unchanged.

    Raises:
        AouError: the text does not lint (its own diagnostics), it is not in the
            descriptor form, a name is not one it sets (I504), or the new text would not
            lint (its diagnostics, said at the statement changed).
    """
    lint = lint_source(text, path)
    b = lint.behaviour
    if not lint.ok or b is None:
        raise AouError([d for d in lint.diagnostics if d.severity == "error"])
    now = settable(b)
    edits: list[Edit] = []
    for name, value in changes.items():
        if name not in now:
            raise AouError(diag(I504, f"the file sets no `{name}` to change: the studio "
                                "changes the descriptors a descriptor-form file sets",
                                b.span))
        if _same(name, now[name], value):
            continue
        edits.append(_edit(text, b, name, value, path))
    new = _splice(text, edits)
    after = lint_source(new, path)
    if not after.ok:
        raise AouError([d for d in after.diagnostics if d.severity == "error"])
    return new


def _same(name: str, old: float, new: float) -> bool:
    d = REGISTRY[name]
    if d.is_count:
        return int(old) == int(round(new))
    return f"{old * d.scale:.6g}" == f"{new * d.scale:.6g}"


def _edit(text: str, b: Behaviour, name: str, value: float, path: str) -> Edit:
    """The rewrite of one descriptor's token in its statement."""
    d = REGISTRY[name]
    node = source_of(b, name)
    new_value = int(round(value)) if d.is_count else value * d.scale
    if d.is_count and new_value < 0:
        raise AouError(diag(I504, f"{name} is a count: 0 or more, found {new_value}",
                            node.span))
    printed = KINDS[d.kind].format(node.replace(**{d.ir_field: new_value}))
    fresh = _statement(parse(printed + "\n", path), 1)
    st = _statement(parse(text, path), node.span.line)
    printed_token = _token(fresh, d.ir_field)
    new = (f"x{new_value}" if printed_token is None  # the printer leaves out `x1`
           else printed[printed_token.span.col - 1:printed_token.span.end_col - 1])
    token = _token(st, d.ir_field)
    if token is not None:
        return Edit(_offset(text, token.span, False), _offset(text, token.span, True), new)
    where = _offset(text, _insert_at(st, d.ir_field), True)
    return Edit(where, where, " " + new)


def _statement(tree, line: int) -> Statement:
    for item in tree.items:
        for st in getattr(item, "statements", (item,)):
            if st.span.line == line:
                return st
    raise LookupError(f"no statement on line {line}")  # the IR's spans come from this parse


def _is_count(a) -> bool:
    return isinstance(a, Word) and a.text[:1] == "x" and a.text[1:].isdigit()


def _token(st: Statement, field: str) -> Any:
    """The argument of ``st`` that carries IR ``field``: ``xN`` for the count, ``key=``
    for a key the kind takes, else the first number."""
    kind = KINDS[st.keyword]
    for a in st.args:
        if field == "count" and _is_count(a):
            return a
        if field in kind.keys and isinstance(a, KeyVal) and a.key == field:
            return a
        if field != "count" and field not in kind.keys and isinstance(a, Quantity):
            return a
    return None


def _insert_at(st: Statement, field: str) -> Span:
    """Where a missing argument goes: after the last argument (a key before the count)."""
    args = [a for a in st.args if not (field != "count" and _is_count(a))]
    return args[-1].span if args else st.keyword_span


def _offset(text: str, span: Span, end: bool) -> int:
    line, col = (span.end_line, span.end_col) if end else (span.line, span.col)
    lines = text.splitlines(keepends=True)
    return sum(len(x) for x in lines[:line - 1]) + col - 1


def _splice(text: str, edits: list[Edit]) -> str:
    for e in sorted(edits, key=lambda e: e.start, reverse=True):
        text = text[:e.start] + e.new + text[e.end:]
    return text
