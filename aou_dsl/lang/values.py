"""Reading a statement's arguments: quantities in SI units with checked dimensions.

:class:`Reader` is what a primitive kind's ``read`` works with: it hands out the
positional arguments, the ``key=`` values (a bare value takes the key's unit) and the
``xN`` count, and records a diagnostic for anything that does not fit.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..core.codes import V102, V103, V104, V105, V110, V111, V112, V113, V116, V118, V123, V130
from ..core.diagnostics import Diagnostic, Fix, Span, diag
from ..core.units import RANGE, UNITS, Dim, as_unit, suggest_unit, units_for
from .parse import Colon, KeyVal, Quantity, Statement, Vector, Word

__all__ = ["Ctx", "Reader", "did_you_mean", "fix_word", "robot_hint", "si", "split_args"]

_REPEAT = re.compile(r"^x(\d+)$")
#: What looks like a repeat count but is not a whole number >= 0: `x-1`, `x2b`, and
#: `x1.5`, `x+2` (read as the word `x1` or `x` with the number `.5` or `+2` glued on).
_COUNTLIKE = re.compile(r"^x[-+]?\d")


def _a(noun: str) -> str:
    """The noun with its article: `a length`, `an angle`, `an acceleration`."""
    return f"{'an' if str(noun)[:1] in ('a', 'e', 'i', 'o', 'u') else 'a'} {noun}"


def did_you_mean(word: str, choices: Iterable[str]) -> str | None:
    import difflib  # only for a misspelt word

    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return f"did you mean `{close[0]}`?" if close else None


def fix_word(span: Span, word: str, choices: Iterable[str]) -> Fix | None:
    """:func:`did_you_mean` as an edit of the word at ``span``."""
    import difflib

    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return Fix(span, close[0]) if close else None


#: Other names people give the built-in arms (the maker, the arm's other models).
_ROBOT_NAMES = {"franka": "panda", "fr3": "panda", "franka_panda": "panda", "emika": "panda",
                "ur5e": "ur5", "ur3e": "ur3", "ur10e": "ur10", "universal_robots": "ur5",
                "xarm": "xarm7", "ufactory": "xarm7", "gen3": "kinova", "jaco": "kinova",
                "unitree": "z1"}


def robot_hint(name: str, choices: Iterable[str]) -> str | None:
    """"did you mean" for an unknown robot: by another name of a built-in arm (`franka`
    is the Panda), else by spelling."""
    meant = _ROBOT_NAMES.get(name.lower().replace("-", "_"))
    if meant is not None and meant in choices:
        return f"did you mean `{meant}`? aou calls that arm `{meant}`"
    return did_you_mean(name, choices)


@dataclass
class Ctx:
    """The diagnostics of one file, collected in one pass."""

    path: str
    diags: list[Diagnostic] = field(default_factory=list)

    def error(self, code: str, message: str, span: Span, hint: str | None = None,
              **fields: Any) -> None:
        self.diags.append(diag(code, message, span, hint=hint, **fields))

    #: The severity comes from the rule: ``report`` reads better for notes and warnings.
    report = error

    def has_errors(self) -> bool:
        return any(d.severity == "error" for d in self.diags)


def si(ctx: Ctx, q: Quantity, dim: Dim, *, what: str, bare_unit: str | None) -> float | None:
    """The SI value of ``q`` checked against ``dim``; None (and a diagnostic) when wrong.
    A bare number takes ``bare_unit``; with ``bare_unit`` None a unit is required."""
    fits = ", ".join(units_for(dim))
    if q.unit == "":
        if bare_unit is None:
            ctx.error(V103, f"{what} `{q.text}` needs a unit: expected {_a(dim)} ({fits})",
                      q.span, hint=f"write e.g. `{q.text}{units_for(dim)[0]}`",
                      expected=str(dim), found=q.text)
            return None
        return in_range(ctx, q, q.value * UNITS[bare_unit][1], dim, bare_unit, what)
    if q.unit not in UNITS:
        meant = suggest_unit(q.unit, dim)
        ctx.error(V104, f"unknown unit `{q.unit}` in `{q.text}`: expected {_a(dim)} ({fits})",
                  q.span, hint=f"did you mean `{q.text[:-len(q.unit)]}{meant}`?" if meant
                  else None, found=q.unit,
                  fix=Fix(q.span, f"{q.text[:-len(q.unit)]}{meant}") if meant else None)
        return None
    found_dim, factor = UNITS[q.unit]
    if found_dim is not dim:
        ctx.error(V102, f"{what}: expected {_a(dim)} ({fits}), found {_a(found_dim)} "
                  f"`{q.text}`",
                  q.span, expected=str(dim), found=str(found_dim))
        return None
    return in_range(ctx, q, q.value * factor, dim, q.unit, what)


def in_range(ctx: Ctx, q: Quantity, value: float, dim: Dim, unit: str, what: str
             ) -> float | None:
    """``value`` [SI] when it is finite and its magnitude is zero or within the
    language's :data:`~aou_dsl.core.units.RANGE` for ``dim``; else None and V105 or V130
    (the bounds shown in ``unit``, the unit written)."""
    if not math.isfinite(value):
        ctx.error(V105, f"{what} must be a finite number, found `{q.text}`", q.span)
        return None
    least, most = RANGE[dim]
    if value == 0 or least <= abs(value) <= most:
        return value
    factor = UNITS[unit][1]
    span = f"up to {most / factor:.6g} {unit}" if least == 0 else \
        f"from {least / factor:.6g} {unit} to {most / factor:.6g} {unit}"
    ctx.error(V130, f"{what} `{q.text}` is out of range: the language takes {_a(dim)} "
              f"{span}", q.span, hint=f"write a value {span}", found=q.text, least=least,
              greatest=most, unit=unit)
    return None


def positive(ctx: Ctx, value: float | None, q: Quantity, what: str) -> float | None:
    if value is not None and not value > 0:
        ctx.error(V105, f"{what} must be positive, found `{q.text}`", q.span, found=q.text)
        return None
    return value


@dataclass
class Args:
    """A statement's arguments sorted by shape."""

    positional: list[Quantity | Word | Vector | Colon] = field(default_factory=list)
    keys: dict[str, KeyVal] = field(default_factory=dict)
    count: int | None = None
    for_: Quantity | None = None


