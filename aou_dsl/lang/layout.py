"""Layout: a behaviour -> a timeline of episodes (pure Python, no heavy imports).

A sequence is laid out as written. The descriptor form is laid out in three steps
(docs/compiler.md has the rules with a table per state):

1. *Stops*: the episodes that are not approaches, grouped. Gaze episodes alternate
   +angle, -angle (horizontal first, then vertical), tilts join gaze stops (before the
   gaze) and shivers retreat stops; retreats form clusters (``R R`` when pauses are
   scarce), and pauses left over after the end's hold become stops of their own. The
   stops are ordered by the state's composition; then the tilts alternate +angle, -angle
   in the order they run, so the roll stays between the start's and one angle from it.
2. *Motion*: an approach piece leads to each stop and a last one to the standoff; each
   wins back the last withdrawal and makes an equal share of the net progress, so the
   reach never gets closer than the standoff and ends there.
3. *Pauses* go into the gaps between motion episodes: first those the definitions need
   (before and after every retreat; after the first gaze of each plane, since a gaze
   descriptor is an angle, read at a pause that ends a gaze), then the pause stops, the
   hold at the end, then any gap left (after the other gazes first), the start last.
   Two pauses never touch: they would read as one.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

from .cv import composition, infer
from .descriptors import EpisodeValues
from .ir import Behaviour, Node, State
from .primitives import KINDS, Approach, Gaze, Tilt
from .timeline import Episode, Pose, Timeline

__all__ = ["STOP_ORDER", "Laid", "episode_values", "layout", "nominal_values"]

#: Which kinds of stop come first along the reach, by state (the composition of each
#: state: docs/model.md).
STOP_ORDER: dict[State, tuple[str, ...]] = {
    State.CONFIDENT: ("pause", "gaze", "tilt", "retreat", "shiver"),
    State.CURIOUS: ("gaze", "tilt", "pause", "retreat", "shiver"),
    State.HESITANT: ("retreat", "pause", "shiver", "gaze", "tilt"),
    State.FEARFUL: ("retreat", "shiver", "pause", "gaze", "tilt"),
    State.INACTIVE: ("pause", "shiver", "tilt", "gaze", "retreat"),
}


# --- the sequence form ----------------------------------------------------------------------


class Laid:
    """The episodes each statement of a sequence was laid out into, and from which pose:
    a layout of the same file after an edit takes them again for a statement whose node
    (the same object: kept by the incremental linter) starts from the same pose. What
    one layout did not use is forgotten by the next (:meth:`turn`)."""

    def __init__(self) -> None:
        self._last: dict[int, tuple] = {}
        self._now: dict[int, tuple] = {}

    def turn(self) -> None:
        self._last, self._now = self._now, {}

    @staticmethod
    def _where(pose: Pose, standoff: float) -> bytes:
        """The pose and standoff to the bit (``==`` would take -0.0 for 0.0)."""
        return struct.pack("5d", pose.d, pose.h, pose.v, pose.roll, standoff)

    def get(self, p: Node, pose: Pose, standoff: float) -> tuple[list[Episode], Pose] | None:
        e = self._now.get(id(p)) or self._last.get(id(p))
        if e is None or e[0] is not p or e[1] != self._where(pose, standoff):
            return None
        self._now[id(p)] = e
        return e[2], e[3]

    def put(self, p: Node, pose: Pose, standoff: float, eps: list[Episode], end: Pose
            ) -> None:
        # p is held, so that its id stays its own while kept
        self._now[id(p)] = (p, self._where(pose, standoff), eps, end)


def _sequence(b: Behaviour, laid: Laid | None = None) -> list[Episode]:
    s = b.settings
    pose = Pose(s.start)
    out: list[Episode] = []
    for p in b.primitives:
        kept = laid.get(p, pose, s.standoff) if laid is not None else None
        if kept is not None:
            out += kept[0]
            pose = kept[1]
            continue
        start, eps = pose, []
        for _ in range(p.count):
            ep = _sequence_episode(p, pose, s.standoff)
            if ep.moving and ep.path_length == 0.0 and ep.kind != "shiver":
                continue  # nothing moves (e.g. an approach already at the standoff)
            eps.append(ep)
            pose = ep.end
        out += eps
        if laid is not None:
            laid.put(p, start, s.standoff, eps, pose)
    return out


def _sequence_episode(p: Node, pose: Pose, standoff: float) -> Episode:
    arg: float | None = None
    if isinstance(p, Approach):
        arg = standoff if p.length is None else pose.d - p.length
    elif isinstance(p, (Gaze, Tilt)):  # to a plane angle, by a roll: as written
        arg = p.angle
    return KINDS[p.kind].episode(p, pose, arg)


# --- the descriptor form --------------------------------------------------------------------


@dataclass
class _Stop:
    """A group of non-approach episodes at one place of the reach.

    ``items`` are ``(node, arg)``: ``arg`` is a gaze's plane angle or a tilt's roll
    [rad], else None.
    """

    kind: str
    items: list[tuple[Node, float | None]] = field(default_factory=list)


def _split(n: int, k: int) -> list[int]:
    """``n`` split into ``k`` near-equal parts, larger first."""
    return [n // k + (1 if i < n % k else 0) for i in range(k)]


def _count(node: Node | None) -> int:
    return node.count if node is not None else 0


def _gazes(b: Behaviour) -> list[tuple[Node, float]]:
    out = []
    for plane in ("horizontal", "vertical"):
        g = b.first("gaze", plane)
        out += [(g, g.angle if i % 2 == 0 else -g.angle) for i in range(_count(g))]
    return out


@dataclass
class _Plan:
    stops: list[_Stop]
    pause_stops: int
    end_hold: bool


def _plan(b: Behaviour, has_approach: bool) -> _Plan:
    """The stops, and how the pauses left after the required ones are used."""
    n_p, n_r = _count(b.first("pause")), _count(b.first("retreat"))
    retreat, tilt, shiver = b.first("retreat"), b.first("tilt"), b.first("shiver")
    gazes = _gazes(b)
    need_r = n_r + 1 if n_r else 0
    spare = n_p - need_r - min(len(gazes), max(0, n_p - need_r))
    clusters = 1 + min(n_r - 1, max(0, spare)) if n_r else 0
    spare -= max(0, clusters - 1)
    stops = [_Stop("gaze", [(g, angle)]) for g, angle in gazes]
    gaze_stops = list(stops)
    for size in _split(n_r, clusters) if clusters else []:
        stops.append(_Stop("retreat", [(retreat, None)] * size))
    for i in range(_count(tilt)):  # the signs are set in time order, once stops are sorted
        if gaze_stops:
            gaze_stops[i % len(gaze_stops)].items.insert(0, (tilt, tilt.angle))
        else:
            stops.append(_Stop("tilt", [(tilt, tilt.angle)]))
    retreat_stops = [s for s in stops if s.kind == "retreat"]
    _share_pauses(stops, gaze_stops, retreat_stops, n_p - need_r - (clusters - 1))
    for i in range(_count(shiver)):
        if retreat_stops:
            retreat_stops[i % len(retreat_stops)].items.append((shiver, None))
        else:
            stops.append(_Stop("shiver", [(shiver, None)]))
    end_hold = spare > 0
    pause_stops = max(0, spare - 1) if has_approach else 0
    stops += [_Stop("pause") for _ in range(pause_stops)]
    return _Plan(stops, pause_stops, end_hold)


def _share_pauses(stops: list[_Stop], gaze_stops: list[_Stop], retreat_stops: list[_Stop],
                  free: int) -> None:
    """When pauses are too few for every gaze plane to end at one of its own, a gaze
    joins a retreat stop, just before the retreats: the pause that starts them ends it."""
    firsts: dict[str, _Stop] = {}
    for st in gaze_stops:
        plane = next(n.plane for n, _ in st.items if isinstance(n, Gaze))
        firsts.setdefault(plane, st)
    short = max(0, len(firsts) - max(0, free))
    for st, host in zip(list(firsts.values())[len(firsts) - short:], retreat_stops,
                        strict=False):
        stops.remove(st)
        host.items[:0] = st.items


def _alternate_tilts(stops: list[_Stop]) -> None:
    """Tilts alternate +angle, -angle in the order they run, so the roll goes back and
    forth between the start's and one angle away, whichever stops they join."""
    n = 0
    for st in stops:
        for k, (node, arg) in enumerate(st.items):
            if node.kind == "tilt" and arg is not None:
                st.items[k] = (node, abs(arg) if n % 2 == 0 else -abs(arg))
                n += 1


