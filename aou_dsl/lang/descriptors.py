"""The eleven expressive descriptors: one table, and one way to derive them from episodes.

Everything else in aou reads :data:`REGISTRY`: the declared side (a file's values, or the
timeline the layout makes of it), the measured side (``aouc measure``), reports, study
variants, the C-V inference and synthesis. A descriptor is defined by the episodes it is
read from and how their values aggregate (docs/model.md, "Descriptors"):

- counts are the number of qualifying episodes;
- durations, distances, tilt angles and velocities are the median over episodes;
- peaks (accelerations, shiver amplitude) are the maximum;
- a gaze is the largest angle from the initial line of sight reached at the pause that
  ends a gaze episode (a look that comes back is still the look).

Which episodes qualify is decided once, by :func:`qualify`: two pauses with nothing
moving between them are one pause, a retreat counts when it starts and ends at a pause,
a gaze when a pause ends it. The declared timeline and the measured motion go through
the same two functions, so they can only disagree when the motion does.

Pure Python: no numerical imports.
"""

from __future__ import annotations

import enum
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field, replace

from ..core import plugins as _plugins
from ..core.codes import K801, K803
from ..core.memo import table
from .ir import State

__all__ = [
    "DEFINITIONS",
    "REGISTRY",
    "Aggregate",
    "Descriptor",
    "Descriptors",
    "EpisodeValues",
    "Mismatch",
    "compare",
    "derive",
    "descriptor_problems",
    "every_descriptor",
    "qualify",
]


class Aggregate(enum.StrEnum):
    """How the values of several episodes make one descriptor."""

    COUNT = "count"
    MEDIAN = "median"
    MAX = "max"


@dataclass(frozen=True, slots=True)
class Descriptor:
    """One row of the table.

    Attributes:
        name: the name used in files, output and the API.
        unit: the unit values are given in (``""`` for counts).
        kind: the primitive kind whose episodes it is read from.
        key: the episode value it aggregates (unused for counts).
        aggregate: how episodes combine.
        ir_field: the field of the kind's IR node that sets it in the descriptor form, and
            ``scale``, the factor from the descriptor's unit to the IR's (degrees to
            radians); ``count`` for counts.
        rel_tol, abs_tol: a measured value matches a declared ``x`` within
            ``max(abs_tol, rel_tol * |x|)``.
        stronger: Part B of the study: states perceived more strongly as the value rises
            (+1) or falls (-1).
        no_effect: states on which the study found no clear perceived effect.
    """

    name: str
    unit: str
    kind: str
    key: str
    aggregate: Aggregate
    ir_field: str
    scale: float = 1.0
    rel_tol: float = 0.0
    abs_tol: float = 0.0
    stronger: Mapping[State, int] = field(default_factory=dict)
    no_effect: tuple[State, ...] = ()

    @property
    def is_count(self) -> bool:
        return self.aggregate is Aggregate.COUNT

    def tolerance(self, declared: float) -> float:
        """How far a measured value may be from ``declared`` and still match it."""
        return max(self.abs_tol, self.rel_tol * abs(declared))

    def matches(self, declared: float | None, measured: float | None) -> bool:
        if declared is None or measured is None:
            return declared is None and measured is None
        return abs(measured - declared) <= self.tolerance(declared) + 1e-12


_DEG = 0.017453292519943295  # radians per degree
_C, _Cu, _H, _F = State.CONFIDENT, State.CURIOUS, State.HESITANT, State.FEARFUL
_COUNT, _MEDIAN, _MAX = Aggregate.COUNT, Aggregate.MEDIAN, Aggregate.MAX

