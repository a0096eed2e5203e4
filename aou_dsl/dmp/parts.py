"""How each primitive kind becomes a part of a DMP folder: one registry keyed by kind.

A kind's episode becomes one of three shapes of part (:class:`Shape`): a *move* (a
``CartesianDMP`` of the hand's pose from rest to rest, fitted to the episode: approach,
retreat, gaze, tilt), a *hold* of the pose (pause) or an *oscillation* of the robot's
shiver joint (shiver). The registry says, for every kind, its shape, which DMP parameter
controls each of its descriptors (the manifest's ``parameters``, by episode key, ``""``
for a count), how a rollout to a new goal ``s`` and tempo ``k`` moves each descriptor
(:class:`Scaling`), and which descriptors an intensity moves without a re-plan.

A plugin kind takes part through its ``dmp`` part (:class:`DmpKindPart`): an object with
a ``shape`` and ``parameters``, and optionally ``scaling`` and ``intensity``. A plugin
kind without one cannot be exported (:func:`dmp_kind` raises K802, naming the kind, the
plugin and the stage); a part that does not have that form is K801. Reading a ``.dmp``
folder only looks a kind's name up here: nothing named in a file is imported, the plugin
parts come from the installed packages' metadata (:mod:`aou_dsl.core.plugins`).

Pure Python: the command line's parser reads :func:`pinnable` from it.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

from ..core import plugins as _plugins
from ..core.codes import K801, K802
from ..core.diagnostics import AouError, Severity, Span, diag
from ..lang.primitives import APPROACH, GAZE, PAUSE, RETREAT, SHIVER, TILT

__all__ = ["LAYER", "PARAMETER_LINES", "DmpKind", "DmpKindPart", "Scaling", "Shape",
           "descriptor_name", "dmp_kind", "dmp_kinds", "moves", "parameter_lines",
           "pinnable", "scaled", "shape_of"]

#: The plugin part this registry reads.
LAYER = "dmp"


class Shape(enum.StrEnum):
    """What a kind's episode becomes in a DMP folder."""

    #: A ``CartesianDMP`` of the hand's pose from rest to rest (a part file).
    MOVE = "move"
    #: The pose held for the episode's duration (no part file).
    HOLD = "hold"
    #: An oscillation of the shiver joint: ``amplitude`` [deg], ``frequency`` [Hz],
    #: ``cycles`` in the part's values (no part file).
    OSCILLATION = "oscillation"


class Scaling(enum.StrEnum):
    """How a rollout to a goal ``s`` times as far and a tempo ``k`` (durations times
    ``k``) moves a descriptor from its measured value; ``f`` is the intensity's factor."""

    #: A peak acceleration: ``s f / k^2`` (``f`` alone when pinned).
    PEAK = "peak"
    #: A duration: ``k f``.
    TIME = "time"
    #: A distance: ``s``.
    SPACE = "space"
    #: A velocity: ``1 / k``.
    RATE = "rate"
    #: An amplitude the intensity alone moves: ``f``.
    KEPT = "kept"


@runtime_checkable
class DmpKindPart(Protocol):
    """What a plugin's ``dmp`` part gives (a module, an instance or a class will do).

    Attributes:
        shape: ``"move"`` (moves like a line-of-sight move: a CartesianDMP fitted to the
            episode, like a retreat), ``"hold"`` or ``"oscillation"`` (:class:`Shape`).
        parameters: the manifest's text of which DMP parameter controls each of the
            kind's descriptors, by episode key (``""`` for the count), e.g.
            ``{"distance": "start_y/goal_y and forcing weights (amplitude scaling)"}``.

    Optional attributes (read with a default): ``scaling``, a mapping of episode key to a
    :class:`Scaling` word (``"peak"``, ``"time"``, ``"space"``, ``"rate"``, ``"kept"``;
    default: none, the descriptor is predicted unchanged), and ``intensity``, the episode
    keys an intensity moves without a re-plan (default: none). A ``"peak"`` key makes the
    kind a choice of ``aouc dmp roll --pin``.
    """

    shape: str
    parameters: Mapping[str, str]