def _motion(b: Behaviour, approach: Approach | None, stops: list[_Stop]
            ) -> tuple[list[Episode], set[int], list[int]]:
    """The motion episodes in order; the gaps that need a pause (gap ``i`` is before
    episode ``i``); then the gaps that want one, best first (after the other gazes, then
    where a pause stop sits)."""
    s = b.settings
    k, net = len(stops), s.start - s.standoff
    pose, out = Pose(s.start), []
    required: set[int] = set()
    gaze_gaps: dict[str | None, list[int]] = {}  # per plane, the gaps after its gazes
    stop_gaps: list[int] = []
    for j, stop in enumerate(stops):
        target = s.standoff + net * (k - j) / (k + 1)
        if approach is not None and pose.d > target + 1e-12:
            out.append(KINDS["approach"].episode(approach, pose, target))
            pose = out[-1].end
        if stop.kind == "pause":
            stop_gaps.append(len(out))
        for node, arg in stop.items:
            ep = KINDS[node.kind].episode(node, pose, arg)
            if ep.kind == "retreat":
                required.add(len(out))
            out.append(ep)
            pose = ep.end
            if ep.kind == "retreat":
                required.add(len(out))
            elif ep.kind == "gaze":
                gaze_gaps.setdefault(ep.plane, []).append(len(out))
    if approach is not None and pose.d > s.standoff + 1e-12:
        out.append(KINDS["approach"].episode(approach, pose, s.standoff))
    # A plane's gaze angle is read at a pause that ends one of its gazes: one per plane is
    # needed (shared with a retreat's pause where one follows a gaze); the rest are wanted.
    wanted: list[int] = []
    for gaps in gaze_gaps.values():
        if not required.intersection(gaps):
            required.add(gaps[-1])
        wanted += [g for g in gaps if g not in required]
    return out, required, sorted(wanted) + stop_gaps


