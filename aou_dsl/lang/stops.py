"""The descriptor form's layout: stops in the state's order, an approach split between
them, pauses in the gaps (docs/compiler.md has the rules with a table per state).

1. *Stops*: the episodes that are not approaches, grouped. Gaze episodes alternate
   +angle, -angle (horizontal first, then vertical), tilts join gaze stops (before the
   gaze) and shivers retreat stops; retreats form clusters (``R R`` when pauses are
   scarce), and pauses left over after the end's hold become stops of their own. A kind
   the state's order does not name (a plugin's) makes stops of its own, after the others.
   The stops are ordered by the state's composition; then the tilts alternate +angle,
   -angle in the order they run, so the roll stays between the start's and one angle
   from it.
2. *Motion*: an approach piece leads to each stop and a last one to the standoff; each
   wins back the last withdrawal and makes an equal share of the net progress, so the
   reach never gets closer than the standoff and ends there.
3. *Pauses* go into the gaps between motion episodes, as the kinds' needs say
   (:attr:`~.primitives.kind.Kind.needs`): first those they need (before and after every
   retreat; after the last gaze of each plane unless a pause ends one already, since a
   gaze descriptor is an angle, read at a pause that ends a gaze), then the pause stops,
   the hold at the end, then any gap left (after the other gazes first), the start last;
   never where a kind needs another kind next to it (a move directly before an
   approach). Two pauses never touch: they would read as one.

That is the first arrangement tried. When it does not show every descriptor the file
writes (:func:`~.kind_needs.shows_all`), others are searched in a fixed order (the
state's order of stops first, then the other orders of the file's stops, with the gazes'
signs alternating in the order they run; then the same orders with each number of
retreat clusters and of gaze planes sharing their pauses; at most :data:`MAX_WAYS`) and
the first that shows the file is laid out. Counting (:func:`~.kind_needs.why_not`)
skips the search when no arrangement can show the file.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from dataclasses import dataclass, field

from .ir import Behaviour, Node, State
from .kind_needs import every_counts, shows_all, why_not
from .primitives import APPROACH, GAZE, KINDS, PAUSE, RETREAT, SHIVER, TILT, Approach, Gaze
from .timeline import Episode, Pose

__all__ = ["MAX_WAYS", "STOP_ORDER", "descriptor_layout"]

#: Which kinds of stop come first along the reach, by state (the composition of each
#: state: docs/model.md).
STOP_ORDER: dict[State, tuple[str, ...]] = {
    State.CONFIDENT: (PAUSE, GAZE, TILT, RETREAT, SHIVER),
    State.CURIOUS: (GAZE, TILT, PAUSE, RETREAT, SHIVER),
    State.HESITANT: (RETREAT, PAUSE, SHIVER, GAZE, TILT),
    State.FEARFUL: (RETREAT, SHIVER, PAUSE, GAZE, TILT),
    State.INACTIVE: (PAUSE, SHIVER, TILT, GAZE, RETREAT),
}
#: The kinds the plan groups itself; any other kind (a plugin's) makes stops of its own.
_PLANNED = frozenset({APPROACH, PAUSE, GAZE, TILT, RETREAT, SHIVER})


@dataclass
class _Stop:
    """A group of non-approach episodes at one place of the reach.

    ``items`` are ``(node, arg)``: ``arg`` is a gaze's plane angle or a tilt's roll
    [rad], else None.
    """

    kind: str
    items: list[tuple[Node, float | None]] = field(default_factory=list)


@dataclass(frozen=True)
class _Way:
    """One arrangement of the search: the order of the kinds of stop, whether the gazes'
    signs alternate in the order they run (else in the order they are made), and, when
    set, the number of retreat clusters and of gaze planes that share a retreat's pause."""

    order: tuple[str, ...]
    in_time: bool = False
    clusters: int | None = None
    share: int | None = None