def split_args(ctx: Ctx, st: Statement, allowed: Iterable[str], repeat: bool,
               takes_for: bool = False) -> Args:
    """Sort ``st``'s arguments; unknown or repeated keys and counts are diagnostics.
    ``takes_for``: the statement's kind takes a duration as ``for DURATION`` (a shiver's
    oscillation)."""
    allowed = list(allowed)
    out = Args()
    args = list(st.args)
    i = 0
    while i < len(args):
        a = args[i]
        bad = _malformed_count(args, i) if repeat and isinstance(a, Word) else None
        if bad is not None:
            _bad_count(ctx, *bad)
            i += bad[2]
        elif isinstance(a, Word) and repeat and _REPEAT.match(a.text):
            if out.count is not None:
                ctx.error(V116, f"`{st.keyword}` has two repeat counts", a.span)
            if len(a.text) > 10:  # past Python's int-string limit and any bound
                ctx.error(V110, f"a repeat count of {len(a.text) - 1} digits; at most "
                          "1000 episodes are allowed", a.span, found=a.text[:12] + "...")
            else:
                out.count = int(a.text[1:])
        elif isinstance(a, Word) and a.text == "for" and takes_for:
            nxt = args[i + 1] if i + 1 < len(args) else None
            if not isinstance(nxt, Quantity):
                ctx.error(V113, "`for` must be followed by a duration, e.g. `for 1s`",
                          a.span)
            elif out.for_ is not None:  # the second would silently win
                ctx.error(V111, "`for` is given twice: a shiver has one duration",
                          a.span.to(nxt.span), hint=f"keep one of `for {out.for_.text}` "
                          f"and `for {nxt.text}`", found=nxt.text)
                i += 1
            else:
                out.for_ = nxt
                i += 1
        elif isinstance(a, KeyVal):
            _key(ctx, st, a, allowed, out, takes_for)
        else:
            out.positional.append(a)
        i += 1
    return out


def _glued(a: object, b: object) -> bool:
    """``b`` is written right after ``a``, with no space between them."""
    sa, sb = getattr(a, "span", None), getattr(b, "span", None)
    return sa is not None and sb is not None and (sa.end_line, sa.end_col) == \
        (sb.line, sb.col)


def _malformed_count(args: list, i: int) -> tuple[str, Span, int] | None:
    """A repeat count that is not a whole number >= 0 starting at ``args[i]`` (a word):
    its text as written, its span and how many arguments after ``args[i]`` it takes."""
    a = args[i]
    nxt = args[i + 1] if i + 1 < len(args) else None
    if not isinstance(nxt, Quantity):
        nxt = None
    glued = nxt is not None and _glued(a, nxt)
    if a.text == "x" and nxt is not None and nxt.unit == "" and \
            (glued or not nxt.text.isdigit()):
        gap = "" if glued else " "
        return f"{a.text}{gap}{nxt.text}", a.span.to(nxt.span), 1  # `x+2`, `x.5`, `x -1`
    if not _COUNTLIKE.match(a.text):
        return None
    if nxt is not None and glued:
        return f"{a.text}{nxt.text}", a.span.to(nxt.span), 1  # `x1.5`, `x-1.5`
    return None if _REPEAT.match(a.text) else (a.text, a.span, 0)  # `x-1`, `x2b`


