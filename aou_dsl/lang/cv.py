"""The Commitment-Vigilance model (docs/model.md) and the inference of (C, V) from motion.

Three things live here:

1. :func:`effort_to_cv`: equations 1 and 2, ``C = -c1 W - c2 T``, ``V = v1 S - v2 F``.
2. :func:`classify`: a point of the plane belongs to the nearest canonical state
   (Euclidean), ties broken in Table I's order.
3. :func:`infer`: a (C, V) point from a behaviour's *composition*: what its episodes
   do, so that ``aouc lint`` (from a file) and ``aouc measure`` (from a recorded motion)
   place motion on the plane the same way. docs/cv-model.md explains the formula; in
   short, each primitive kind feeds evidence channels (its ``evidence`` table), and
   each channel gives a saturating term ``1 - exp(-x / x_ref)`` or ``x / (x + x_ref)``
   in [0, 1)::

       C = clip(b + k_a D - k_x Rx - k_v Rv)
       V = clip(-1 + k_p P + k_e X + k_s S)

   D drive (peak approach acceleration), Rx retreat extent (total distance retreated),
   Rv retreat vigour (peak retreat acceleration), P stillness (total pause time),
   X exploration (total gaze and tilt angle), S tremor (total shiver amplitude).
   Every term is monotone in its evidence, so more or longer retreats never raise C,
   a higher approach acceleration never lowers C, and adding pauses, gaze, tilt or
   shiver never lowers V.

A kind from a plugin takes part the same way, with no change here: its ``evidence``
table names channels of :data:`CHANNELS` (and the episode value that feeds each, added
up or the largest), and :func:`evidence_problem` refuses a table that names anything
else (the plugin is then not loaded: K801).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from .evidence import CHANNELS, evidence_problem
from .ir import Effort, State
from .primitives import APPROACH, GAZE, PAUSE, RETREAT, SHIVER, TILT

__all__ = [
    "CANONICAL",
    "CHANNELS",
    "Composition",
    "Contribution",
    "CVPoint",
    "CVWeights",
    "DEFAULT_WEIGHTS",
    "INFERENCE",
    "classify",
    "composition",
    "effort_to_cv",
    "evidence_problem",
    "infer",
    "missing_descriptors",
]

#: Table I of the model: state -> (W, T, S, F), in the table's order.
CANONICAL_EFFORT: dict[State, tuple[float, float, float, float]] = {
    State.CONFIDENT: (-1, -1, -1, +1),
    State.CURIOUS: (-1, -1, +1, -1),
    State.HESITANT: (+1, -1, +1, +1),
    State.FEARFUL: (+1, +1, +1, -1),
    State.INACTIVE: (+1, +1, -1, +1),
}

#: Table I of the model: state -> canonical (C, V).
CANONICAL: dict[State, tuple[float, float]] = {
    State.CONFIDENT: (1.0, -1.0),
    State.CURIOUS: (1.0, 1.0),
    State.HESITANT: (0.0, 0.0),
    State.FEARFUL: (-1.0, 1.0),
    State.INACTIVE: (-1.0, -1.0),
}


@dataclass(frozen=True, slots=True)
class CVWeights:
    """The weights of equations 1-2; all positive. 1/2 each maps Table I exactly."""

    c1: float = 0.5
    c2: float = 0.5
    v1: float = 0.5
    v2: float = 0.5

    def __post_init__(self) -> None:
        if min(self.c1, self.c2, self.v1, self.v2) <= 0:
            raise ValueError("C-V weights must be positive")


@dataclass(frozen=True, slots=True)
class CVPoint:
    C: float
    V: float

    @property
    def state(self) -> State:
        return classify(self.C, self.V)

    def to_json(self) -> dict:
        return {"C": round(self.C, 4), "V": round(self.V, 4), "state": self.state.value}


DEFAULT_WEIGHTS = CVWeights()


def effort_to_cv(effort: Effort | tuple[float, float, float, float],
                 weights: CVWeights = DEFAULT_WEIGHTS) -> CVPoint:
    """Equations 1 and 2 of the model. ``effort`` is (W, T, S, F), each in [-1, 1]."""
    if isinstance(effort, Effort):
        w, t, s, f = effort.W, effort.T, effort.S, effort.F
    else:
        w, t, s, f = effort
    return CVPoint(-weights.c1 * w - weights.c2 * t, weights.v1 * s - weights.v2 * f)


def classify(c: float, v: float) -> State:
    """The canonical state nearest to (c, v); ties go to the earlier state of Table I."""
    best, best_d = State.CONFIDENT, math.inf
    for state, (cc, vv) in CANONICAL.items():
        d = math.hypot(c - cc, v - vv)
        if d < best_d - 1e-12:
            best, best_d = state, d
    return best


# --- inference from composition -----------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Composition:
    """The evidence a behaviour's episodes give, per channel (zero when absent).

    Attributes:
        drive: peak approach acceleration [m/s^2].
        extent: total distance retreated [m].
        vigour: peak retreat acceleration [m/s^2].
        stillness: total pause time [s].
        exploration: total angle of gazes (from the initial line of sight) and tilts [deg].
        tremor: total shiver amplitude [deg].
    """

    drive: float = 0.0
    extent: float = 0.0
    vigour: float = 0.0
    stillness: float = 0.0
    exploration: float = 0.0
    tremor: float = 0.0




@dataclass(frozen=True, slots=True)
class InferenceParams:
    """Reference scales and gains of the inference (docs/cv-model.md). Chosen so the five
    study behaviours land in their own states with margin (the tests check it)."""

    a_ref: float = 0.05  # m/s^2: drive is 1/2 at this acceleration
    d_ref: float = 0.10  # m: retreat extent 1 - 1/e at this total distance
    ar_ref: float = 0.5  # m/s^2: retreat vigour is 1/2 at this acceleration
    p_ref: float = 5.0  # s: stillness 1 - 1/e at this total pause time
    e_ref: float = 30.0  # deg: exploration 1 - 1/e at this total angle
    s_ref: float = 5.0  # deg: tremor 1 - 1/e at this total shiver amplitude
    bias: float = -0.8
    k_drive: float = 2.7
    k_extent: float = 0.3
    k_vigour: float = 1.54
    k_still: float = 1.2
    k_explore: float = 2.0
    k_tremor: float = 2.0


INFERENCE = InferenceParams()


@dataclass(frozen=True, slots=True)
class Contribution:
    """How much one evidence channel moves the point: ``dC``, ``dV`` before clipping."""

    primitive: str
    dC: float
    dV: float


def _sat(x: float, ref: float) -> float:
    return 1.0 - math.exp(-max(x, 0.0) / ref)


def _ratio(x: float, ref: float) -> float:
    x = max(x, 0.0)
    return x / (x + ref)


def infer(comp: Composition, params: InferenceParams = INFERENCE
          ) -> tuple[CVPoint, list[Contribution]]:
    """The (C, V) point a composition expresses, and each channel's pull on it."""
    p = params
    terms = (
        (APPROACH, comp.drive, p.k_drive * _ratio(comp.drive, p.a_ref), 0.0),
        (f"{RETREAT} extent", comp.extent, -p.k_extent * _sat(comp.extent, p.d_ref), 0.0),
        (f"{RETREAT} vigour", comp.vigour, -p.k_vigour * _ratio(comp.vigour, p.ar_ref), 0.0),
        (PAUSE, comp.stillness, 0.0, p.k_still * _sat(comp.stillness, p.p_ref)),
        (f"{GAZE}/{TILT}", comp.exploration, 0.0,
         p.k_explore * _sat(comp.exploration, p.e_ref)),
        (SHIVER, comp.tremor, 0.0, p.k_tremor * _sat(comp.tremor, p.s_ref)),
    )
    contrib = [Contribution(name, dc, dv) for name, x, dc, dv in terms if x > 0]
    c = p.bias + sum(x.dC for x in contrib)
    v = -1.0 + sum(x.dV for x in contrib)
    return CVPoint(max(-1.0, min(1.0, c)), max(-1.0, min(1.0, v))), contrib


def composition(episodes: Iterable) -> Composition:
    """The evidence of a list of :class:`~aou_dsl.lang.descriptors.EpisodeValues` (declared or
    measured): each kind's ``evidence`` table says which value feeds which channel and
    whether its episodes add up or the largest counts (a plugin kind's table too: its
    channels were checked when it loaded). An episode is read by what it does: a
    negative approach is a retreat."""
    from .primitives import KINDS

    amounts: dict[str, float] = {}
    for e in episodes:
        kind = KINDS.get(e.kind)
        for channel, (key, how) in (kind.evidence.items() if kind else ()):
            x = float(e.values.get(key, 0.0))
            old = amounts.get(channel, 0.0)
            amounts[channel] = old + x if how == "sum" else max(old, x)
    return Composition(**amounts)


def missing_descriptors(goal: object) -> tuple[str, ...]:
    """The descriptors a C-V point inferred from measured motion could not use, given
    the motion's ``goal`` (None: unknown): the gazes are bearings of the goal, so without
    one they are unknown and their exploration is missing from the point. Empty for a
    complete measurement."""
    if goal is not None:
        return ()
    from .descriptors import every_descriptor

    return tuple(name for name, d in every_descriptor().items() if d.kind == GAZE)
