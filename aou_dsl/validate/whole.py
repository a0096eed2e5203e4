"""Checks of a whole behaviour: resource bounds, how far it goes, and whether its layout
can show what it declares."""

from __future__ import annotations

import math
from typing import Any

from ..declared import source_of, written
from ..descriptors import compare, derive
from ..ir import Behaviour
from ..layout import episode_values, layout
from ..primitives import MIN_RETREAT
from ..timeline import Timeline
from .reader import Ctx

__all__ = ["MAX_EPISODES", "MAX_MOTION_TIME", "MAX_REACH_DISTANCE", "check_whole"]

#: Resource bounds: a file asking for more is an error, not a hang.
MAX_MOTION_TIME = 600.0  # s
MAX_EPISODES = 1000
#: Furthest the end-effector may be sent from the goal [m].
MAX_REACH_DISTANCE = 1.0


def _episodes(ctx: Ctx, b: Behaviour) -> bool:
    n = sum(p.count for p in b.primitives)
    if n > MAX_EPISODES:
        big = max(b.primitives, key=lambda p: p.count)
        ctx.error("V110", f"the behaviour has {n} episodes; at most {MAX_EPISODES} are allowed",
                  big.span, found=n, limit=MAX_EPISODES)
        return False
    return True


def _time(ctx: Ctx, b: Behaviour, tl: Timeline) -> bool:
    t = tl.planned_duration
    if t > MAX_MOTION_TIME:
        big = max(tl.episodes, key=lambda e: e.duration)
        ctx.error("V110", f"the behaviour asks for about {t:.0f} s of motion; at most "
                  f"{MAX_MOTION_TIME:.0f} s are allowed", big.span, found=t,
                  limit=MAX_MOTION_TIME)
        return False
    return True


def _standoff(ctx: Ctx, b: Behaviour) -> bool:
    """A sequence's moves toward the goal stop at the standoff (V120)."""
    s = b.settings
    dist = s.start
    for node in b.primitives:
        p: Any = node
        if p.kind not in ("approach", "retreat"):
            continue
        for _ in range(p.count):
            if p.kind == "approach" and p.length is None:
                dist = s.standoff
                continue
            new = dist - p.length if p.kind == "approach" else dist + p.length
            if new < s.standoff - 1e-9:
                left = max(dist - s.standoff, 0.0)
                ctx.error("V120", f"this {p.kind} would end {s.standoff - new:.3g} m inside "
                          f"the standoff ({s.standoff:g} m from the goal); {left:.3g} m are "
                          "left", p.span, left=left)
                return False
            dist = new
    return True


def _reach(ctx: Ctx, b: Behaviour, tl: Timeline) -> None:
    """V119: no pose of the timeline, its start included, lies further than
    :data:`MAX_REACH_DISTANCE` from the goal."""
    far = max(((max(e.start.d, e.end.d), e) for e in tl.episodes), key=lambda x: x[0],
              default=None)
    if far is not None and far[0] > MAX_REACH_DISTANCE + 1e-9:
        where = b.settings.spans.get("start") if far[1] is tl.episodes[0] and \
            far[1].start.d >= far[1].end.d else None
        ctx.error("V119", f"the end-effector would be {far[0]:.3g} m from the goal; at most "
                  f"{MAX_REACH_DISTANCE:g} m", where or far[1].span, distance=far[0])


def _swept(ctx: Ctx, tl: Timeline) -> None:
    """V123: a gaze moves the end-effector around the goal; an arc shorter than the
    smallest visible motion cannot be seen, whatever its angle."""
    for e in tl.episodes:
        if e.kind != "gaze":
            continue
        turn = math.hypot(e.end.h - e.start.h, e.end.v - e.start.v)
        arc = 2.0 * e.start.d * math.sin(turn / 2.0)
        if 0.0 < arc < MIN_RETREAT:
            ctx.error("V123", f"this gaze of {math.degrees(turn):.3g} deg at "
                      f"{e.start.d:.3g} m from the goal moves the end-effector "
                      f"{arc * 1e3:.2g} mm; at least {MIN_RETREAT * 1e3:g} mm can be seen",
                      e.span, hint="a larger angle, or gaze from further away",
                      swept=arc, least=MIN_RETREAT)
            return


def _touching(ctx: Ctx, tl: Timeline) -> None:
    """V125: two pauses in a row are one hold."""
    for a, b in zip(tl.episodes, tl.episodes[1:], strict=False):
        if a.kind == b.kind == "pause":
            ctx.report("V125", f"this pause follows another with no motion between them: "
                       f"they are seen and measured as one hold of "
                       f"{a.duration + b.duration:.3g} s", b.span,
                       hint="put a motion between them, or write one longer pause")


def _realisable(ctx: Ctx, b: Behaviour, tl: Timeline) -> None:
    """V121: the laid-out descriptor form must show the values the file writes."""
    for m in compare(written(b), derive(episode_values(tl.episodes))):
        node = source_of(b, m.name)
        ctx.error("V121", f"{m.name} is declared {m.declared} but no layout of this file "
                  f"can show more than {m.measured}", node.span if node else b.span,
                  hint="pauses need motion between them (an approach, a retreat, a gaze...); "
                  "a retreat needs a pause before and after it, a gaze one after it",
                  descriptor=m.name, declared=m.declared, realised=m.measured)


def check_whole(ctx: Ctx, b: Behaviour) -> Timeline | None:
    """Check the behaviour as a whole; its timeline, or None when it cannot be laid out."""
    if not _episodes(ctx, b):
        return None
    if b.form == "sequence" and not _standoff(ctx, b):
        return None
    tl = layout(b)
    if not _time(ctx, b, tl):
        return None
    if not tl.episodes:
        ctx.error("V124", "the behaviour has nothing to move or hold: no primitive makes an "
                  "episode", b.span, hint="add a primitive, e.g. `approach` or `pause 1s`")
        return tl
    _reach(ctx, b, tl)
    _swept(ctx, tl)
    _touching(ctx, tl)
    if b.form == "descriptor":
        _realisable(ctx, b, tl)
    return tl
