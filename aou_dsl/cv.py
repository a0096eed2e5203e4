"""The Commitment-Vigilance model (MODEL.md s1-3) and the inference of (C, V) from motion.

Three things live here:

1. :func:`effort_to_cv`: equations 1 and 2, ``C = -c1 W - c2 T``, ``V = v1 S - v2 F``.
2. :func:`classify`: a point of the plane belongs to the nearest canonical state
   (Euclidean), ties broken in Table I's order.
3. :func:`infer`: a (C, V) point from a behaviour's *composition*, i.e. from its
   descriptor values alone, so that ``aouc lint`` (from a file) and ``aouc measure``
   (from a recorded motion) place motion on the plane the same way. docs/cv-model.md
   explains the formula; in short, each primitive contributes a saturating evidence
   term ``1 - exp(-x / x_ref)`` or ``x / (x + x_ref)`` in [0, 1)::

       C = clip(b + k_a D - k_x Rx - k_v Rv)
       V = clip(-1 + k_p P + k_e X + k_s S)

   D approach drive (approach acceleration), Rx retreat extent (count x distance),
   Rv retreat vigour (retreat acceleration), P stillness (count x pause duration),
   X exploration (gaze and tilt angle swept), S tremor (shiver amplitude x count).
   Every term is monotone in its descriptors, so more or longer retreats never raise C,
   a higher approach acceleration never lowers C, and adding pauses, gaze, tilt or
   shiver never lowers V.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .ir import Behaviour, Effort, State

__all__ = [
    "CANONICAL",
    "Composition",
    "Contribution",
    "CVPoint",
    "CVWeights",
    "DEFAULT_WEIGHTS",
    "INFERENCE",
    "classify",
    "composition_of",
    "effort_to_cv",
    "infer",
]

#: MODEL.md Table I: state -> (W, T, S, F), in the table's order.
CANONICAL_EFFORT: dict[State, tuple[float, float, float, float]] = {
    State.CONFIDENT: (-1, -1, -1, +1),
    State.CURIOUS: (-1, -1, +1, -1),
    State.HESITANT: (+1, -1, +1, +1),
    State.FEARFUL: (+1, +1, +1, -1),
    State.INACTIVE: (+1, +1, -1, +1),
}

#: MODEL.md Table I: state -> canonical (C, V).
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
    """Equations 1 and 2 of MODEL.md. ``effort`` is (W, T, S, F), each in [-1, 1]."""
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
    """The descriptors that drive the inference; zero/None for absent primitives.

    Units: accelerations [m/s^2], distances [m], durations [s], angles [deg].
    """

    approach_acceleration: float | None = None
    pause_count: int = 0
    pause_duration: float = 0.0
    retreat_count: int = 0
    retreat_distance: float = 0.0
    retreat_acceleration: float = 0.0
    gaze_swept: float = 0.0  # total |angle| of gaze episodes, both planes [deg]
    tilt_swept: float = 0.0  # total |angle| of tilt episodes [deg]
    shiver_amplitude: float = 0.0
    shiver_count: int = 0


@dataclass(frozen=True, slots=True)
class InferenceParams:
    """Reference scales and gains of the inference (docs/cv-model.md). Chosen so the five
    study behaviours land in their own states with margin; see tests/test_cv.py."""

    a_ref: float = 0.05  # m/s^2: approach drive is 1/2 at this acceleration
    d_ref: float = 0.10  # m: retreat extent 1 - 1/e at this total distance
    ar_ref: float = 0.5  # m/s^2: retreat vigour is 1/2 at this acceleration
    p_ref: float = 5.0  # s: stillness 1 - 1/e at this total pause time
    e_ref: float = 30.0  # deg: exploration 1 - 1/e at this total angle swept
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
    """How much one primitive moves the point: ``dC``, ``dV`` before clipping."""

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
    """The (C, V) point a composition expresses, and each primitive's pull on it."""
    p = params
    contrib: list[Contribution] = []
    if comp.approach_acceleration:
        contrib.append(Contribution(
            "approach", p.k_drive * _ratio(comp.approach_acceleration, p.a_ref), 0.0))
    if comp.retreat_count:
        extent = _sat(comp.retreat_count * comp.retreat_distance, p.d_ref)
        vigour = _ratio(comp.retreat_acceleration, p.ar_ref)
        contrib.append(Contribution("retreat", -p.k_extent * extent - p.k_vigour * vigour, 0.0))
    if comp.pause_count:
        contrib.append(Contribution(
            "pause", 0.0, p.k_still * _sat(comp.pause_count * comp.pause_duration, p.p_ref)))
    if comp.gaze_swept or comp.tilt_swept:
        contrib.append(Contribution(
            "gaze/tilt", 0.0, p.k_explore * _sat(comp.gaze_swept + comp.tilt_swept, p.e_ref)))
    if comp.shiver_count:
        contrib.append(Contribution(
            "shiver", 0.0,
            p.k_tremor * _sat(comp.shiver_count * comp.shiver_amplitude, p.s_ref)))
    c = p.bias + sum(x.dC for x in contrib)
    v = -1.0 + sum(x.dV for x in contrib)
    return CVPoint(max(-1.0, min(1.0, c)), max(-1.0, min(1.0, v))), contrib


def composition_of(b: Behaviour) -> Composition:
    """The composition a behaviour declares (descriptor or sequence form).

    In a sequence, counts add up, and durations, distances and accelerations are the
    largest of their kind (the model assumes equal episodes; lint is not the place to
    average them).
    """
    kw: dict = {"pause_count": 0, "retreat_count": 0, "shiver_count": 0}
    acc = None
    pause_d = retreat_d = retreat_a = gaze = tilt = shiver = 0.0
    for prim in b.primitives:
        n = prim.count
        if prim.kind == "approach":
            acc = max(acc or 0.0, prim.a)
        elif prim.kind == "pause":
            kw["pause_count"] += n
            pause_d = max(pause_d, prim.duration)
        elif prim.kind == "retreat":
            kw["retreat_count"] += n
            retreat_d = max(retreat_d, abs(prim.length))
            retreat_a = max(retreat_a, prim.a)
        elif prim.kind == "gaze":
            gaze += n * abs(math.degrees(prim.angle))
        elif prim.kind == "tilt":
            tilt += n * abs(math.degrees(prim.angle))
        elif prim.kind == "shiver":
            kw["shiver_count"] += n
            shiver = max(shiver, math.degrees(prim.amplitude))
    return Composition(
        approach_acceleration=acc,
        pause_duration=pause_d,
        retreat_distance=retreat_d,
        retreat_acceleration=retreat_a,
        gaze_swept=gaze,
        tilt_swept=tilt,
        shiver_amplitude=shiver,
        **kw,
    )
