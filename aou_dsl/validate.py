"""Stage 2, validate: syntax tree -> :class:`~aou_dsl.ir.Behaviour`, with diagnostics.

The validator reports every problem it can find in one pass (not just the first),
each with the span of the offending token. It returns ``None`` for the behaviour when
any error was found.
"""

from __future__ import annotations

import difflib
import math
import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Literal

from .diagnostics import Diagnostic, Span, diag
from .ir import (
    DEFAULTS,
    Approach,
    Behaviour,
    Effort,
    Gaze,
    Pause,
    Primitive,
    Retreat,
    Settings,
    Shiver,
    State,
    Tilt,
)
from .parse import Colon, KeyVal, Quantity, SequenceBlock, Statement, SyntaxTree, Vector, Word
from .robots import ROBOTS
from .units import SI_UNIT, UNITS, Dim, units_for

__all__ = [
    "MAX_EPISODES",
    "MAX_MOTION_TIME",
    "MIN_PAUSE",
    "bang_time",
    "estimate_duration",
    "validate",
]

#: Resource bounds: a file asking for more is an error, not a hang.
MAX_MOTION_TIME = 600.0  # s
MAX_EPISODES = 1000
#: Shortest pause [s] that can be told apart from the stop between two episodes.
MIN_PAUSE = 0.2
#: Furthest the end-effector may be sent from the goal [m].
MAX_REACH_DISTANCE = 1.0
#: Furthest the goal may be from the robot's base [m].
MAX_GOAL_DISTANCE = 3.0
#: Smallest angle [rad] and retreat [m] a behaviour may ask for: below, nobody sees it
#: and it cannot be measured (angles to 0.5 deg, distances to 1 mm).
MIN_ANGLE = math.radians(1.0)
MIN_RETREAT = 0.005

PRIMITIVES = ("approach", "pause", "retreat", "gaze", "tilt", "shiver")
SETTINGS = ("robot", "goal", "from", "start", "standoff", "effort")
KEYWORDS = ("behaviour", *SETTINGS, *PRIMITIVES, "sequence")

# Keys each primitive takes, with their dimension.
_KEYS: dict[str, dict[str, Dim]] = {
    "approach": {"a": Dim.ACCEL, "v": Dim.SPEED},
    "pause": {},
    "retreat": {"a": Dim.ACCEL, "v": Dim.SPEED},
    "gaze": {"v": Dim.ANGULAR_SPEED},
    "tilt": {"v": Dim.ANGULAR_SPEED},
    "shiver": {"f": Dim.FREQUENCY},
}

_REPEAT = re.compile(r"^x(\d+)$")


def _did_you_mean(word: str, choices: Iterable[str]) -> str | None:
    close = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return f"did you mean `{close[0]}`?" if close else None


@dataclass
class _Ctx:
    path: str
    diags: list[Diagnostic] = field(default_factory=list)

    def error(self, code: str, message: str, span: Span, hint: str | None = None, **f) -> None:
        self.diags.append(diag(code, message, span, hint=hint, **f))


# --- quantities -------------------------------------------------------------------------


def _si(ctx: _Ctx, q: Quantity, dim: Dim, *, what: str, unit_required: bool) -> float | None:
    """The SI value of ``q`` checked against ``dim``; None (and a diagnostic) when wrong."""
    fits = ", ".join(units_for(dim))
    if q.unit == "":
        if unit_required:
            ctx.error("V103", f"{what} `{q.text}` needs a unit: expected a {dim} ({fits})",
                      q.span, hint=f"write e.g. `{q.text}{units_for(dim)[0]}`",
                      expected=str(dim), found=q.text)
            return None
        return q.value * UNITS[SI_UNIT[dim]][1]
    if q.unit not in UNITS:
        ctx.error("V104", f"unknown unit `{q.unit}` in `{q.text}`: expected a {dim} ({fits})",
                  q.span, hint=_did_you_mean(q.unit, units_for(dim)), found=q.unit)
        return None
    found_dim, factor = UNITS[q.unit]
    if found_dim is not dim:
        ctx.error("V102", f"{what} must be a {dim} ({fits}), found a {found_dim} `{q.text}`",
                  q.span, expected=str(dim), found=str(found_dim))
        return None
    return q.value * factor