def _bad_count(ctx: Ctx, text: str, span: Span, _: int) -> None:
    try:
        n = float(text[1:].strip())
    except ValueError:
        n = math.nan
    if n < 0:
        hint = "a count cannot be negative; `x0` leaves the statement out"
    elif math.isfinite(n) and n != int(n):
        hint = f"write `x{math.floor(n)}` or `x{math.ceil(n)}`" if n > 1 else "write `x1`"
    elif math.isfinite(n):
        hint = f"write `x{int(n)}`"
    else:
        hint = "write e.g. `x2`"
    fix = Fix(span, f"x{int(n)}") if math.isfinite(n) and n == int(n) and n >= 0 else None
    ctx.error(V116, f"a repeat count is a whole number of episodes, 0 or more: found "
              f"`{text}`", span, hint=hint, found=text, fix=fix)


def _key(ctx: Ctx, st: Statement, a: KeyVal, allowed: list[str], out: Args,
         takes_for: bool) -> None:
    if a.key not in allowed:
        keys = ", ".join(f"{k}=" for k in allowed) or "no keys"
        hint = did_you_mean(a.key, allowed)
        at = a.span
        fix = fix_word(Span(at.path, at.line, at.col, at.line, at.col + len(a.key)), a.key,
                       allowed)
        if a.key == "for" and takes_for:  # `for` is a word, not a key
            keys += " and `for DURATION`"
            hint = f"write `for {a.value.text}`, with a space, not `=`"
            fix = Fix(a.span, f"for {a.value.text}")
        ctx.error(V112, f"`{st.keyword}` takes {keys}; found `{a.key}=`", a.span,
                  hint=hint, found=a.key, fix=fix)
    elif a.key in out.keys:
        ctx.error(V111, f"`{a.key}=` is given twice", a.span)
    else:
        out.keys[a.key] = a


