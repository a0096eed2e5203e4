"""Stage 3, layout: a behaviour -> a timeline of episodes (pure Python, no heavy imports).

An episode moves the end-effector between two *poses* of the reach, written in the
goal-centred coordinates of :class:`Pose`: the distance to the goal, the gaze bearings
in the horizontal and vertical planes, and the roll about the forward axis. The
geometry stage turns poses into SE(3) targets; the timing stage gives moving episodes
their durations. docs/compiler.md has the layout rules with a table per state.

Descriptor form, in short:

1. Gaze episodes alternate +angle, -angle (horizontal ones first, then vertical), each
   followed by a pause when the pause budget allows.
2. Retreats form clusters ``P R P`` (or chains ``P R P R P`` when pauses are short),
   because a retreat starts and ends at a pause. Tilts join gaze clusters, shivers join
   retreat clusters, else each forms a stop of its own.
3. A pause left over holds the pre-grasp pose at the end; further ones become stops.
4. The stops are ordered by the state's composition and the approach is split between
   them: each advance wins back the last withdrawal and then makes an equal share of the
   net progress, so the reach never gets closer than the standoff and ends there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Literal

from ..cv import composition_of, infer
from ..diagnostics import Span
from ..ir import Approach, Behaviour, Gaze, Pause, Retreat, Shiver, State, Tilt
from ..validate import bang_time

__all__ = [
    "GAZE_ANGULAR_ACCEL",
    "Episode",
    "Pose",
    "STOP_ORDER",
    "Timeline",
    "bang_time",
    "layout",
]

#: Angular acceleration of gaze arcs [rad/s^2] (the language sets only their speed).
GAZE_ANGULAR_ACCEL = math.radians(45.0)

Kind = Literal["approach", "retreat", "pause", "gaze", "tilt", "shiver"]


@dataclass(frozen=True, slots=True)
class Pose:
    """A pose of the reach in goal-centred coordinates.

    Attributes:
        d: distance from the goal [m].
        h: bearing in the horizontal plane [rad] (rotation about the start y axis).
        v: bearing in the vertical plane [rad] (rotation about the start x axis).
        roll: roll about the forward axis [rad].
    """

    d: float
    h: float = 0.0
    v: float = 0.0
    roll: float = 0.0


@dataclass(frozen=True, slots=True)
class Episode:
    """One primitive episode of the timeline.

    ``a`` and ``vmax`` bound the episode's own path coordinate: metres for approach and
    retreat, radians for gaze (bearing) and tilt (roll). ``duration`` is fixed for pauses,
    shivers and tilts, and planned (rest to rest at ``a`` and ``vmax``) for the others.
    """

    kind: Kind
    span: Span
    start: Pose
    end: Pose
    duration: float
    a: float = 0.0
    vmax: float = 0.0
    amplitude: float = 0.0  # shiver, peak to peak [rad]
    f: float = 0.0  # shiver [Hz]
    plane: str | None = None  # gaze

    @property
    def moving(self) -> bool:
        return self.kind != "pause"

    @property
    def path_length(self) -> float:
        """Length of the episode's path coordinate [m or rad]."""
        s, e = self.start, self.end
        if self.kind in ("approach", "retreat"):
            return abs(e.d - s.d)
        if self.kind == "gaze":
            return abs(e.h - s.h) + abs(e.v - s.v)
        if self.kind == "tilt":
            return abs(e.roll - s.roll)
        return 0.0


@dataclass(frozen=True, slots=True)
class Timeline:
    behaviour: str
    state: State
    declared_state: State | None
    episodes: tuple[Episode, ...]

    @property
    def planned_duration(self) -> float:
        return sum(e.duration for e in self.episodes)


# --- episode builders ---------------------------------------------------------------------


def _move(kind: Kind, span: Span, start: Pose, end: Pose, a: float, vmax: float,
          **kw) -> Episode:
    ep = Episode(kind, span, start, end, 0.0, a=a, vmax=vmax, **kw)
    return replace(ep, duration=bang_time(ep.path_length, a, vmax))


def _approach_to(p: Approach, pose: Pose, d: float) -> Episode:
    kind: Kind = "approach" if d <= pose.d else "retreat"
    return _move(kind, p.span, pose, replace(pose, d=d), p.a, p.v)