def _positive(ctx: _Ctx, value: float | None, q: Quantity, what: str) -> float | None:
    if value is not None and not value > 0:
        ctx.error("V105", f"{what} must be positive, found `{q.text}`", q.span,
                  found=q.text)
        return None
    return value


# --- statements -------------------------------------------------------------------------


@dataclass
class _Args:
    """A statement's arguments sorted by shape."""

    positional: list[Quantity | Word | Vector | Colon] = field(default_factory=list)
    keys: dict[str, KeyVal] = field(default_factory=dict)
    count: int | None = None
    count_span: Span | None = None
    for_: Quantity | None = None


def _split_args(ctx: _Ctx, st: Statement, allowed_keys: dict[str, Dim], repeat: bool) -> _Args:
    out = _Args()
    args = list(st.args)
    i = 0
    while i < len(args):
        a = args[i]
        if isinstance(a, Word) and repeat and _REPEAT.match(a.text):
            if out.count is not None:
                ctx.error("V116", f"`{st.keyword}` has two repeat counts", a.span)
            out.count, out.count_span = int(a.text[1:]), a.span
        elif isinstance(a, Word) and a.text == "for" and st.keyword == "shiver":
            nxt = args[i + 1] if i + 1 < len(args) else None
            if not isinstance(nxt, Quantity):
                ctx.error("V113", "`for` must be followed by a duration, e.g. `for 1s`",
                          a.span)
            else:
                out.for_ = nxt
                i += 1
        elif isinstance(a, KeyVal):
            if a.key not in allowed_keys:
                keys = ", ".join(f"{k}=" for k in allowed_keys) or "no keys"
                ctx.error("V112", f"`{st.keyword}` takes {keys}; found `{a.key}=`", a.span,
                          hint=_did_you_mean(a.key, allowed_keys), found=a.key)
            elif a.key in out.keys:
                ctx.error("V111", f"`{a.key}=` is given twice", a.span)
            else:
                out.keys[a.key] = a
        else:
            out.positional.append(a)
        i += 1
    return out


def _key_value(ctx: _Ctx, kv: KeyVal | None, dim: Dim, what: str) -> float | None:
    if kv is None:
        return None
    if not isinstance(kv.value, Quantity):
        ctx.error("V113", f"`{kv.key}=` takes a {dim}, found `{kv.value.text}`", kv.value.span)
        return None
    return _positive(ctx, _si(ctx, kv.value, dim, what=what, unit_required=False),
                     kv.value, what)


def _too_many(ctx: _Ctx, st: Statement, extra: list, usage: str) -> None:
    for a in extra:
        text = getattr(a, "text", None) or ":"
        ctx.error("V113", f"unexpected argument `{text}` to `{st.keyword}`; usage: {usage}",
                  a.span, found=text)


_USAGE = {
    "approach": "approach [LENGTH] [a=ACC] [v=SPEED]",
    "pause": "pause DURATION [xN]",
    "retreat": "retreat LENGTH [a=ACC] [v=SPEED] [xN]",
    "gaze": "gaze horizontal|vertical ANGLE [v=ANGSPEED] [xN]",
    "tilt": "tilt ANGLE [v=ANGSPEED] [xN]",
    "shiver": "shiver ANGLE [f=FREQ] [for DURATION] [xN]",
}