def _descriptor(b: Behaviour, state: State) -> list[Episode]:
    approach = b.first("approach")
    approach = approach if _count(approach) else None
    pause = b.first("pause")
    plan = _plan(b, approach is not None)
    order = STOP_ORDER[state]
    plan.stops.sort(key=lambda st: order.index(st.kind))  # stable: keeps alternation
    _alternate_tilts(plan.stops)
    motion, required, preferred = _motion(b, approach, plan.stops)
    n = len(motion)
    wanted = sorted(required) + preferred + ([n] if plan.end_hold else [])
    wanted += [g for g in range(n, -1, -1)]  # any gap left, from the end to the start
    gaps: list[int] = []
    for g in wanted:
        if len(gaps) == _count(pause):
            break
        if g not in gaps:
            gaps.append(g)
    out: list[Episode] = []
    for i in range(n + 1):
        if i in gaps and pause is not None:
            at = motion[i].start if i < n else (motion[-1].end if motion else
                                                Pose(b.settings.start))
            out.append(KINDS["pause"].episode(pause, at))
        if i < n:
            out.append(motion[i])
    return out


# --- values for the descriptors and the C-V inference ------------------------------------


def nominal_values(b: Behaviour) -> list[EpisodeValues]:
    """A descriptor-form file's episodes as written, before any layout: ``count`` copies of
    each statement's values (for the C-V inference, which needs no order)."""
    return [EpisodeValues(p.kind, values=KINDS[p.kind].values(p))
            for p in b.primitives for _ in range(p.count)]


def episode_values(episodes: tuple[Episode, ...] | list[Episode]) -> list[EpisodeValues]:
    """A timeline's episodes as the descriptors see them, on the planned clock."""
    out, t = [], 0.0
    for e in episodes:
        out.append(EpisodeValues(e.kind, t, t + e.duration, KINDS[e.kind].episode_values(e)))
        t += e.duration
    return out


def layout(b: Behaviour, laid: Laid | None = None) -> Timeline:
    """Lay a behaviour out in time. Deterministic: the same IR gives the same timeline.

    A file without a declared state is laid out as the state its primitives express.
    ``laid`` keeps a sequence's episodes for the next layout of the same file.
    """
    if b.form == "sequence":
        episodes = _sequence(b, laid)
        state = b.state or infer(composition(episode_values(episodes)))[0].state
    else:
        state = b.state or infer(composition(nominal_values(b)))[0].state
        episodes = _descriptor(b, state)
    return Timeline(b.name, state, b.state, tuple(episodes))