def _retreat(p: Retreat, pose: Pose, length: float) -> Episode:
    end = replace(pose, d=pose.d + length)
    return _move("retreat" if length >= 0 else "approach", p.span, pose, end, p.a, p.v)


def _pause(p: Pause, pose: Pose) -> Episode:
    return Episode("pause", p.span, pose, pose, p.duration)


def _gaze(p: Gaze, pose: Pose, bearing: float) -> Episode:
    end = replace(pose, h=bearing) if p.plane == "horizontal" else replace(pose, v=bearing)
    return _move("gaze", p.span, pose, end, GAZE_ANGULAR_ACCEL, p.v, plane=p.plane)


def _tilt(p: Tilt, pose: Pose, delta: float) -> Episode:
    end = replace(pose, roll=pose.roll + delta)
    # The tilt velocity descriptor is angle / duration: the duration is fixed.
    duration = abs(delta) / p.v
    return Episode("tilt", p.span, pose, end, duration, a=4.0 * abs(delta) / duration ** 2,
                   vmax=2.0 * p.v)


def _shiver(p: Shiver, pose: Pose) -> Episode:
    return Episode("shiver", p.span, pose, pose, shiver_duration(p.duration, p.f),
                   amplitude=p.amplitude, f=p.f)


def shiver_duration(requested: float, f: float) -> float:
    """A shiver lasts a whole number of cycles, at least 3 (ramp up, full, ramp down)."""
    return max(3, round(requested * f)) / f


# --- the sequence form ----------------------------------------------------------------------


def _sequence(b: Behaviour) -> list[Episode]:
    s = b.settings
    pose = Pose(s.start)
    out: list[Episode] = []
    for p in b.primitives:
        for _ in range(p.count):
            if isinstance(p, Approach):
                d = s.standoff if p.length is None else pose.d - p.length
                ep = _approach_to(p, pose, d)
            elif isinstance(p, Retreat):
                ep = _retreat(p, pose, p.length)
            elif isinstance(p, Pause):
                ep = _pause(p, pose)
            elif isinstance(p, Gaze):
                ep = _gaze(p, pose, p.angle)
            elif isinstance(p, Tilt):
                ep = _tilt(p, pose, p.angle)
            else:
                ep = _shiver(p, pose)
            if ep.moving and ep.path_length == 0.0 and ep.kind != "shiver":
                continue  # nothing moves (e.g. an approach already at the standoff)
            out.append(ep)
            pose = ep.end
    return out


# --- the descriptor form ----------------------------------------------------------------------

#: Which kinds of stop come first along the reach, by state (MODEL.md s3 composition).
STOP_ORDER: dict[State, tuple[str, ...]] = {
    State.CONFIDENT: ("pause", "gaze", "tilt", "retreat", "shiver"),
    State.CURIOUS: ("gaze", "tilt", "pause", "retreat", "shiver"),
    State.HESITANT: ("retreat", "pause", "shiver", "gaze", "tilt"),
    State.FEARFUL: ("retreat", "shiver", "pause", "gaze", "tilt"),
    State.INACTIVE: ("pause", "shiver", "tilt", "gaze", "retreat"),
}


@dataclass
class _Stop:
    """A cluster of non-approach episodes at one place of the reach, as a recipe."""

    kind: str
    #: ("pause", Pause), ("retreat", Retreat), ("gaze", (Gaze, bearing)),
    #: ("tilt", (Tilt, delta)), ("shiver", Shiver)
    items: list[tuple[str, Any]]


