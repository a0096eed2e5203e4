"""Scenarios for ``aouc live``: a scene and a timeline of events, read from TOML.

A scenario file (its JSON Schema: ``aou_dsl/schemas/scenario.schema.json``)::

    title = "A card slides over the tag and away"
    duration = 30.0            # s
    rate = 100                 # Hz, the controller's tick (default 100)
    goal = [0.55, 0.0, 0.25]   # the arm's goal in its base frame [m] (default: the arm's)
    follow = false             # true: the goal moves with the target the perception sees

    [scene]
    target = [0.6, 0.0, 0.04]  # the target cube's centre [m]
    target_yaw = 180           # its tagged face looks this way [deg]
    camera = [0.2, 0.0, 0.15]  # [m]
    light = 1.0                # 1 a lit lab, 0 dark

    [[occluder]]
    name = "card"
    center = [0.45, 0.15, 0.06]
    size = [0.01, 0.06, 0.12]  # [m]

    [[event]]
    kind = "move"              # move (an occluder, the target or the camera), light, shake
    what = "card"
    at = 4.0                   # s
    duration = 4.0             # s
    to = [0.45, 0.0, 0.06]

A move goes in a straight line at constant speed (its speed blurs the image); a light
event changes the light linearly; a shake moves the camera up and down (and a little
sideways) by ``amplitude`` [m] at ``frequency`` [Hz]. Every file is untrusted: anything
it does not say right is an I507 diagnostic naming the key, never a traceback.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, replace
from typing import Any

from ..core.codes import I507
from ..core.diagnostics import AouError, Span, diag
from .world import Box, Scene

__all__ = ["EVENT_KINDS", "Event", "Scenario", "load", "parse"]

EVENT_KINDS = ("move", "light", "shake")
#: Bounds that keep a scenario a scene on a table and a run a bounded one.
MAX_DURATION, MAX_EVENTS, MAX_OCCLUDERS, MAX_BYTES = 600.0, 200, 20, 256 * 1024
_SCENE_KEYS = {"target", "target_yaw", "camera", "look_at", "light", "exposure", "noise",
               "fov"}
_TOP_KEYS = {"title", "duration", "rate", "goal", "follow", "scene", "occluder", "event"}


@dataclass(frozen=True)
class Event:
    """One change on the timeline (the module's docstring)."""

    kind: str
    at: float
    duration: float
    what: str = ""
    to: tuple[float, ...] = ()
    amplitude: float = 0.0
    frequency: float = 0.0


@dataclass(frozen=True)
class Scenario:
    """A scene and its timeline; :meth:`scene_at` is the scene at any time."""

    title: str
    duration: float
    rate: float
    goal: tuple[float, float, float] | None
    scene: Scene
    events: tuple[Event, ...]
    path: str = "<scenario>"
    follow: bool = False

    @property
    def offset(self) -> tuple[float, float, float] | None:
        """Where the goal is from the target at the start (``follow``), else None."""
        if not self.follow or self.goal is None:
            return None
        g, t = self.goal, self.scene.target
        return (g[0] - t[0], g[1] - t[1], g[2] - t[2])

    def scene_at(self, t: float) -> Scene:
        """The scene at ``t`` [s], with the velocities of whatever moves then."""
        s = self.scene
        target, target_v = _track(s.target, "target", self.events, t)
        camera, camera_v = _track(s.camera, "camera", self.events, t)
        boxes = []
        for b in s.occluders:
            centre, _ = _track(b.center, b.name, self.events, t)
            boxes.append(replace(b, center=centre))
        light = s.light
        for e in self.events:
            if e.kind == "light" and t >= e.at:
                light = light + (e.to[0] - light) * _progress(e, t)
        for e in self.events:
            if e.kind == "shake" and e.at <= t < e.at + e.duration:
                w = 2.0 * math.pi * e.frequency
                k = e.amplitude * math.sin(w * (t - e.at))
                dk = e.amplitude * w * math.cos(w * (t - e.at))
                n = math.hypot(0.3, 1.0)
                camera = (camera[0], camera[1] + 0.3 * k / n, camera[2] + k / n)
                camera_v = (camera_v[0], camera_v[1] + 0.3 * dk / n, camera_v[2] + dk / n)
        return replace(s, target=target, camera=camera, occluders=tuple(boxes),
                       light=max(0.0, light), target_velocity=target_v,
                       camera_velocity=camera_v)


def _progress(e: Event, t: float) -> float:
    return 1.0 if e.duration <= 0 else min(1.0, max(0.0, (t - e.at) / e.duration))


def _track(start: tuple[float, float, float], what: str, events: tuple[Event, ...],
           t: float) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """Where ``what`` is at ``t`` and its velocity, after the moves of it so far."""
    p: tuple[float, ...] = tuple(start)
    v: tuple[float, ...] = (0.0, 0.0, 0.0)
    for e in events:
        if e.kind != "move" or e.what != what or t < e.at:
            continue
        f = _progress(e, t)
        moving = e.duration > 0 and t < e.at + e.duration
        v = tuple((b - a) / e.duration for a, b in zip(p, e.to, strict=True)) if moving \
            else (0.0, 0.0, 0.0)
        p = tuple(a + f * (b - a) for a, b in zip(p, e.to, strict=True))
    return p, v  # type: ignore[return-value]


def load(path: str) -> Scenario:
    """The scenario of the file at ``path``.

    Raises:
        AouError: I501 when it cannot be read; I507 when it is not a scenario.
    """
    from ..core.codes import I501

    try:
        with open(path, "rb") as f:
            data = f.read(MAX_BYTES + 1)
    except OSError as exc:
        raise AouError(diag(I501, f"cannot read the scenario: {exc.strerror or exc}",
                            Span.whole_file(path))) from None
    if len(data) > MAX_BYTES:
        raise _bad(path, f"the file is larger than {MAX_BYTES // 1024} KiB")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise _bad(path, "the file is not UTF-8 text") from None
    return parse(text, path)


def parse(text: str, path: str = "<scenario>") -> Scenario:
    """The scenario of a TOML text (see :func:`load`)."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise _bad(path, f"not TOML: {exc}") from None
    _keys(path, doc, _TOP_KEYS, "the file")
    duration = _number(path, doc, "duration", lo=0.1, hi=MAX_DURATION)
    rate = _number(path, doc, "rate", lo=10.0, hi=1000.0, default=100.0)
    title = doc.get("title", "")
    if not isinstance(title, str) or len(title) > 200:
        raise _bad(path, "`title` must be a string of at most 200 characters")
    goal = _vector(path, doc, "goal", default=None)
    follow = doc.get("follow", False)
    if not isinstance(follow, bool):
        raise _bad(path, f"`follow` must be true or false, found {follow!r:.40}")
    if follow and goal is None:
        raise _bad(path, "`follow` needs a `goal`: where the arm reaches, from the target")
    sc = doc.get("scene", {})
    if not isinstance(sc, dict):
        raise _bad(path, "`scene` must be a table")
    _keys(path, sc, _SCENE_KEYS, "[scene]")
    base = Scene()
    scene = Scene(
        target=_vector(path, sc, "target", default=base.target,  # type: ignore[arg-type]
                       where="scene."),
        target_yaw=math.radians(_number(path, sc, "target_yaw", lo=-360, hi=360,
                                        default=180.0, where="scene.")),
        camera=_vector(path, sc, "camera", default=base.camera,  # type: ignore[arg-type]
                       where="scene."),
        look_at=_vector(path, sc, "look_at", default=None, where="scene."),
        light=_number(path, sc, "light", lo=0.0, hi=2.0, default=1.0, where="scene."),
        exposure=_number(path, sc, "exposure", lo=0.0, hi=0.5, default=base.exposure,
                         where="scene."),
        noise=_number(path, sc, "noise", lo=0.0, hi=50.0, default=base.noise,
                      where="scene."),
        fov=_number(path, sc, "fov", lo=10.0, hi=120.0, default=base.fov, where="scene."))
    occluders = _list(path, doc, "occluder", MAX_OCCLUDERS)
    boxes = []
    for i, o in enumerate(occluders):
        where = f"occluder[{i}]."
        _keys(path, o, {"name", "center", "size"}, f"[[occluder]] {i + 1}")
        name = o.get("name", f"occluder{i + 1}")
        if not isinstance(name, str) or not name or name in ("target", "camera"):
            raise _bad(path, f"`{where}name` must be a name other than target and camera")
        size = _vector(path, o, "size", where=where, positive=True)
        assert size is not None
        boxes.append(Box(_vector(path, o, "center", where=where),  # type: ignore[arg-type]
                         tuple(x / 2.0 for x in size), name))  # type: ignore[arg-type]
    names = [b.name for b in boxes]
    if len(set(names)) != len(names):
        raise _bad(path, "two occluders have the same name")
    events = tuple(_event(path, e, i, set(names), duration)
                   for i, e in enumerate(_list(path, doc, "event", MAX_EVENTS)))
    _no_overlap(path, events)
    return Scenario(title, duration, rate, goal, replace(scene, occluders=tuple(boxes)),
                    tuple(sorted(events, key=lambda e: e.at)), path, follow)


def _event(path: str, e: dict, i: int, names: set[str], duration: float) -> Event:
    where = f"event[{i}]."
    kind = e.get("kind")
    if kind not in EVENT_KINDS:
        raise _bad(path, f"`{where}kind` must be one of {', '.join(EVENT_KINDS)}, found "
                   f"{kind!r:.40}")
    keys = {"move": {"what", "to"}, "light": {"to"}, "shake": {"amplitude", "frequency"}}
    _keys(path, e, {"kind", "at", "duration"} | keys[kind], f"[[event]] {i + 1} ({kind})")
    at = _number(path, e, "at", lo=0.0, hi=duration, where=where)
    span = _number(path, e, "duration", lo=0.0, hi=MAX_DURATION, default=0.0, where=where)
    if kind == "move":
        what = e.get("what")
        if what not in names | {"target", "camera"}:
            raise _bad(path, f"`{where}what` must be target, camera or an occluder's name "
                       f"({', '.join(sorted(names)) or 'none declared'}), found {what!r:.40}")
        to = _vector(path, e, "to", where=where)
        assert to is not None
        return Event(kind, at, span, what, to)
    if kind == "light":
        return Event(kind, at, span, to=(_number(path, e, "to", lo=0.0, hi=2.0,
                                                 where=where),))
    if span <= 0:
        raise _bad(path, f"`{where}duration` of a shake must be positive")
    return Event(kind, at, span, amplitude=_number(path, e, "amplitude", lo=0.0, hi=0.1,
                                                   where=where),
                 frequency=_number(path, e, "frequency", lo=0.0, hi=50.0, where=where))


def _no_overlap(path: str, events: tuple[Event, ...]) -> None:
    """Two moves of one thing, or two light changes, may not run at the same time."""
    for kind, key in (("move", lambda e: e.what), ("light", lambda e: "")):
        runs: dict[str, list[Event]] = {}
        for e in sorted((e for e in events if e.kind == kind), key=lambda e: e.at):
            prev = runs.setdefault(key(e), [])
            if prev and e.at < prev[-1].at + prev[-1].duration:
                what = f" of {e.what}" if kind == "move" else ""
                raise _bad(path, f"two {kind} events{what} overlap (at {prev[-1].at:g} s and "
                           f"{e.at:g} s)")
            prev.append(e)


def _bad(path: str, message: str) -> AouError:
    return AouError(diag(I507, message, Span.whole_file(path),
                         hint="docs/live.md describes scenario files"))


def _keys(path: str, d: Any, allowed: set[str], where: str) -> None:
    if not isinstance(d, dict):
        raise _bad(path, f"{where} must be a table")
    extra = sorted(set(d) - allowed)
    if extra:
        raise _bad(path, f"{where} has key(s) it does not know: {', '.join(extra)[:120]} "
                   f"(known: {', '.join(sorted(allowed))})")


def _list(path: str, doc: dict, key: str, most: int) -> list:
    v = doc.get(key, [])
    if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
        raise _bad(path, f"`{key}` must be an array of tables ([[{key}]])")
    if len(v) > most:
        raise _bad(path, f"at most {most} [[{key}]] tables, found {len(v)}")
    return v


_MISSING = object()


def _number(path: str, d: dict, key: str, *, lo: float, hi: float, default: Any = _MISSING,
            where: str = "") -> float:
    v = d.get(key, default)
    if v is _MISSING:
        raise _bad(path, f"`{where}{key}` is missing")
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) \
            or not lo <= v <= hi:
        raise _bad(path, f"`{where}{key}` must be a number in [{lo:g}, {hi:g}], found "
                   f"{v!r:.40}")
    return float(v)


def _vector(path: str, d: dict, key: str, *, default: Any = _MISSING, where: str = "",
            positive: bool = False) -> tuple[float, float, float] | None:
    v = d.get(key, default)
    if v is _MISSING:
        raise _bad(path, f"`{where}{key}` is missing")
    if v is None:
        return None
    ok = (isinstance(v, list | tuple) and len(v) == 3
          and all(isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)
                  and abs(x) <= 10.0 and (x > 0 or not positive) for x in v))
    if not ok:
        kind = "positive numbers" if positive else "numbers within 10 m"
        raise _bad(path, f"`{where}{key}` must be three {kind} [m], found {v!r:.60}")
    return (float(v[0]), float(v[1]), float(v[2]))