#: The eleven descriptors, in the order they are reported. Tolerances: counts exactly,
#: durations 2 % or 20 ms, distances 1 mm, angles 0.5 deg, accelerations 3 %, angular
#: velocities 2 % or 0.5 deg/s.
REGISTRY: dict[str, Descriptor] = {d.name: d for d in (
    Descriptor("approach_acceleration", "m/s^2", "approach", "peak_acceleration", _MAX, "a",
               rel_tol=0.03, stronger={_C: +1, _Cu: +1, _H: -1, _F: -1}),
    Descriptor("pause_count", "", "pause", "", _COUNT, "count", stronger={_F: +1}),
    Descriptor("pause_duration", "s", "pause", "duration", _MEDIAN, "duration",
               rel_tol=0.02, abs_tol=0.02, stronger={_C: -1, _H: +1, _F: +1},
               no_effect=(_Cu,)),
    Descriptor("retreat_count", "", "retreat", "", _COUNT, "count",
               stronger={_H: +1, _F: +1}),
    Descriptor("retreat_distance", "m", "retreat", "distance", _MEDIAN, "length",
               abs_tol=1e-3, stronger={_H: +1}),
    Descriptor("retreat_acceleration", "m/s^2", "retreat", "peak_acceleration", _MAX, "a",
               rel_tol=0.03, no_effect=(_H, _F)),
    Descriptor("horizontal_gaze", "deg", "gaze", "horizontal", _MAX, "angle", _DEG,
               abs_tol=0.5, stronger={_Cu: +1}),
    Descriptor("vertical_gaze", "deg", "gaze", "vertical", _MAX, "angle", _DEG,
               abs_tol=0.5, stronger={_Cu: +1}),
    Descriptor("tilt_angle", "deg", "tilt", "angle", _MEDIAN, "angle", _DEG, abs_tol=0.5,
               stronger={_Cu: +1}, no_effect=(_H,)),
    Descriptor("tilt_velocity", "deg/s", "tilt", "velocity", _MEDIAN, "v", _DEG,
               rel_tol=0.02, abs_tol=0.5, no_effect=(_Cu,)),
    Descriptor("shiver_amplitude", "deg", "shiver", "amplitude", _MAX, "amplitude", _DEG,
               abs_tol=0.5, no_effect=(_F,)),
)}


#: What each descriptor measures, in docs/model.md's words (its table of descriptors):
#: what an editor shows on hover.
DEFINITIONS = {
    "approach_acceleration": "peak magnitude of the end-effector's translational "
    "acceleration over all approach episodes (episodes in which the goal distance "
    "decreases)",
    "pause_count": "number of pauses: holds with every joint velocity zero",
    "pause_duration": "how long a pause lasts",
    "retreat_count": "number of retreat episodes (moving away from the goal) that start "
    "and end at a pause",
    "retreat_distance": "distance the end-effector covers in one retreat episode",
    "retreat_acceleration": "peak magnitude of the translational acceleration over the "
    "retreat episodes",
    "horizontal_gaze": "angle between `proj_H(g_0)` and `proj_H(g_i)`, i the pause that "
    "ends a gaze episode",
    "vertical_gaze": "the same angle in the vertical plane",
    "tilt_angle": "amplitude of the end-effector's roll about its forward (z) axis in one "
    "tilt episode",
    "tilt_velocity": "the tilt angle divided by the tilt episode's duration",
    "shiver_amplitude": "peak-to-peak amplitude of the fast oscillation of a redundant "
    "joint (one the rest of the motion does not use) about its axis",
}

#: The last table made, with the plugins it was made from (as in ``primitives.KINDS``).
_KEPT = table("aou_dsl.lang.descriptors.every", 1)