def _split(n: int, k: int) -> list[int]:
    """``n`` split into ``k`` near-equal parts, larger first."""
    return [n // k + (1 if i < n % k else 0) for i in range(k)]


def _stops(b: Behaviour) -> tuple[list[_Stop], bool]:
    """The stops of a descriptor-form behaviour and whether a final pause holds the end."""
    pause = b.first("pause")
    retreat = b.first("retreat")
    tilt = b.first("tilt")
    shiver = b.first("shiver")
    n_p = pause.count if pause else 0
    n_r = retreat.count if retreat else 0
    gazes: list[tuple[Gaze, float]] = []
    for plane in ("horizontal", "vertical"):
        g = b.first("gaze", plane)
        if g is not None:
            gazes += [(g, g.angle if i % 2 == 0 else -g.angle) for i in range(g.count)]

    # Pause budget: retreats need n_r + 1, gazes one each, the rest holds and stops.
    need_r = n_r + 1 if n_r else 0
    gaze_p = min(len(gazes), max(0, n_p - need_r))
    extra = n_p - need_r - gaze_p
    clusters = 1 + min(n_r - 1, extra) if n_r else 0
    extra -= max(0, clusters - 1)

    stops: list[_Stop] = []
    for g, bearing in gazes:
        stops.append(_Stop("gaze", [("gaze", (g, bearing))]))
    for size in _split(n_r, clusters) if clusters else []:
        items: list = [("pause", pause)]
        for _ in range(size):
            items += [("retreat", retreat), ("pause", pause)]
        stops.append(_Stop("retreat", items))
    # Tilts join gaze stops (before their pause), else stand alone; alternate +/-.
    gaze_stops = [s for s in stops if s.kind == "gaze"]
    for i in range(tilt.count if tilt is not None else 0):
        assert tilt is not None
        delta = tilt.angle if i % 2 == 0 else -tilt.angle
        if gaze_stops:
            gaze_stops[i % len(gaze_stops)].items.append(("tilt", (tilt, delta)))
        else:
            stops.append(_Stop("tilt", [("tilt", (tilt, delta))]))
    # Gaze pauses come after the gaze (and its tilts).
    for i, s in enumerate(gaze_stops):
        if i < gaze_p:
            s.items.append(("pause", pause))
    retreat_stops = [s for s in stops if s.kind == "retreat"]
    for i in range(shiver.count if shiver else 0):
        if retreat_stops:
            retreat_stops[i % len(retreat_stops)].items.append(("shiver", shiver))
        else:
            stops.append(_Stop("shiver", [("shiver", shiver)]))
    final_pause = extra > 0
    extra -= 1 if final_pause else 0
    stops += [_Stop("pause", [("pause", pause)]) for _ in range(max(0, extra))]
    return stops, final_pause


def _descriptor(b: Behaviour, state: State) -> list[Episode]:
    s = b.settings
    approach = b.first("approach")
    pause = b.first("pause")
    stops, final_pause = _stops(b)
    order = STOP_ORDER[state]
    stops.sort(key=lambda st: order.index(st.kind))  # stable: keeps gaze alternation
    # Without an approach there is no progress: the stops run at the start pose, and
    # pauses that would touch are kept apart by the motion between them where possible.
    k = len(stops)
    net = s.start - s.standoff
    pose = Pose(s.start)
    out: list[Episode] = []

    def add(ep: Episode) -> None:
        nonlocal pose
        out.append(ep)
        pose = ep.end

    for j, stop in enumerate(stops):
        if approach is not None and approach.count:
            target = s.standoff + net * (k - j) / (k + 1)
            if pose.d > target + 1e-12:
                add(_approach_to(approach, pose, target))
        for what, data in stop.items:
            if what == "pause":
                if out and out[-1].kind == "pause":
                    continue  # two pauses touching would read as one
                add(_pause(data, pose))
            elif what == "retreat":
                add(_retreat(data, pose, data.length))
            elif what == "gaze":
                g, bearing = data
                add(_gaze(g, pose, bearing))
            elif what == "tilt":
                t, delta = data
                add(_tilt(t, pose, delta))
            elif what == "shiver":
                add(_shiver(data, pose))
    if approach is not None and approach.count and pose.d > s.standoff + 1e-12:
        add(_approach_to(approach, pose, s.standoff))
    if final_pause and pause is not None and not (out and out[-1].kind == "pause"):
        add(_pause(pause, pose))
    return out


def layout(b: Behaviour) -> Timeline:
    """Lay a behaviour out in time. Deterministic: the same IR gives the same timeline."""
    state = b.state or infer(composition_of(b))[0].state
    episodes = _sequence(b) if b.form == "sequence" else _descriptor(b, state)
    return Timeline(b.name, state, b.state, tuple(episodes))

