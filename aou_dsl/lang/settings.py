"""The settings of a file: ``robot``, ``goal``, ``from``, ``start``, ``standoff``,
``effort``; each at most once, each checked on its own."""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from typing import Any

from ..core.diagnostics import Span
from ..core.robot_specs import ROBOT_FILE_TYPES, ROBOTS
from ..core.units import Dim
from .ir import DEFAULTS, Effort, Settings
from .parse import Quantity, Statement, Vector, Word
from .values import Args, Ctx, did_you_mean, positive, si, split_args

__all__ = ["MAX_GOAL_DISTANCE", "SETTINGS", "read_settings"]

#: Furthest the goal may be from the robot's base [m].
MAX_GOAL_DISTANCE = 3.0
SETTINGS = ("robot", "goal", "from", "start", "standoff", "effort")


def _robot(ctx: Ctx, st: Statement, args: Args) -> Any:
    """A built-in arm's name, or a quoted path to a robot file (a URDF or a robot
    description), relative to this file's folder. The file must exist; its content is
    read when the behaviour compiles."""
    pos = args.positional
    if len(pos) != 1 or not isinstance(pos[0], Word):
        ctx.error("V113", '`robot` takes one name, e.g. `robot panda`, or a quoted path, '
                  'e.g. `robot "my_arm.urdf"`', st.keyword_span)
        return None
    word = pos[0]
    if word.quoted:
        return _robot_file(ctx, word)
    if word.text not in ROBOTS:
        ctx.error("V109", f"unknown robot `{word.text}`: expected one of "
                  f"{', '.join(ROBOTS)}, or a quoted path to a robot file",
                  word.span, hint=did_you_mean(word.text, ROBOTS), found=word.text,
                  valid=list(ROBOTS))
        return None
    return word.text


def _robot_file(ctx: Ctx, word: Word) -> str | None:
    """The quoted path joined to the file's folder (as given when absolute)."""
    text = word.text
    if not text.lower().endswith(ROBOT_FILE_TYPES):
        ctx.error("V109", f"robot file `{text}` is neither a URDF nor a robot description",
                  word.span, hint=f"a robot file ends in {' or '.join(ROBOT_FILE_TYPES)}",
                  found=text)
        return None
    folder = os.path.dirname(ctx.path) if not ctx.path.startswith("<") else ""
    path = text if os.path.isabs(text) else os.path.normpath(os.path.join(folder, text))
    if not os.path.isfile(path):
        ctx.error("V109", f"robot file `{text}` not found (looked for `{path}`)", word.span,
                  hint="a relative path starts from the folder of the .aou file",
                  found=text)
        return None
    return path


def _vector(ctx: Ctx, st: Statement, args: Args) -> tuple[Vector, list[float]] | None:
    pos = args.positional
    if len(pos) != 1 or not isinstance(pos[0], Vector):
        ctx.error("V113", f"`{st.keyword}` takes a vector, e.g. `{st.keyword} (0.5, 0, 0.3)`",
                  st.keyword_span)
        return None
    return pos[0], []


def _goal(ctx: Ctx, st: Statement, args: Args) -> Any:
    got = _vector(ctx, st, args)
    if got is None:
        return None
    vec, comps = got
    for q in vec.items:
        value = si(ctx, q, Dim.LENGTH, what="a goal coordinate", bare_unit="m")
        if value is None:
            return None
        comps.append(value)
    norm = math.sqrt(sum(c * c for c in comps))
    if norm > MAX_GOAL_DISTANCE:
        ctx.error("V122", f"the goal is {norm:.3g} m from the robot's base; at most "
                  f"{MAX_GOAL_DISTANCE:g} m", vec.span)
        return None
    return tuple(comps)


def _direction(ctx: Ctx, st: Statement, args: Args) -> Any:
    got = _vector(ctx, st, args)
    if got is None:
        return None
    vec, comps = got
    for q in vec.items:
        if q.unit:
            ctx.error("V102", f"`from` is a direction and takes plain numbers, found "
                      f"`{q.text}`", q.span)
            return None
        comps.append(q.value)
    norm = math.sqrt(sum(c * c for c in comps))
    if not math.isfinite(norm) or norm == 0:
        ctx.error("V105", "`from` must be a finite, non-zero vector", vec.span)
        return None
    return tuple(c / norm for c in comps)


def _distance(ctx: Ctx, st: Statement, args: Args) -> Any:
    pos = args.positional
    if len(pos) != 1 or not isinstance(pos[0], Quantity):
        ctx.error("V113", f"`{st.keyword}` takes a distance, e.g. `{st.keyword} 0.30m`",
                  st.keyword_span)
        return None
    what = f"the {st.keyword} distance"
    return positive(ctx, si(ctx, pos[0], Dim.LENGTH, what=what, bare_unit=None), pos[0], what)


def _effort(ctx: Ctx, st: Statement, args: Args) -> Any:
    factors: dict[str, float] = {}
    for k in "WTSF":
        kv = args.keys.get(k)
        if kv is None:
            ctx.error("V113", f"`effort` needs all of W= T= S= F=; `{k}=` is missing",
                      st.keyword_span)
        elif not isinstance(kv.value, Quantity) or kv.value.unit:
            ctx.error("V113", f"`{k}=` takes a plain number in [-1, 1]", kv.value.span)
        elif not -1.0 <= kv.value.value <= 1.0:
            ctx.error("V106", f"effort {k} must lie in [-1, 1], found {kv.value.text}",
                      kv.value.span, factor=k, found=kv.value.value)
        else:
            factors[k] = kv.value.value
    for a in args.positional:
        ctx.error("V113", "`effort` takes only W= T= S= F=", a.span)
    if len(factors) != 4:
        return None
    return Effort(span=st.span, W=factors["W"], T=factors["T"], S=factors["S"], F=factors["F"])


#: setting keyword -> (IR field, reader, the keys it takes)
_READERS: dict[str, tuple[str, Callable[[Ctx, Statement, Args], Any], str]] = {
    "robot": ("robot", _robot, ""),
    "goal": ("goal", _goal, ""),
    "from": ("start_direction", _direction, ""),
    "start": ("start", _distance, ""),
    "standoff": ("standoff", _distance, ""),
    "effort": ("effort", _effort, "WTSF"),
}


def read_settings(ctx: Ctx, stmts: list[Statement]) -> Settings:
    """The file's settings with defaults filled in; diagnostics for what does not fit."""
    values: dict[str, Any] = {}
    spans: dict[str, Span] = {}
    for st in stmts:
        key, reader, keys = _READERS[st.keyword]
        if key in spans:
            ctx.error("V111", f"`{st.keyword}` is set twice (first at {spans[key]})",
                      st.keyword_span)
            continue
        spans[key] = st.span
        n_before = len(ctx.diags)
        value = reader(ctx, st, split_args(ctx, st, keys, repeat=False))
        if value is not None and len(ctx.diags) == n_before:
            values[key] = value
    start = values.get("start", DEFAULTS["start"])
    standoff = values.get("standoff", DEFAULTS["standoff"])
    if ("start" in values or "standoff" in values) and start <= standoff:
        where = spans.get("start") or spans["standoff"]
        ctx.error("V117", f"the start distance ({start:g} m) must be larger than the "
                  f"standoff ({standoff:g} m)", where, start=start, standoff=standoff)
    return Settings(**values, spans=spans)