def _every() -> tuple[Mapping[str, Descriptor], Mapping[str, int], tuple]:
    """Every descriptor by name, each one's index, and the plugin problems; made again
    when the loaded plugins change (see :func:`aou_dsl.lang.primitives.plugin_problems`)."""
    from .primitives import BUILTIN_KINDS, KINDS, PluginProblem  # they import no descriptor

    got = _plugins.loaded()
    kept = _KEPT.get("every")
    if kept is not None and kept[0] is got:
        return kept[1], kept[2], kept[3]
    table = dict(REGISTRY)
    problems = []
    for p in _plugins.plugins():
        given = p.part("descriptors")
        if given is None or p.name not in KINDS or p.name in BUILTIN_KINDS:
            continue  # no descriptors, or its kind is not used (said by the kinds)
        try:
            rows = list(given)  # type: ignore[call-overload]
        except TypeError:
            rows = [given]
        for d in rows:
            why = _problem_of(d, p.name, table)
            if why is not None:
                problems.append(PluginProblem(why[0], p.name, p.source, why[1]))
            else:
                table[d.name] = d
    out = (table, {name: i for i, name in enumerate(table)}, tuple(problems))
    _KEPT.put("every", (got, *out))
    return out


def _problem_of(d: object, kind: str, taken: Mapping[str, Descriptor]) -> tuple[str, str] | None:
    """Why ``d`` (one of plugin ``kind``'s descriptors) cannot be used: (code, why)."""
    if not isinstance(d, Descriptor):
        return K801, f"its `descriptors` part holds a {type(d).__name__}, not a Descriptor"
    if d.kind != kind:
        return K801, f"its descriptor `{d.name}` is read from `{d.kind}`, not from `{kind}`"
    if not d.is_count and not d.key:
        return K801, f"its descriptor `{d.name}` names no episode value"
    if d.name in taken:
        return K803, f"its descriptor `{d.name}` is already aou's or an earlier plugin's"
    return None


def every_descriptor() -> Mapping[str, Descriptor]:
    """Every descriptor by name: :data:`REGISTRY`'s eleven, then those of each loaded
    plugin (its ``descriptors`` part, :class:`Descriptor` records read from its own
    kind). A plugin's descriptor that is malformed (K801) or whose name is taken (K803)
    is left out; :func:`descriptor_problems` says which and why."""
    return _every()[0]


def descriptor_problems() -> tuple:
    """Why plugins' descriptors are left out (``PluginProblem`` records, K801/K803)."""
    return _every()[2]


class Descriptors(Mapping[str, float | int | None]):
    """The values of one behaviour or trajectory, frozen; ``None`` for an absent
    primitive. A mapping from name to value, in :func:`every_descriptor`'s order (the
    eleven of :data:`REGISTRY`, then the plugins')."""

    __slots__ = ("_index", "_values")

    def __init__(self, values: Mapping[str, float | int | None] | None = None, **kw):
        given = dict(values or {}, **kw)
        every, self._index, _ = _every()
        unknown = set(given) - set(every)
        if unknown:
            raise KeyError(f"unknown descriptor(s): {', '.join(sorted(unknown))}")
        self._values = tuple(given.get(name) for name in every)

    def __getitem__(self, name: str) -> float | int | None:
        return self._values[self._index[name]]

    def __iter__(self) -> Iterator[str]:
        return iter(self._index)

    def __len__(self) -> int:
        return len(self._index)

    def __hash__(self) -> int:
        return hash(self._values)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Descriptors):
            return list(self._index) == list(other._index) and self._values == other._values
        return isinstance(other, Mapping) and dict(self) == dict(other)

    def __repr__(self) -> str:
        shown = ", ".join(f"{k}={v!r}" for k, v in self.items() if v is not None)
        return f"Descriptors({shown})"

    def to_json(self, digits: int = 6) -> dict[str, float | int | None]:
        return {k: (round(v, digits) if isinstance(v, float) else v) for k, v in self.items()}