def _split(n: int, k: int) -> list[int]:
    """``n`` split into ``k`` near-equal parts, larger first."""
    return [n // k + (1 if i < n % k else 0) for i in range(k)]


def _count(node: Node | None) -> int:
    return node.count if node is not None else 0


def _gazes(b: Behaviour) -> list[tuple[Node, float]]:
    out = []
    for plane in ("horizontal", "vertical"):
        g = b.first(GAZE, plane)
        out += [(g, g.angle if i % 2 == 0 else -g.angle) for i in range(_count(g))]
    return out


@dataclass
class _Plan:
    stops: list[_Stop]
    pause_stops: int
    end_hold: bool


def _plan(b: Behaviour, has_approach: bool, way: _Way) -> _Plan:
    """The stops, and how the pauses left after the required ones are used."""
    n_p, n_r = _count(b.first(PAUSE)), _count(b.first(RETREAT))
    retreat, tilt, shiver = b.first(RETREAT), b.first(TILT), b.first(SHIVER)
    gazes = _gazes(b)
    need_r = n_r + 1 if n_r else 0
    spare = n_p - need_r - min(len(gazes), max(0, n_p - need_r))
    clusters = 1 + min(n_r - 1, max(0, spare)) if n_r else 0
    if way.clusters is not None and n_r:
        clusters = max(1, min(n_r, way.clusters))
    spare -= max(0, clusters - 1)
    stops = [_Stop(GAZE, [(g, angle)]) for g, angle in gazes]
    gaze_stops = list(stops)
    for size in _split(n_r, clusters) if clusters else []:
        stops.append(_Stop(RETREAT, [(retreat, None)] * size))
    for i in range(_count(tilt)):  # the signs are set in time order, once stops are sorted
        if gaze_stops:
            gaze_stops[i % len(gaze_stops)].items.insert(0, (tilt, tilt.angle))
        else:
            stops.append(_Stop(TILT, [(tilt, tilt.angle)]))
    retreat_stops = [s for s in stops if s.kind == RETREAT]
    _share_pauses(stops, gaze_stops, retreat_stops, n_p - need_r - (clusters - 1), way)
    for i in range(_count(shiver)):
        if retreat_stops:
            retreat_stops[i % len(retreat_stops)].items.append((shiver, None))
        else:
            stops.append(_Stop(SHIVER, [(shiver, None)]))
    for p in b.primitives:  # a kind the plan does not group (a plugin's): stops of its own
        if p.kind not in _PLANNED:
            stops += [_Stop(p.kind, [(p, None)]) for _ in range(p.count)]
    end_hold = spare > 0
    pause_stops = max(0, spare - 1) if has_approach else 0
    stops += [_Stop(PAUSE) for _ in range(pause_stops)]
    return _Plan(stops, pause_stops, end_hold)


def _share_pauses(stops: list[_Stop], gaze_stops: list[_Stop], retreat_stops: list[_Stop],
                  free: int, way: _Way) -> None:
    """When pauses are too few for every gaze plane to end at one of its own, a gaze
    joins a retreat stop, just before the retreats: the pause that starts them ends it."""
    firsts: dict[str, _Stop] = {}
    for st in gaze_stops:
        plane = next(n.plane for n, _ in st.items if isinstance(n, Gaze))
        firsts.setdefault(plane, st)
    short = max(0, len(firsts) - max(0, free))
    if way.share is not None:
        short = min(len(firsts), way.share)
    for st, host in zip(list(firsts.values())[len(firsts) - short:], retreat_stops,
                        strict=False):
        stops.remove(st)
        host.items[:0] = st.items


def _alternate(stops: list[_Stop], kind: str, by_plane: bool) -> None:
    """Episodes of ``kind`` alternate +angle, -angle in the order they run (per plane
    with ``by_plane``): a tilt's roll goes back and forth between the start's and one
    angle away, a gaze always turns, whichever stops they join."""
    n: dict[str | None, int] = {}
    for st in stops:
        for k, (node, arg) in enumerate(st.items):
            if node.kind == kind and arg is not None:
                key = getattr(node, "plane", None) if by_plane else None
                i = n.get(key, 0)
                st.items[k] = (node, abs(arg) if i % 2 == 0 else -abs(arg))
                n[key] = i + 1


def _motion(b: Behaviour, approach: Approach | None, stops: list[_Stop]
            ) -> tuple[list[Episode], set[int], list[int], set[int]]:
    """The motion episodes in order; the gaps that need a pause (gap ``i`` is before
    episode ``i``); the gaps that want one, best first (after the other gazes, then where
    a pause stop sits); the gaps no pause may take (a kind needs another kind there)."""
    s = b.settings
    k, net = len(stops), s.start - s.standoff
    pose, out = Pose(s.start), []
    required: set[int] = set()
    barred: set[int] = set()
    ends: dict[tuple[str, str | None], list[int]] = {}  # per kind and plane, the gaps after
    stop_gaps: list[int] = []
    # a need the file cannot meet (no episode of the kind needed) bars no gap: it is V121's
    has = {p.kind for p in b.primitives if p.count} - ({APPROACH} if approach is None else set())
    for j, stop in enumerate(stops):
        target = s.standoff + net * (k - j) / (k + 1)
        if approach is not None and pose.d > target + 1e-12:
            out.append(KINDS[APPROACH].episode(approach, pose, target))
            pose = out[-1].end
        if stop.kind == PAUSE:
            stop_gaps.append(len(out))
        for node, arg in stop.items:
            ep = KINDS[node.kind].episode(node, pose, arg)
            needs = KINDS[ep.kind].needs
            if needs.preceded_by is not None and needs.preceded_by in has:
                (required if needs.preceded_by == PAUSE else barred).add(len(out))
            out.append(ep)
            pose = ep.end
            if needs.followed_by == PAUSE and not every_counts(ep.kind):
                ends.setdefault((ep.kind, ep.plane), []).append(len(out))
            elif needs.followed_by is not None and needs.followed_by in has:
                (required if needs.followed_by == PAUSE else barred).add(len(out))
    if approach is not None and pose.d > s.standoff + 1e-12:
        out.append(KINDS[APPROACH].episode(approach, pose, s.standoff))
    # A plane's gaze angle is read at a pause that ends one of its gazes: one per plane is
    # needed (shared with a retreat's pause where one follows a gaze); the rest are wanted.
    wanted: list[int] = []
    for gaps in ends.values():
        if not required.intersection(gaps):
            required.add(gaps[-1])
        wanted += [g for g in gaps if g not in required]
    return out, required, sorted(wanted) + stop_gaps, barred


def _arranged(b: Behaviour, approach: Approach | None, way: _Way) -> list[Episode]:
    """The episodes of one arrangement: the plan's stops in ``way``'s order, the approach
    split between them, the pauses in the gaps."""
    pause = b.first(PAUSE)
    plan = _plan(b, approach is not None, way)
    order = way.order
    plan.stops.sort(key=lambda st: order.index(st.kind) if st.kind in order else len(order))
    _alternate(plan.stops, TILT, by_plane=False)
    if way.in_time:
        _alternate(plan.stops, GAZE, by_plane=True)
    motion, required, preferred, barred = _motion(b, approach, plan.stops)
    n = len(motion)
    wanted = sorted(required) + preferred + ([n] if plan.end_hold else [])
    wanted += [g for g in range(n, -1, -1)]  # any gap left, from the end to the start
    gaps: list[int] = []
    for g in wanted:
        if len(gaps) == _count(pause):
            break
        if g not in gaps and g not in barred:
            gaps.append(g)
    out: list[Episode] = []
    for i in range(n + 1):
        if i in gaps and pause is not None:
            at = motion[i].start if i < n else (motion[-1].end if motion else
                                                Pose(b.settings.start))
            out.append(KINDS[PAUSE].episode(pause, at))
        if i < n:
            out.append(motion[i])
    return out


#: At most this many arrangements are tried after the first: a file's stops have at most
#: 120 orders, and a retreat's clusters multiply them; the search stays a bounded part of
#: a lint however large the counts.
MAX_WAYS = 1000


def _ways(b: Behaviour, state: State) -> Iterator[_Way]:
    """The arrangements tried after the state's own, in a fixed order: the state's order
    of stops first, then every other order of the kinds the file has stops of, each with
    the gazes' signs alternating in the order they run; then the same orders with each
    number of retreat clusters and of gaze planes that share a retreat's pause."""
    own = STOP_ORDER[state]
    present = [k for k in own if _count(b.first(k))]
    rest = [k for k in own if k not in present]
    n_r = _count(b.first(RETREAT))
    planes = sum(1 for plane in ("horizontal", "vertical") if _count(b.first(GAZE, plane)))
    orders = [(*kinds, *rest) for kinds in itertools.permutations(present)]
    yield from (_Way(order, in_time=True) for order in orders)
    for order in orders:
        for clusters in range(1, n_r + 1):
            for share in (None, *range(planes + 1)):
                yield _Way(order, True, clusters, share)


def descriptor_layout(b: Behaviour, state: State) -> list[Episode]:
    """The descriptor form laid out as ``state`` orders it: the first arrangement that
    shows every descriptor the file writes (the state's own first), else the state's own
    (lint then says which descriptor it cannot show, V121)."""
    approach = b.first(APPROACH)
    approach = approach if _count(approach) else None
    first = _arranged(b, approach, _Way(STOP_ORDER[state]))
    if shows_all(b, first) or why_not(b) is not None:
        return first  # shown, or no arrangement can show it (counting says why)
    for way in itertools.islice(_ways(b, state), MAX_WAYS):
        eps = _arranged(b, approach, way)
        if shows_all(b, eps):
            return eps
    return first
