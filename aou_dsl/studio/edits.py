"""The studio's edits of a ``.aou`` text: new descriptor values written into the text.

Pure: text in, text out. Only the tokens that carry a changed value are rewritten, at
their source spans (a statement's ``a=0.05``, its ``1.67s``, its ``x5``); every other
byte (comments, blank lines, spacing, units of the values left alone) stays. The new
token is taken from the formatter's printer (each kind's ``format``), so a value is
written the way ``aouc synth`` and ``aouc variants`` write it: six significant digits in
the descriptor's unit. A value the statement leaves to its default (``approach`` with no
``a=``) is added after the statement's last argument, a count before the end.

The descriptor form (on many lines or on one, ``approach a=0.05; pause 1.67s x5``) has
one statement per descriptor: its value is the statement's. A ``sequence { }`` sets a
descriptor through every statement of its kind (the median or the largest of their
episodes): a new value scales all of them by one factor, so their signs and proportions
stay, and the laid-out timeline then declares the new value. A sequence's counts are its
order of statements: the studio leaves them to the text. :func:`settable` says which
descriptors a text sets, :func:`apply` rewrites them.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, NamedTuple

from ..core.codes import I504
from ..core.diagnostics import AouError, Span, diag
from ..lang.declared import declared, source_of, written
from ..lang.ir import Behaviour
from ..lang.linter import lint_source
from ..lang.parse import KeyVal, Quantity, Statement, Word, parse
from ..lang.primitives import KINDS
from ..lang.timeline import Timeline
from .kind_controls import descriptor_of, descriptors

__all__ = ["Edit", "Origin", "apply", "settable", "synth_origin"]

#: The first line ``aouc synth`` writes: the state and the intensity it was asked for.
_SYNTH = re.compile(r"# (\w+) at intensity ([0-9.eE+-]+), written by `aouc synth`")
#: The line of a blend of states: the C-V point it was written for.
_POINT = re.compile(r"^# C-V point \(([-+][0-9.]+), ([-+][0-9.]+)\)", re.MULTILINE)
#: Rescaling rounds that bring a sequence's declared value to the one asked for.
_ROUNDS = 3


@dataclass(frozen=True)
class Edit:
    """One rewrite: the text from ``start`` to ``end`` (offsets) becomes ``new``."""

    start: int
    end: int
    new: str


class Origin(NamedTuple):
    """What ``aouc synth`` wrote a file for: a state, or (``point``) the C-V point whose
    blend of states reads as ``state``, at ``intensity``."""

    state: str
    intensity: float
    point: tuple[float, float] | None = None


def settable(b: Behaviour, timeline: Timeline | None = None) -> dict[str, float | int]:
    """The descriptors the file sets, in the descriptor's unit (as ``aouc measure``
    reports them). The descriptor form: each one a statement sets. A sequence (its
    ``timeline`` needed): each non-count descriptor its statements give a value."""
    if b.form == "sequence":
        return _sequence_values(b, timeline) if timeline is not None else {}
    values = written(b)
    out: dict[str, float | int] = {}
    for name in descriptors():
        v = values.get(name)
        if v is not None and source_of(b, name) is not None:
            out[name] = v
    return out


def _sequence_values(b: Behaviour, timeline: Timeline) -> dict[str, float | int]:
    values = declared(b, timeline)
    out: dict[str, float | int] = {}
    for name, d in descriptors().items():
        v = values.get(name)
        if not d.is_count and v and _sources(b, name):
            out[name] = v
    return out


def _sources(b: Behaviour, name: str) -> list[Any]:
    """The statements that set descriptor ``name``: one node per statement (a
    sequence's ``xN`` may repeat a node)."""
    d = descriptor_of(name)
    seen: dict[tuple[int, int], Any] = {}
    for p in b.primitives:
        plane = getattr(p, "plane", None)  # a kind with planes: one descriptor each
        if p.kind == d.kind and (plane is None or plane == d.key):
            seen.setdefault((p.span.line, p.span.col), p)
    return list(seen.values())


def synth_origin(text: str) -> Origin | None:
    """What a file ``aouc synth`` wrote came from (its first lines say so), else None:
    such a file can be written again at another intensity."""
    found = _SYNTH.match(text)
    if found is None:
        return None
    point = _POINT.search(text)
    return Origin(found.group(1), float(found.group(2)),
                  (float(point.group(1)), float(point.group(2))) if point else None)


def apply(text: str, changes: Mapping[str, float], path: str = "<studio>") -> str:
    """``text`` with the descriptors of ``changes`` (name -> value in the descriptor's
    unit) rewritten; values equal to the file's leave it unchanged.

    Raises:
        AouError: the text does not lint (its own diagnostics), a name is not one it
            sets (I504), or the new text would not lint (its diagnostics, said at the
            statement changed).
    """
    lint = _linted(text, path)
    b = lint.behaviour
    now = settable(b, lint.timeline)
    edits: list[Edit] = []
    for name, value in changes.items():
        if name not in now:
            raise AouError(diag(I504, f"the file sets no `{name}` to change: the studio "
                                "changes the descriptors the file sets (in a sequence, "
                                "all but the counts)", b.span))
        if _same(name, now[name], value):
            continue
        if b.form == "sequence":
            edits += _scaled(text, b, name, value / now[name], path)
        else:
            edits.append(_edit(text, source_of(b, name), name, value, path))
    new = _splice(text, edits)
    if b.form == "sequence":
        new = _rescaled(new, {n: v for n, v in changes.items() if not _same(n, now[n], v)},
                        path)
    _linted(new, path)
    return new


def _linted(text: str, path: str):
    lint = lint_source(text, path)
    if not lint.ok or lint.behaviour is None:
        raise AouError([d for d in lint.diagnostics if d.severity == "error"])
    return lint


def _rescaled(text: str, wanted: Mapping[str, float], path: str) -> str:
    """A sequence's values scaled again until the timeline declares ``wanted`` (a
    descriptor that is not exactly proportional to its statements' values)."""
    for _ in range(_ROUNDS):
        lint = _linted(text, path)
        now = settable(lint.behaviour, lint.timeline)
        edits = [e for n, v in wanted.items() if n in now and not _same(n, now[n], v)
                 for e in _scaled(text, lint.behaviour, n, v / now[n], path)]
        if not edits:
            break
        text = _splice(text, edits)
    return text


def _scaled(text: str, b: Behaviour, name: str, k: float, path: str) -> list[Edit]:
    """Every statement that sets ``name`` in a sequence, its value times ``k``."""
    d = descriptor_of(name)
    return [_edit(text, node, name, getattr(node, d.ir_field) * k / d.scale, path)
            for node in _sources(b, name)]


def _same(name: str, old: float, new: float) -> bool:
    d = descriptor_of(name)
    if d.is_count:
        return int(old) == int(round(new))
    return f"{old * d.scale:.6g}" == f"{new * d.scale:.6g}"


def _edit(text: str, node: Any, name: str, value: float, path: str) -> Edit:
    """The rewrite of the token of ``node`` (its statement) that sets ``name``."""
    d = descriptor_of(name)
    new_value = int(round(value)) if d.is_count else value * d.scale
    if d.is_count and new_value < 0:
        raise AouError(diag(I504, f"{name} is a count: 0 or more, found {new_value}",
                            node.span))
    printed = KINDS[d.kind].format(node.replace(**{d.ir_field: new_value}))
    fresh = _statement(parse(printed + "\n", path), Span(path, 1, 1, 1, 1))
    st = _statement(parse(text, path), node.span)
    printed_token = _token(fresh, d.ir_field)
    new = (f"x{new_value}" if printed_token is None  # the printer leaves out `x1`
           else printed[printed_token.span.col - 1:printed_token.span.end_col - 1])
    token = _token(st, d.ir_field)
    if token is not None:
        return Edit(_offset(text, token.span, False), _offset(text, token.span, True), new)
    where = _offset(text, _insert_at(st, d.ir_field), True)
    return Edit(where, where, " " + new)


def _statement(tree, at: Span) -> Statement:
    """The statement that starts where ``at`` starts (a line may hold several)."""
    for item in tree.items:
        for st in getattr(item, "statements", (item,)):
            if (st.span.line, st.span.col) == (at.line, at.col):
                return st
    raise LookupError(f"no statement at {at.line}:{at.col}")  # the IR's spans are this parse's


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
    """The offset in ``text`` of ``span``'s start (or end). Lines are counted as the
    parser counts them, at ``\n`` only: a form feed, a vertical tab or U+2028 in a
    comment is within its line (``str.splitlines`` would count a line there, and an
    edit would land on the statement before)."""
    line, col = (span.end_line, span.end_col) if end else (span.line, span.col)
    start = 0
    for _ in range(line - 1):
        start = text.index("\n", start) + 1
    return start + col - 1


def _splice(text: str, edits: list[Edit]) -> str:
    for e in sorted(edits, key=lambda e: e.start, reverse=True):
        text = text[:e.start] + e.new + text[e.end:]
    return text