class Reader:
    """Reads one primitive statement's arguments, reporting what does not fit.

    Attributes:
        st: the statement; ``in_sequence``: inside a ``sequence { }`` block;
        count: its ``xN`` (1 when absent); ``args``: its arguments by shape.
    """

    def __init__(self, ctx: Ctx, st: Statement, kind: Any, in_sequence: bool,
                 takes_for: bool = False):
        self.ctx, self.st, self.kind, self.in_sequence = ctx, st, kind, in_sequence
        self.n_before = len(ctx.diags)
        keys: Mapping = kind.keys
        self.args = split_args(ctx, st, keys, repeat=True, takes_for=takes_for)
        self.pos = self.args.positional
        self.count = 1 if self.args.count is None else self.args.count
        self._index: dict[int, int] | None = None

    def _where(self, a: object, missing: int) -> int:
        """The place of ``a`` among the statement's arguments (``missing`` when it is not
        one): looked up, not searched, so a statement of many arguments reads in linear
        time."""
        if self._index is None:
            self._index = {id(b): k for k, b in enumerate(self.st.args)}
        return self._index.get(id(a), missing)

    def error(self, code: str, message: str, span: Span, hint: str | None = None,
              fix: Fix | None = None) -> None:
        self.ctx.error(code, message, span, hint, fix=fix)

    def _usage_error(self, what: str, first: object) -> None:
        found = f", found `{first.text}`" if isinstance(first, Quantity | Word) else ""
        span = first.span if isinstance(first, Quantity | Word | Vector | Colon) \
            else self.st.keyword_span
        self.error(V113, f"`{self.st.keyword}` needs {what}{found}; usage: "
                   f"{self.kind.usage}", span)

    def quantity(self, what: str) -> Quantity | None:
        """The next positional argument, which must be a quantity."""
        first = self.pos[0] if self.pos else None
        if not isinstance(first, Quantity):
            self._usage_error(what, first)
            return None
        self.pos.pop(0)
        return first

    def optional_quantity(self) -> Quantity | None:
        first = self.pos[0] if self.pos else None
        if isinstance(first, Quantity):
            self.pos.pop(0)
            return first
        return None

    def word(self, choices: tuple[str, ...], message: str) -> Any:
        """The next positional argument, which must be one of ``choices``."""
        first = self.pos[0] if self.pos else None
        if isinstance(first, Word) and first.text in choices:
            self.pos.pop(0)
            return first.text
        found = f", found `{first.text}`" if isinstance(first, Word | Quantity) else ""
        self.error(V113, f"{message}{found}",
                   first.span if isinstance(first, Word | Quantity) else self.st.keyword_span,
                   hint=did_you_mean(first.text, choices) if isinstance(first, Word) else None)
        if isinstance(first, Word):
            self.pos.pop(0)
        return None

    def _after(self, a: object) -> object | None:
        """The argument written after ``a`` in the statement."""
        args = self.st.args
        i = self._where(a, len(args))
        return args[i + 1] if i + 1 < len(args) else None

    def si(self, q: Quantity | None, dim: Dim, what: str) -> float | None:
        if q is None:
            return None
        unit = self._after(q) if q.unit == "" else None
        if isinstance(unit, Word) and as_unit(unit.text) and unit in self.pos:
            self.pos.remove(unit)  # `1.25 s`: one slip, one diagnostic
            self.error(V103, f"{what} `{q.text}` needs a unit glued to it: found "
                       f"`{q.text} {unit.text}`", q.span.to(unit.span),
                       hint=f"write `{q.text}{as_unit(unit.text)}`, without a space",
                       fix=Fix(q.span.to(unit.span), f"{q.text}{as_unit(unit.text)}"))
            return None
        return si(self.ctx, q, dim, what=what, bare_unit=None)

    def positive(self, q: Quantity | None, value: float | None, what: str) -> float | None:
        return None if q is None else positive(self.ctx, value, q, what)

    def key(self, name: str) -> float | None:
        """The value of ``name=`` in SI units (a bare number takes the key's unit), or
        None when absent or wrong."""
        kv = self.args.keys.get(name)
        spec = self.kind.keys[name]
        if kv is None:
            return None
        if not isinstance(kv.value, Quantity):
            self.error(V113, f"`{kv.key}=` takes a {spec.dim}, found `{kv.value.text}`",
                       kv.value.span)
            return None
        value = si(self.ctx, kv.value, spec.dim, what=f"`{kv.key}=` ({spec.what})",
                   bare_unit=spec.bare_unit)
        return positive(self.ctx, value, kv.value, spec.what)

    def amplitude(self, q: Quantity | None, value: float | None, what: str) -> float | None:
        """In the descriptor form, angles are amplitudes: positive."""
        if q is not None and value is not None and not self.in_sequence and value <= 0:
            self.error(V118, f"{what} in the descriptor form is an amplitude and must "
                       f"be positive, found `{q.text}`", q.span,
                       hint="signed angles (directions) belong in a `sequence { }` block")
            return None
        return value

    def visible(self, q: Quantity | None, value: float | None, least: float, what: str,
                unit: str) -> None:
        """Values under ``least`` (SI) cannot be seen or measured (V123)."""
        if q is not None and value is not None and 0 < abs(value) < least:
            shown = f"{math.degrees(least):g} deg" if unit == "deg" else f"{least * 1e3:g} mm"
            self.error(V123, f"{what} `{q.text}` is too small to be seen or measured; "
                       f"at least {shown}", q.span)

    def done(self) -> bool:
        """Report arguments left over; True when this statement added no diagnostic."""
        skip: set[int] = set()
        for a in self.pos:
            if id(a) in skip:
                continue
            text = getattr(a, "text", None) or ":"
            hint = self._slip(a)
            if hint and "repeat count" in hint:  # `x 3`: one slip, one diagnostic
                skip.add(id(self._after(a)))
            self.error(V113, f"unexpected argument `{text}` to `{self.st.keyword}`; "
                       f"usage: {self.kind.usage}", a.span, hint=hint, fix=self._slip_fix(a))
        return len(self.ctx.diags) == self.n_before

    def _slip_fix(self, a: object) -> Fix | None:
        """:meth:`_slip`'s hint as an edit of the two arguments it joins."""
        m = re.match(r"write (the repeat count as )?`([^`]*)`, without a space",
                     self._slip(a) or "")
        if m is None:
            return None
        args = self.st.args
        i = self._where(a, 0)
        first, last = (a, self._after(a)) if m.group(1) else (args[i - 1] if i else None, a)
        if first is None or last is None:
            return None
        return Fix(first.span.to(last.span), m.group(2))  # type: ignore[attr-defined]

    def _slip(self, a: object) -> str | None:
        """What a left-over argument most likely meant: a unit written apart from its
        number (`f=3 Hz`), a repeat count apart from its x (`x 3`)."""
        args = self.st.args
        i = self._where(a, 0)
        before, after = args[i - 1] if i else None, self._after(a)
        key = f"{before.key}=" if isinstance(before, KeyVal) else ""
        if isinstance(before, KeyVal):
            before = before.value
        if isinstance(a, Word) and as_unit(a.text) and isinstance(before, Quantity) \
                and before.unit == "":
            return f"write `{key}{before.text}{as_unit(a.text)}`, without a space"
        if isinstance(a, Word) and a.text == "x" and isinstance(after, Quantity) \
                and after.unit == "":
            return f"write the repeat count as `x{after.text}`, without a space"
        return None