class _Reader:
    """Reads one primitive statement's arguments, reporting what does not fit."""

    def __init__(self, ctx: _Ctx, st: Statement, in_sequence: bool):
        self.ctx, self.st, self.in_sequence = ctx, st, in_sequence
        self.kind = st.keyword
        self.n_before = len(ctx.diags)
        self.args = _split_args(ctx, st, _KEYS[self.kind], repeat=True)
        self.pos = self.args.positional
        self.count = 1 if self.args.count is None else self.args.count

    def quantity(self, what: str) -> Quantity | None:
        """The next positional argument, which must be a quantity."""
        if not self.pos or not isinstance(self.pos[0], Quantity):
            first = self.pos[0] if self.pos else None
            found = f", found `{first.text}`" if isinstance(first, Quantity | Word) else ""
            self.ctx.error("V113", f"`{self.kind}` needs {what}{found}; usage: "
                           f"{_USAGE[self.kind]}", first.span if first else self.st.keyword_span)
            return None
        q = self.pos.pop(0)
        assert isinstance(q, Quantity)
        return q

    def optional_quantity(self) -> Quantity | None:
        if self.pos and isinstance(self.pos[0], Quantity):
            q = self.pos.pop(0)
            assert isinstance(q, Quantity)
            return q
        return None

    def si(self, q: Quantity | None, dim: Dim, what: str) -> float | None:
        return None if q is None else _si(self.ctx, q, dim, what=what, unit_required=True)

    def positive(self, q: Quantity | None, value: float | None, what: str) -> float | None:
        return None if q is None else _positive(self.ctx, value, q, what)

    def key(self, name: str, what: str) -> float | None:
        dim = _KEYS[self.kind].get(name)
        if dim is None:
            return None
        return _key_value(self.ctx, self.args.keys.get(name), dim, what)

    def amplitude(self, q: Quantity | None, value: float | None, what: str) -> float | None:
        """In the descriptor form, angles are amplitudes: positive."""
        if q is not None and value is not None and not self.in_sequence and value <= 0:
            self.ctx.error("V118", f"{what} in the descriptor form is an amplitude and must "
                           f"be positive, found `{q.text}`", q.span,
                           hint="signed angles (directions) belong in a `sequence { }` block")
            return None
        return value

    def visible(self, q: Quantity | None, value: float | None, least: float,
                what: str) -> None:
        if q is not None and value is not None and 0 < abs(value) < least:
            shown = f"{math.degrees(least):g} deg" if least < 0.1 else f"{least * 1000:g} mm"
            self.ctx.error("V123", f"{what} `{q.text}` is too small to be seen or measured; "
                           f"at least {shown}", q.span)

    def done(self) -> bool:
        """Report arguments left over; True when this statement added no diagnostic."""
        _too_many(self.ctx, self.st, self.pos, _USAGE[self.kind])
        return len(self.ctx.diags) == self.n_before


def _approach(r: _Reader) -> Approach | None:
    length = None
    q = r.optional_quantity()
    if q is not None:
        length = r.si(q, Dim.LENGTH, "approach length")
        if length is not None and not r.in_sequence:
            r.ctx.error("V113", "an approach length is only allowed in a `sequence { }`; "
                        "in the descriptor form the approach runs from start to standoff",
                        q.span)
        elif length == 0:
            r.ctx.error("V105", "an approach length must not be zero", q.span)
    a, v = r.key("a", "acceleration"), r.key("v", "speed")
    if r.done():
        return Approach(span=r.st.span, length=length, a=a or DEFAULTS["approach_a"],
                        v=v or DEFAULTS["speed_cap"], count=r.count)
    return None


def _pause(r: _Reader) -> Pause | None:
    q = r.quantity("a duration")
    d = r.positive(q, r.si(q, Dim.TIME, "pause duration"), "pause duration")
    if q is not None and d is not None and d < MIN_PAUSE:
        r.ctx.error("V105", f"a pause must last at least {MIN_PAUSE}s to be told apart from "
                    f"the stop between two episodes, found `{q.text}`", q.span)
    if r.done() and d is not None:
        return Pause(span=r.st.span, duration=d, count=r.count)
    return None


def _retreat(r: _Reader) -> Retreat | None:
    q = r.quantity("a distance")
    d = r.si(q, Dim.LENGTH, "retreat distance")
    if q is not None and not r.in_sequence:
        d = r.positive(q, d, "retreat distance")
    elif q is not None and d == 0:
        r.ctx.error("V105", "a retreat distance must not be zero", q.span)
    r.visible(q, d, MIN_RETREAT, "a retreat of")
    a, v = r.key("a", "acceleration"), r.key("v", "speed")
    if r.done() and d is not None:
        return Retreat(span=r.st.span, length=d, a=a or DEFAULTS["retreat_a"],
                       v=v or DEFAULTS["speed_cap"], count=r.count)
    return None


