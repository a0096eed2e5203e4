"""Checks of a whole behaviour: resource bounds, how far it goes, and whether its layout
can show what it declares."""

from __future__ import annotations

import math
from typing import Any

from ..core.codes import V110, V119, V120, V121, V123, V124, V125
from .declared import source_of, written
from .descriptors import compare, derive, every_descriptor
from .ir import Behaviour
from .kind_needs import why_not
from .layout import Laid, episode_values, layout
from .primitives import APPROACH, GAZE, KINDS, MIN_RETREAT, PAUSE
from .timeline import Pose, Timeline
from .values import Ctx

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
        ctx.error(V110, f"the behaviour has {n} episodes; at most {MAX_EPISODES} are allowed",
                  big.span, found=n, limit=MAX_EPISODES)
        return False
    return True


def _time(ctx: Ctx, b: Behaviour, tl: Timeline) -> bool:
    t = tl.planned_duration
    if t > MAX_MOTION_TIME:
        big = max(tl.episodes, key=lambda e: e.duration)
        ctx.error(V110, f"the behaviour asks for about {t:.0f} s of motion; at most "
                  f"{MAX_MOTION_TIME:.0f} s are allowed", big.span, found=t,
                  limit=MAX_MOTION_TIME)
        return False
    return True


def _standoff(ctx: Ctx, b: Behaviour) -> bool:
    """A sequence's moves toward the goal stop at the standoff (V120). A move along the
    line of sight of another kind (a retreat, a plugin's draw-back) goes where its kind's
    episode goes."""
    s = b.settings
    dist = s.start
    for node in b.primitives:
        p: Any = node
        if p.kind not in KINDS or not KINDS[p.kind].translation:
            continue
        for _ in range(p.count):
            if p.kind == APPROACH and p.length is None:
                dist = s.standoff
                continue
            new = dist - p.length if p.kind == APPROACH else \
                KINDS[p.kind].episode(p, Pose(dist)).end.d
            if new < s.standoff - 1e-9:
                left = max(dist - s.standoff, 0.0)
                ctx.error(V120, f"this {p.kind} would end {s.standoff - new:.3g} m inside "
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
        ctx.error(V119, f"the end-effector would be {far[0]:.3g} m from the goal; at most "
                  f"{MAX_REACH_DISTANCE:g} m", where or far[1].span, distance=far[0])


def _swept(ctx: Ctx, tl: Timeline) -> None:
    """V123: a gaze moves the end-effector around the goal; an arc shorter than the
    smallest visible motion cannot be seen, whatever its angle."""
    for e in tl.episodes:
        if e.kind != GAZE:
            continue
        turn = math.hypot(e.end.h - e.start.h, e.end.v - e.start.v)
        arc = 2.0 * e.start.d * math.sin(turn / 2.0)
        if 0.0 < arc < MIN_RETREAT:
            ctx.error(V123, f"this gaze of {math.degrees(turn):.3g} deg at "
                      f"{e.start.d:.3g} m from the goal moves the end-effector "
                      f"{arc * 1e3:.2g} mm; at least {MIN_RETREAT * 1e3:g} mm can be seen",
                      e.span, hint="a larger angle, or gaze from further away",
                      swept=arc, least=MIN_RETREAT)
            return


def _short_moves(ctx: Ctx, b: Behaviour, tl: Timeline) -> None:
    """V123: a move along the line of sight shorter than the smallest visible motion. A
    written length is checked where it is read; here, the moves the layout makes: an
    approach without a length (the rest of the way to the standoff) and, in the
    descriptor form, the pieces the approach is split into between the stops."""
    short = [e for e in tl.episodes if KINDS[e.kind].translation
             and 0.0 < e.path_length < MIN_RETREAT - 1e-12]
    if not short:
        return
    e = min(short, key=lambda x: x.path_length)
    mm = f"{e.path_length * 1e3:.2g} mm"
    least_mm = f"{MIN_RETREAT * 1e3:g} mm"
    least = f"at least {least_mm}"
    if b.form == "sequence":
        ctx.error(V123, f"this approach runs the rest of the way to the standoff: "
                  f"{mm}, too little to be seen or measured; {least}", e.span,
                  hint=f"the moves before it end {mm} from the standoff: end them at "
                  f"least {least_mm} from it, or leave this approach out",
                  moved=e.path_length, least=MIN_RETREAT)
        return
    pieces = sum(1 for x in tl.episodes if x.kind == APPROACH)
    ctx.error(V123, f"the layout splits the approach into {pieces} pieces (one to each "
              f"stop, the last to the standoff) and the shortest moves {mm}, too little to "
              f"be seen or measured; {least}", e.span,
              hint=_further_start(b, pieces), moved=e.path_length, least=MIN_RETREAT)


def _further_start(b: Behaviour, pieces: int) -> str:
    """A hint for approach pieces too short: a start far enough for every piece (checked
    on the layout), or fewer stops."""
    s = b.settings
    fewer = "fewer pauses, gazes, tilts or retreats to stop at"
    first = max(s.start + 0.01, s.standoff + MIN_RETREAT * pieces)  # equal shares at best
    for cm in range(math.ceil(first * 100 - 1e-9), round(MAX_REACH_DISTANCE * 100) + 1):
        tl = layout(b.replace(settings=s.replace(start=cm / 100)))
        if all(e.path_length >= MIN_RETREAT for e in tl.episodes
               if e.kind == APPROACH):
            return f"start further from the goal, e.g. `start {cm}cm`, or {fewer}"
    return f"{fewer}, or a start further from the goal (`start`)"


def _touching(ctx: Ctx, tl: Timeline) -> None:
    """V125: two pauses in a row are one hold."""
    for a, b in zip(tl.episodes, tl.episodes[1:], strict=False):
        if a.kind == b.kind == PAUSE:
            ctx.report(V125, f"this pause follows another with no motion between them: "
                       f"they are seen and measured as one hold of "
                       f"{a.duration + b.duration:.3g} s", b.span,
                       hint="put a motion between them, or write one longer pause")


def _beside(ctx: Ctx, tl: Timeline) -> None:
    """V121 in a sequence: a statement whose kind needs a motion of another kind right
    beside it (:attr:`~.primitives.kind.Kind.needs`, e.g. a counter-movement directly
    before an approach) where the sequence puts none. It would not count as declared,
    yet be measured as some other kind. (A kind that needs a pause beside it is not
    held to it here: a sequence may move without holds, and its episodes then do not
    count, on paper and measured alike.)"""
    eps, said = tl.episodes, set()
    for i, e in enumerate(eps):
        needs = KINDS[e.kind].needs if e.kind in KINDS else None
        if needs is None or e.span in said:
            continue
        for other, where, j in ((needs.preceded_by, "before", i - 1),
                                (needs.followed_by, "after", i + 1)):
            if other is None or other == PAUSE or (0 <= j < len(eps) and eps[j].kind == other):
                continue
            said.add(e.span)
            ctx.error(V121, f"this {e.kind} has no {other} directly {where} it: "
                      f"{needs.words(e.kind, PAUSE)}; here it would be measured as "
                      "another kind", e.span,
                      hint=f"put {'an' if other[0] in 'aeiou' else 'a'} {other} "
                      f"directly {where} it")
            break


def _none_shown(b: Behaviour, kind: str, tl: Timeline) -> str:
    """Why no episode of ``kind`` counts in the layout, in words: what the kind needs
    around it (:attr:`~.primitives.kind.Kind.needs`), and what of that the file lacks or
    else the rule that stops the layout."""
    article = "an" if kind[0] in "aeiou" else "a"
    needs = KINDS[kind].needs if kind in KINDS else None
    why = needs.words(kind, PAUSE) if needs is not None else None
    if needs is None or why is None:
        return f"the layout cannot show {article} {kind}: no {kind} of it counts"
    n_pauses = _count(b, PAUSE)
    wanted = needs.around.count(PAUSE)
    lacks = [f"this file has {('no pause', 'only one pause')[n_pauses]}"] \
        if wanted and n_pauses < wanted else []
    lacks += [f"this file has no {other}" for other in dict.fromkeys(needs.around)
              if other != PAUSE and not _count(b, other)]
    why += f", and {lacks[0]}" if lacks else f"; {_stopped_by(b, tl)}"
    return f"the layout cannot show {article} {kind}: {why}"


def _count(b: Behaviour, kind: str) -> int:
    node = b.first(kind)
    return node.count if node is not None else 0


def _shown(name: str, value: float | int | None) -> str:
    """A descriptor's value with its unit, as the file would write it."""
    unit = every_descriptor()[name].unit
    return f"{value:.3g} {unit}" if isinstance(value, float) and unit else f"{value}"


def _stopped_by(b: Behaviour, tl: Timeline) -> str:
    """The rule that keeps the layout from showing more, in words: a need of the kinds
    counting finds, else the bounds of the search (the orders of stops it tries)."""
    why = why_not(b)
    if why is not None:
        return why
    return (f"no arrangement the layout tries shows more (its stops in the {tl.state.value} "
            "order, then in the other orders it tries)")


def _realisable(ctx: Ctx, b: Behaviour, tl: Timeline) -> None:
    """V121: the laid-out descriptor form must show the values the file writes. When no
    episode of a statement counts, one diagnostic says why: its values are absent for
    that one reason."""
    said: set[int] = set()
    table = every_descriptor()
    for m in compare(written(b), derive(episode_values(tl.episodes))):
        node = source_of(b, m.name)
        if m.measured is None and id(node) in said:
            continue  # its statement is already said to show no episode that counts
        said.add(id(node))
        kind = table[m.name].kind
        none = m.measured is None or (table[m.name].is_count and m.measured == 0)
        shows = _none_shown(b, kind, tl) if none else \
            f"its layout shows {_shown(m.name, m.measured)}: {_stopped_by(b, tl)}" \
            if table[m.name].is_count else \
            f"its layout shows {_shown(m.name, m.measured)}"
        ctx.error(V121, f"{m.name} is declared {_shown(m.name, m.declared)} but {shows}",
                  node.span if node else b.span,
                  hint="pauses need motion between them (an approach, a retreat, a gaze...); "
                  "a retreat needs a pause before and after it, a gaze one after it",
                  descriptor=m.name, declared=m.declared, realised=m.measured)


def check_whole(ctx: Ctx, b: Behaviour, laid: Laid | None = None) -> Timeline | None:
    """Check the behaviour as a whole; its timeline, or None when it cannot be laid out
    (with ``laid``, the episodes of the file's last layout are taken again)."""
    if not _episodes(ctx, b):
        return None
    if b.form == "sequence" and not _standoff(ctx, b):
        return None
    tl = layout(b, laid)
    if not _time(ctx, b, tl):
        return None
    if not tl.episodes:
        ctx.error(V124, "the behaviour has nothing to move or hold: no primitive makes an "
                  "episode", b.span, hint="add a primitive, e.g. `approach` or `pause 1s`")
        return tl
    _reach(ctx, b, tl)
    _swept(ctx, tl)
    _short_moves(ctx, b, tl)
    _touching(ctx, tl)
    if b.form == "descriptor":
        _realisable(ctx, b, tl)
    else:
        _beside(ctx, tl)
    return tl