@dataclass(frozen=True, slots=True)
class EpisodeValues:
    """One episode as the descriptors see it: its kind, when it ran, and its values.

    ``values`` keys are the :attr:`Descriptor.key` of the kind's descriptors (e.g. a
    retreat's ``distance`` [m] and ``peak_acceleration`` [m/s^2], a gaze's
    ``horizontal`` and ``vertical`` angle from the initial line of sight [deg] at its
    end, only for the planes it moved in). ``counts`` is set by :func:`qualify`.
    """

    kind: str
    t_start: float = 0.0
    t_end: float = 0.0
    values: Mapping[str, float] = field(default_factory=dict)
    counts: bool = True

    @property
    def duration(self) -> float:
        return self.t_end - self.t_start

    def to_json(self) -> dict:
        return {"kind": self.kind, "t_start": round(self.t_start, 4),
                "t_end": round(self.t_end, 4), "counts": self.counts,
                **{k: round(v, 6) for k, v in self.values.items()}}


def qualify(episodes: Iterable[EpisodeValues]) -> list[EpisodeValues]:
    """The episodes as the definitions read them: touching pauses merged into one (their
    durations added), and every episode marked whether it counts: whether the episodes
    next to it are those its kind needs (:attr:`~.primitives.kind.Kind.needs`; none for
    a kind no registry knows)."""
    # imported here: a plugin's kinds, loaded with the registry, may read this module
    from .primitives import KINDS, PAUSE

    merged: list[EpisodeValues] = []
    for e in episodes:
        last = merged[-1] if merged else None
        if e.kind == PAUSE and last is not None and last.kind == PAUSE:
            duration = last.values.get("duration", 0.0) + e.values.get("duration", 0.0)
            merged[-1] = replace(last, t_end=e.t_end, values={"duration": duration})
        else:
            merged.append(e)
    out = []
    for i, e in enumerate(merged):
        kind = KINDS.get(e.kind)
        if kind is not None and kind.needs.around:
            before = merged[i - 1].kind if i > 0 else None
            after = merged[i + 1].kind if i + 1 < len(merged) else None
            e = replace(e, counts=kind.needs.met(before, after))
        out.append(e)
    return out


def _aggregate(d: Descriptor, episodes: list[EpisodeValues]) -> float | int | None:
    mine = [e for e in episodes if e.kind == d.kind and e.counts]
    if d.is_count:
        return len(mine)
    values = [e.values[d.key] for e in mine if d.key in e.values]
    if not values:
        return None
    if d.aggregate is Aggregate.MAX:
        return max(values)
    values.sort()  # the median, without `statistics` (it brings random and fractions)
    mid = len(values) // 2
    return float(values[mid] if len(values) % 2 else (values[mid - 1] + values[mid]) / 2)


def derive(episodes: Iterable[EpisodeValues]) -> Descriptors:
    """The eleven descriptors of a list of episodes, in time order: declared (a laid-out
    timeline) and measured (episodes found in a trajectory) alike."""
    eps = qualify(episodes)
    return Descriptors({name: _aggregate(d, eps) for name, d in every_descriptor().items()})


def spread(episodes: Iterable[EpisodeValues]) -> dict[str, list[float]]:
    """Per non-count descriptor, the values of the episodes it aggregates (for reports
    of unequal episodes)."""
    eps = qualify(episodes)
    out: dict[str, list[float]] = {}
    for name, d in every_descriptor().items():
        if not d.is_count:
            vals = [e.values[d.key] for e in eps
                    if e.kind == d.kind and e.counts and d.key in e.values]
            if vals:
                out[name] = vals
    return out


@dataclass(frozen=True, slots=True)
class Mismatch:
    """A descriptor whose measured value misses the declared one."""

    name: str
    declared: float | int | None
    measured: float | int | None


def compare(declared: Mapping[str, float | int | None],
            measured: Mapping[str, float | int | None]) -> list[Mismatch]:
    """The descriptors whose measured value misses the declared one by more than its
    tolerance. Absent must be measured absent, and present present; a count of zero and
    an absent count are the same."""
    out = []
    for name, d in every_descriptor().items():
        want, got = declared.get(name), measured.get(name)
        if d.is_count:
            want, got = want or 0, got or 0
        if not d.matches(want, got):
            out.append(Mismatch(name, want, got))
    return out