def _gaze(r: _Reader) -> Gaze | None:
    plane: Literal["horizontal", "vertical"] | None = None
    first = r.pos[0] if r.pos else None
    if isinstance(first, Word) and first.text in ("horizontal", "vertical"):
        r.pos.pop(0)
        plane = "horizontal" if first.text == "horizontal" else "vertical"
    else:
        found = f", found `{first.text}`" if isinstance(first, Word | Quantity) else ""
        r.ctx.error("V113", f"`gaze` needs a plane: `horizontal` or `vertical`{found}",
                    first.span if first is not None else r.st.keyword_span,
                    hint=_did_you_mean(first.text, ("horizontal", "vertical"))
                    if isinstance(first, Word) else None)
        if isinstance(first, Word):
            r.pos.pop(0)
    q = r.quantity("an angle")
    angle = r.amplitude(q, r.si(q, Dim.ANGLE, "gaze angle"), "a gaze angle")
    if not r.in_sequence:  # in a sequence, 0deg looks straight again
        r.visible(q, angle, MIN_ANGLE, "a gaze of")
    v = r.key("v", "speed")
    if r.done() and plane is not None and angle is not None:
        return Gaze(span=r.st.span, plane=plane, angle=angle, v=v or DEFAULTS["gaze_v"],
                    count=r.count)
    return None


def _tilt(r: _Reader) -> Tilt | None:
    q = r.quantity("an angle")
    angle = r.amplitude(q, r.si(q, Dim.ANGLE, "tilt angle"), "a tilt angle")
    if q is not None and angle == 0:
        r.ctx.error("V105", "a tilt angle must not be zero", q.span)
    r.visible(q, angle, MIN_ANGLE, "a tilt of")
    v = r.key("v", "speed")
    if r.done() and angle is not None:
        return Tilt(span=r.st.span, angle=angle, v=v or DEFAULTS["tilt_v"], count=r.count)
    return None


def _shiver(r: _Reader) -> Shiver | None:
    q = r.quantity("an amplitude")
    amp = r.positive(q, r.si(q, Dim.ANGLE, "shiver amplitude"), "shiver amplitude")
    r.visible(q, amp, MIN_ANGLE, "a shiver of")
    f = r.key("f", "shiver frequency")
    dur = None
    if r.args.for_ is not None:
        dur = r.positive(r.args.for_, r.si(r.args.for_, Dim.TIME, "shiver duration"),
                         "shiver duration")
    if r.done() and amp is not None:
        return Shiver(span=r.st.span, amplitude=amp, f=f or DEFAULTS["shiver_f"],
                      duration=dur or DEFAULTS["shiver_duration"], count=r.count)
    return None


_BUILDERS: dict[str, Callable[[_Reader], Primitive | None]] = {
    "approach": _approach, "pause": _pause, "retreat": _retreat, "gaze": _gaze,
    "tilt": _tilt, "shiver": _shiver,
}


def _primitive(ctx: _Ctx, st: Statement, in_sequence: bool) -> Primitive | None:
    """A primitive statement as IR, or None (with diagnostics) when it does not fit."""
    return _BUILDERS[st.keyword](_Reader(ctx, st, in_sequence))