@dataclass(frozen=True)
class DmpKind:
    """One kind's entry (the registry's form of a :class:`DmpKindPart`)."""

    shape: Shape
    parameters: Mapping[str, str] = field(default_factory=dict)
    scaling: Mapping[str, Scaling] = field(default_factory=dict)
    intensity: frozenset[str] = frozenset()


_A, _D, _C = "peak_acceleration", "duration", ""
_PARTS = "the parts (fixed)"
_AROUND = "rotation of start_y/goal_y and weights about the goal (kept)"

#: Which DMP parameter controls each built-in descriptor (docs/dmp.md, the scaling
#: rules), by its kind and episode key, in the manifest's order.
PARAMETER_LINES: tuple[tuple[tuple[str, str], str], ...] = (
    ((APPROACH, _A), "execution_time_ of each approach (peak ~ amplitude / time^2); "
                     "forcing weights scaled with the amplitude"),
    ((RETREAT, _A), "execution_time_ of each retreat, as above"),
    ((RETREAT, "distance"), "start_y/goal_y and forcing weights (amplitude scaling)"),
    ((PAUSE, _D), "the hold's duration"),
    ((PAUSE, _C), _PARTS),
    ((RETREAT, _C), _PARTS),
    ((GAZE, "horizontal"), _AROUND),
    ((GAZE, "vertical"), _AROUND),
    ((TILT, "angle"), "the orientation goal_y (kept)"),
    ((TILT, "velocity"), "execution_time_ of each tilt"),
    ((SHIVER, "amplitude"), "the oscillation's amplitude"),
)


def _lines(kind: str) -> dict[str, str]:
    return {key: text for (k, key), text in PARAMETER_LINES if k == kind}


#: The built-in kinds, moves first (the order the schema names them in).
BUILTIN: Mapping[str, DmpKind] = {
    APPROACH: DmpKind(Shape.MOVE, _lines(APPROACH), {_A: Scaling.PEAK}, frozenset({_A})),
    RETREAT: DmpKind(Shape.MOVE, _lines(RETREAT),
                     {_A: Scaling.PEAK, "distance": Scaling.SPACE}, frozenset({_A})),
    GAZE: DmpKind(Shape.MOVE, _lines(GAZE)),
    TILT: DmpKind(Shape.MOVE, _lines(TILT), {"velocity": Scaling.RATE}),
    PAUSE: DmpKind(Shape.HOLD, _lines(PAUSE), {_D: Scaling.TIME}, frozenset({_D})),
    SHIVER: DmpKind(Shape.OSCILLATION, _lines(SHIVER), {"amplitude": Scaling.KEPT},
                    frozenset({"amplitude"})),
}


class MalformedPart(ValueError):
    """A plugin's ``dmp`` part that is not a :class:`DmpKindPart` (why, as text)."""


def _text_map(x: object, what: str) -> dict[str, str]:
    if not isinstance(x, Mapping) or not all(isinstance(k, str) and isinstance(v, str)
                                              for k, v in x.items()):
        raise MalformedPart(f"its `{what}` is not a mapping of texts by episode key")
    return dict(x)


def from_part(part: object) -> DmpKind:
    """The registry entry of a plugin's ``dmp`` part; :class:`MalformedPart` when it is
    not one."""
    try:
        shape = Shape(str(getattr(part, "shape", None)))
    except ValueError:
        raise MalformedPart(f"its `shape` is {getattr(part, 'shape', None)!r}, not one of "
                            f"{', '.join(s.value for s in Shape)}") from None
    params = _text_map(getattr(part, "parameters", None), "parameters")
    try:
        scaling = {k: Scaling(v) for k, v in
                   _text_map(getattr(part, "scaling", None) or {}, "scaling").items()}
    except ValueError:
        raise MalformedPart("its `scaling` gives a word that is not one of "
                            f"{', '.join(s.value for s in Scaling)}") from None
    keys = getattr(part, "intensity", None) or ()
    if isinstance(keys, str) or not all(isinstance(k, str) for k in keys):
        raise MalformedPart("its `intensity` is not a collection of episode keys")
    return DmpKind(shape, params, scaling, frozenset(keys))