def _settings(ctx: _Ctx, stmts: list[Statement]) -> Settings:
    values: dict = {}
    spans: dict[str, Span] = {}
    for st in stmts:
        key = "start_direction" if st.keyword == "from" else st.keyword
        if key in spans:
            ctx.error("V111", f"`{st.keyword}` is set twice (first at {spans[key]})",
                      st.keyword_span)
            continue
        spans[key] = st.span
        n_before = len(ctx.diags)
        args = _split_args(ctx, st, {k: Dim.LENGTH for k in "WTSF"} if key == "effort" else {},
                           repeat=False)
        pos = args.positional
        if key == "robot":
            if len(pos) != 1 or not isinstance(pos[0], Word):
                ctx.error("V113", "`robot` takes one name, e.g. `robot panda`",
                          st.keyword_span)
            elif pos[0].text not in ROBOTS:
                names = ", ".join(ROBOTS)
                ctx.error("V109", f"unknown robot `{pos[0].text}`: expected one of {names}",
                          pos[0].span, hint=_did_you_mean(pos[0].text, ROBOTS),
                          found=pos[0].text, valid=list(ROBOTS))
            else:
                values["robot"] = pos[0].text
        elif key in ("goal", "start_direction"):
            if len(pos) != 1 or not isinstance(pos[0], Vector):
                ctx.error("V113", f"`{st.keyword}` takes a vector, e.g. "
                          f"`{st.keyword} (0.5, 0, 0.3)`", st.keyword_span)
                continue
            vec = []
            for q in pos[0].items:
                if key == "goal":
                    vec.append(_si(ctx, q, Dim.LENGTH, what="a goal coordinate",
                                   unit_required=False))
                elif q.unit:
                    ctx.error("V102", f"`from` is a direction and takes plain numbers, "
                              f"found `{q.text}`", q.span)
                else:
                    vec.append(q.value)
            if len(ctx.diags) != n_before:
                continue
            comps = [c for c in vec if c is not None]
            norm = math.sqrt(sum(c * c for c in comps))
            if key == "goal" and norm > MAX_GOAL_DISTANCE:
                ctx.error("V122", f"the goal is {norm:.3g} m from the robot's base; at most "
                          f"{MAX_GOAL_DISTANCE:g} m", pos[0].span)
                continue
            if key == "start_direction":
                if norm == 0:
                    ctx.error("V105", "`from` must not be the zero vector", pos[0].span)
                    continue
                comps = [c / norm for c in comps]
            values[key] = tuple(comps)
        elif key in ("start", "standoff"):
            if len(pos) != 1 or not isinstance(pos[0], Quantity):
                ctx.error("V113", f"`{key}` takes a distance, e.g. `{key} 0.30m`",
                          st.keyword_span)
                continue
            val = _si(ctx, pos[0], Dim.LENGTH, what=f"the {key} distance", unit_required=True)
            val = _positive(ctx, val, pos[0], f"the {key} distance")
            if val is not None:
                values[key] = val
        elif key == "effort":
            factors: dict[str, float] = {}
            for k in "WTSF":
                kv = args.keys.get(k)
                if kv is None:
                    ctx.error("V113", f"`effort` needs all of W= T= S= F=; `{k}=` is missing",
                              st.keyword_span)
                    continue
                if not isinstance(kv.value, Quantity) or kv.value.unit:
                    ctx.error("V113", f"`{k}=` takes a plain number in [-1, 1]", kv.value.span)
                    continue
                if not -1.0 <= kv.value.value <= 1.0:
                    ctx.error("V106", f"effort {k} must lie in [-1, 1], found {kv.value.text}",
                              kv.value.span, factor=k, found=kv.value.value)
                    continue
                factors[k] = kv.value.value
            for a in pos:
                ctx.error("V113", "`effort` takes only W= T= S= F=", a.span)
            if len(factors) == 4 and len(ctx.diags) == n_before:
                values["effort"] = Effort(span=st.span, **factors)
    if "start" in values or "standoff" in values:
        start = values.get("start", DEFAULTS["start"])
        standoff = values.get("standoff", DEFAULTS["standoff"])
        if start <= standoff:
            where = spans.get("start") or spans["standoff"]
            ctx.error("V117", f"the start distance ({start:g} m) must be larger than the "
                      f"standoff ({standoff:g} m)", where, start=start, standoff=standoff)
    return Settings(**values, spans=spans)


def _header(ctx: _Ctx, st: Statement) -> tuple[str | None, State | None]:
    pos = list(st.args)
    if not pos or not isinstance(pos[0], Word):
        ctx.error("V113", "`behaviour` takes a name, e.g. `behaviour peek : curious`",
                  st.keyword_span)
        return None, None
    name = pos[0].text
    state = None
    rest = pos[1:]
    if rest:
        if not isinstance(rest[0], Colon) or len(rest) != 2 or not isinstance(rest[1], Word):
            ctx.error("V113", "the header is `behaviour NAME : STATE`", rest[0].span)
            return name, None
        sw = rest[1]
        try:
            state = State(sw.text)
        except ValueError:
            ctx.error("V114", f"unknown state `{sw.text}`: expected one of "
                      f"{', '.join(s.value for s in State)}", sw.span,
                      hint=_did_you_mean(sw.text, [s.value for s in State]), found=sw.text)
    return name, state


# --- whole file -------------------------------------------------------------------------


def bang_time(length: float, a: float, vmax: float) -> float:
    """Rest-to-rest time [s] over ``length`` at peak acceleration ``a`` and speed cap
    ``vmax`` (triangular or trapezoidal velocity profile)."""
    length = abs(length)
    if length == 0.0:
        return 0.0
    if length * a <= vmax * vmax:
        return 2.0 * math.sqrt(length / a)
    return length / vmax + vmax / a


def estimate_duration(b: Behaviour) -> float:
    """A quick upper-bound-ish estimate [s] of a behaviour's motion time, for the
    resource bound. The compiler's timeline is exact; this only guards against typos."""
    s = b.settings
    total = 0.0
    reach = s.start - s.standoff
    retreated = 0.0
    approach: Approach | None = None
    for p in b.primitives:
        n = p.count
        if isinstance(p, Pause):
            total += n * p.duration
        elif isinstance(p, Retreat):
            total += n * bang_time(p.length, p.a, p.v)
            retreated += n * abs(p.length)
        elif isinstance(p, Gaze):
            total += n * 2.0 * abs(p.angle) / p.v
        elif isinstance(p, Tilt):
            total += n * abs(p.angle) / p.v
        elif isinstance(p, Shiver):
            total += n * p.duration
        elif isinstance(p, Approach):
            approach = p
            if p.length is not None:
                total += n * bang_time(p.length, p.a, p.v)
    if approach is not None:
        total += bang_time(reach + retreated, approach.a, approach.v)
    return total


def _episode_count(b: Behaviour) -> int:
    return sum(p.count for p in b.primitives)


def _check_whole(ctx: _Ctx, b: Behaviour) -> None:
    n = _episode_count(b)
    if n > MAX_EPISODES:
        big = max(b.primitives, key=lambda p: p.count)
        ctx.error("V110", f"the behaviour has {n} episodes; at most {MAX_EPISODES} are allowed",
                  big.span, found=n, limit=MAX_EPISODES)
        return
    t = estimate_duration(b)
    if t > MAX_MOTION_TIME:
        big = max(b.primitives, key=lambda p: p.count)
        ctx.error("V110", f"the behaviour asks for about {t:.0f} s of motion; at most "
                  f"{MAX_MOTION_TIME:.0f} s are allowed", big.span, found=t,
                  limit=MAX_MOTION_TIME)
    s = b.settings
    if b.form == "descriptor":
        r = b.first("retreat")
        p = b.first("pause")
        n_r = r.count if r else 0
        n_p = p.count if p else 0
        if r is not None and n_r and n_p < n_r + 1:
            ctx.error("V121", f"{n_r} retreat(s) need at least {n_r + 1} pauses (a retreat "
                      f"starts and ends at a pause, MODEL.md s5), found {n_p}", r.span,
                      hint=f"add `pause DURATION x{n_r + 1}`")
        if r and s.start + r.length > MAX_REACH_DISTANCE:
            ctx.error("V119", f"a retreat of {r.length:g} m from the start ({s.start:g} m) "
                      f"ends beyond {MAX_REACH_DISTANCE:g} m from the goal", r.span)
        return
    # Sequence form: follow the distance to the goal statement by statement.
    dist = s.start
    for prim in b.primitives:
        for _ in range(prim.count):
            if isinstance(prim, Approach):
                if prim.length is None:
                    dist = s.standoff
                elif dist - prim.length < s.standoff - 1e-9:
                    ctx.error("V120", f"this approach of {prim.length:g} m would end "
                              f"{s.standoff - (dist - prim.length):.3g} m inside the standoff "
                              f"({s.standoff:g} m from the goal); "
                              f"{max(dist - s.standoff, 0):.3g} m are left", prim.span)
                    return
                else:
                    dist -= prim.length
            elif isinstance(prim, Retreat):
                if dist + prim.length < s.standoff - 1e-9:
                    ctx.error("V120", "this retreat (negative length) would end inside the "
                              "standoff", prim.span)
                    return
                dist += prim.length
                if dist > MAX_REACH_DISTANCE:
                    ctx.error("V119", f"the end-effector would be {dist:.3g} m from the "
                              f"goal; at most {MAX_REACH_DISTANCE:g} m", prim.span)
                    return