def _plugin(kind: str) -> _plugins.Plugin | None:
    return next((p for p in _plugins.plugins() if p.name == kind), None)


def dmp_kinds() -> dict[str, DmpKind]:
    """Every kind a DMP folder may hold: the built-ins, then each loaded plugin's kind
    whose ``dmp`` part is well formed (a clash with a built-in keeps the built-in)."""
    out = dict(BUILTIN)
    for p in _plugins.plugins():
        part = p.part(LAYER)
        if p.name in out or part is None:
            continue
        try:
            out[p.name] = from_part(part)
        except MalformedPart:
            continue  # dmp_kind says why when a file uses it
    return out


def dmp_kind(kind: str, span: Span, stage: str = "the DMP export") -> DmpKind | None:
    """The entry of ``kind``; None for a kind neither built in nor a plugin's.

    Raises:
        AouError: K802 for a plugin kind whose plugin gives no ``dmp`` part, K801 for one
            whose part is malformed (both naming the kind, the plugin and ``stage``).
    """
    found = BUILTIN.get(kind)
    if found is not None:
        return found
    p = _plugin(kind)
    if p is None:
        return None
    part = p.part(LAYER)
    if part is None:
        raise AouError(diag(K802, f"the kind `{kind}` comes from the plugin {p.source}, "
                            f"which gives no `{LAYER}` part: {stage} cannot use it", span,
                            hint="leave the kind out of this file, or use a version of "
                            "the plugin that gives a DMP part"))
    try:
        return from_part(part)
    except MalformedPart as exc:
        raise AouError(diag(K801, f"the kind `{kind}` comes from the plugin {p.source}, "
                            f"whose `{LAYER}` part cannot be used ({exc}): {stage} cannot "
                            "use it", span, severity=Severity.ERROR)) from None


def parameter_lines() -> list[tuple[tuple[str, str], str]]:
    """Every ``((kind, episode key), text)`` line of the manifest's ``parameters``: the
    built-ins' in their order, then the plugin kinds'."""
    out = list(PARAMETER_LINES)
    for name, entry in dmp_kinds().items():
        if name not in BUILTIN:
            out.extend(((name, key), text) for key, text in entry.parameters.items())
    return out


def moves() -> tuple[str, ...]:
    """The kinds whose episodes become a CartesianDMP (:attr:`Shape.MOVE`)."""
    return tuple(name for name, entry in dmp_kinds().items() if entry.shape is Shape.MOVE)


def shape_of(kind: str) -> Shape | None:
    """The shape of ``kind``'s parts; None for a kind no DMP folder holds."""
    entry = dmp_kinds().get(kind)
    return entry.shape if entry is not None else None


def descriptor_name(kind: str, key: str) -> str | None:
    """The name of the descriptor read from ``kind`` episodes by ``key`` (``""``: the
    count), or None when there is none (a plugin's scaling of a key it does not report)."""
    from ..lang.descriptors import every_descriptor

    return next((d.name for d in every_descriptor().values() if d.kind == kind
                 and (d.key == key or (d.is_count and key == ""))), None)


def scaled() -> list[tuple[str, str, Scaling]]:
    """Every ``(kind, descriptor name, scaling)`` a rollout predicts, in the registry's
    order (scalings of keys without a descriptor are left out)."""
    return [(kind, name, how) for kind, entry in dmp_kinds().items()
            for key, how in entry.scaling.items()
            if (name := descriptor_name(kind, key)) is not None]


def pinnable() -> tuple[str, ...]:
    """The kinds whose peak acceleration a rollout may keep (``aouc dmp roll --pin``)."""
    return tuple(dict.fromkeys(kind for kind, _name, how in scaled() if how is Scaling.PEAK))