def validate(tree: SyntaxTree) -> tuple[Behaviour | None, list[Diagnostic]]:
    """Check a syntax tree and build the IR.

    Returns:
        ``(behaviour, diagnostics)``; ``behaviour`` is None when any error was found.
    """
    ctx = _Ctx(tree.path)
    name: str | None = None
    state: State | None = None
    header_span: Span | None = None
    settings: list[Statement] = []
    descriptor: list[Primitive] = []
    sequence: list[Primitive] = []
    seq_block: SequenceBlock | None = None
    first_prim_span: Span | None = None
    seen_kinds: dict[str, Span] = {}

    for i, item in enumerate(tree.items):
        if isinstance(item, SequenceBlock):
            if seq_block is not None:
                ctx.error("V111", f"a file has one `sequence` block; the first is at "
                          f"{seq_block.span}", item.span)
                continue
            seq_block = item
            for st in item.statements:
                if st.keyword not in PRIMITIVES:
                    ctx.error("V101" if st.keyword not in KEYWORDS else "V113",
                              f"`{st.keyword}` is not a primitive; a sequence holds only "
                              f"{', '.join(PRIMITIVES)}", st.keyword_span,
                              hint=_did_you_mean(st.keyword, PRIMITIVES))
                    continue
                p = _primitive(ctx, st, in_sequence=True)
                if p is not None:
                    sequence.append(p)
            continue
        st = item
        if st.keyword == "behaviour":
            if header_span is not None:
                ctx.error("V111", f"the header is given twice (first at {header_span})",
                          st.keyword_span)
            elif i != 0:
                ctx.error("V115", "the `behaviour` header must be the first statement",
                          st.keyword_span)
            else:
                header_span = st.span
                name, state = _header(ctx, st)
        elif st.keyword in SETTINGS:
            settings.append(st)
        elif st.keyword in PRIMITIVES:
            first_prim_span = first_prim_span or st.span
            p = _primitive(ctx, st, in_sequence=False)
            key = st.keyword
            if p is not None and p.kind == "gaze":
                key = f"gaze {p.plane}"
            if key in seen_kinds:
                ctx.error("V107", f"`{key}` appears twice in the descriptor form (first at "
                          f"{seen_kinds[key]})", st.keyword_span,
                          hint="use `xN` for more episodes, or a `sequence { }` block for "
                               "episodes that differ")
                continue
            seen_kinds[key] = st.span
            if p is not None:
                descriptor.append(p)
        else:
            ctx.error("V101", f"unknown statement `{st.keyword}`", st.keyword_span,
                      hint=_did_you_mean(st.keyword, KEYWORDS) or
                      f"statements are {', '.join(KEYWORDS)}", found=st.keyword)

    if seq_block is not None and first_prim_span is not None:
        ctx.error("V108", "a file has either a `sequence { }` block or descriptor-form "
                  "primitives, not both", first_prim_span,
                  hint=f"the sequence block is at {seq_block.span}")
    sett = _settings(ctx, settings)
    if any(d.severity == "error" for d in ctx.diags):
        return None, ctx.diags
    stem = tree.path.rsplit("/", 1)[-1].removesuffix(".aou") or "behaviour"
    lines = 1
    behaviour = Behaviour(
        name=name or stem,
        state=state,
        form="sequence" if seq_block is not None else "descriptor",
        settings=sett,
        primitives=tuple(sequence if seq_block is not None else descriptor),
        span=Span(tree.path, 1, 1, lines, 1),
        header_span=header_span,
    )
    _check_whole(ctx, behaviour)
    if any(d.severity == "error" for d in ctx.diags):
        return None, ctx.diags
    return behaviour, ctx.diags
