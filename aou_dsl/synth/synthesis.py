"""Synthesis: a state (or a C-V point) and an intensity -> a ``.aou`` file that expresses it.

The mapping (docs/synthesis.md):

- **Anchors.** At intensity :data:`STUDY_INTENSITY` (0.5) a state's file is the study's
  stimulus for it (:data:`STUDY_SOURCE`, the statements of ``behaviours/*.aou``), value
  for value. Inactive, which the study did not show, is the shipped hold.
- **Directions.** Each descriptor the study found to change how strongly a state is
  perceived (``REGISTRY[name].stronger``) moves that way as the intensity rises from 0
  to 1: a value ``x0`` becomes ``x0 * r ** (d * (2 I - 1))`` (``d`` = +1 or -1, the span
  ``r`` from :data:`SPANS`), a count ``n0 + d * round(k * (2 I - 1))``. An exploration the
  stimulus lacks (curious: vertical gaze, tilt) appears above 0.5 and grows to its span
  at 1. Descriptors with no clear effect, or not varied, keep the study's value.
- **Blends.** A C-V point between the canonical states blends the compositions of the
  three states of its triangle (hesitant at the centre and two neighbouring corners), with
  barycentric weights; if the blend does not read as the point's nearest state, the
  weights are sharpened toward it until it does.
- **The robot.** Values are fitted to the arm (:mod:`aou_dsl.synth.arm_fit`): accelerations
  below what its joints reach on this reach, a shiver and a tilt within the limits of the
  joint that rolls the hand; an intensity too weak to read as its state on that arm is
  raised to the weakest one that does.

Descriptors are reached through ``REGISTRY`` (their kind, episode key and IR field), the
way ``aouc variants`` rewrites a statement. Every value in the file carries a comment
saying where it came from.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

from ..core.codes import C304, C305, C308, C309, C311, I504
from ..core.diagnostics import AouError, Diagnostic, Span, diag
from ..core.memo import Keyed, cached
from ..fit.refusals import AccelerationShort
from ..fit.rounding import significant
from ..fit.search import DIGITS
from ..lang.cv import CANONICAL, classify
from ..lang.descriptors import Descriptor
from ..lang.ir import State
from ..lang.linter import lint_source
from ..lang.primitives import PAUSE, RETREAT
from .arm_fit import Limits, fit, fit_limits
from .kind_recipes import descriptors, kind_recipes, span_of, spans
from .recipe import Recipe, descriptor, slot_of
from .writer import render

if TYPE_CHECKING:
    from ..driver.builder import BuildResult
    from ..driver.session import Session

__all__ = ["SPANS", "STUDY_INTENSITY", "STUDY_SOURCE", "blend_weights", "compiled", "recipe",
           "study", "synthesize"]

#: The intensity whose file is the study's stimulus, value for value.
STUDY_INTENSITY = 0.5
#: An exploration that grows from nothing is written once it reaches this angle [deg].
MIN_GROWN_ANGLE = 5.0
#: Episodes of an exploration that grows from nothing: one way, then the other.
GROWN_COUNT = 2
_WHERE = Span.whole_file("<synth>")

#: The study's stimuli (the statements of behaviours/*.aou) and the shipped inactive
#: hold. ``x0`` marks an exploration the stimulus lacks but the study found to strengthen
#: the state (its angle is set by :data:`SPANS`; its speed is the language's default).
STUDY_SOURCE: dict[State, str] = {
    State.CONFIDENT: "approach a=0.1\npause 1.67s\n",
    State.CURIOUS: ("approach a=0.09\npause 1.25s x3\ngaze horizontal 20deg x2\n"
                    "gaze vertical 1deg x0\ntilt 1deg x0\n"),
    State.HESITANT: "approach a=0.05\npause 1.67s x5\nretreat 0.06m a=0.12 x3\n",
    State.FEARFUL: ("approach a=0.1\npause 1.25s x4\nretreat 0.06m a=2\n"
                    "shiver 6deg for 1.25s\n"),
    State.INACTIVE: "pause 3s\n",
}

#: How far intensity 1 moves each descriptor of a state's row of the study's perception
#: results (intensity 0 as far the other way), by the descriptor's (kind, episode key):
#: a factor for values, episodes added for counts (key ""), the angle reached [deg] for
#: an exploration the stimulus lacks. The built-in kinds' spans of the registry
#: (:mod:`.kind_recipes`, which also gives the fewest episodes a varied count keeps).
SPANS: dict[State, dict[tuple[str, str], float]] = spans()


def _check_intensity(intensity: float) -> float:
    if not (isinstance(intensity, int | float) and 0.0 <= intensity <= 1.0):
        raise AouError(diag(I504, f"the intensity must be a number in [0, 1], found "
                            f"{intensity!r}", _WHERE))
    return float(intensity)


@cached(maxsize=8)
def study(state: State) -> Recipe:
    """The study's stimulus for ``state`` (the shipped hold for inactive)."""
    res = lint_source(STUDY_SOURCE[state], f"<study {state}>")
    assert res.behaviour is not None, res.diagnostics
    return Recipe.of(res.behaviour.primitives)


def _vary(state: State, d: Descriptor, r: Recipe, x: float) -> Recipe:
    """``r`` with descriptor ``d`` of ``state`` at ``x = 2 I - 1`` in [-1, 1]."""
    sign = d.stronger[state]
    span = span_of(state, d.kind, d.key)
    assert span is not None, (state, d.name)
    least = kind_recipes()[d.kind].min_count
    v0 = study(state).value(d)
    if d.is_count:
        lo = max(least, int(v0 - sign * span))
        hi = int(v0 + sign * span)
        n = max(least, int(v0) + sign * math.floor(span * x + 0.5))
        note = (f"study {v0:g}; reads more {state} with {'more' if sign > 0 else 'fewer'}: "
                f"{lo} at intensity 0, {v0:g} at 0.5, {hi} at 1")
        return r.with_value(d, n, note)
    if v0:
        note = (f"study {v0:g}; reads more {state} when {'higher' if sign > 0 else 'lower'}: "
                f"{significant(v0 * span ** -sign, 3, 'nearest'):g} at intensity 0, "
                f"{v0:g} at 0.5, {significant(v0 * span ** sign, 3, 'nearest'):g} at 1")
        return r.with_value(d, significant(v0 * span ** (sign * x), 3, "nearest"), note)
    grown = span * x
    note = (f"absent from the study's stimulus; reads more {state} when larger: grows from "
            f"intensity 0.5 to {span:g} at 1")
    return r.with_value(d, significant(grown, 3, "nearest"), note, count=GROWN_COUNT) \
        if grown >= MIN_GROWN_ANGLE else r


def recipe(state: State, intensity: float = STUDY_INTENSITY) -> Recipe:
    """The composition of ``state`` at ``intensity``, before any robot is considered."""
    x = 2.0 * _check_intensity(intensity) - 1.0
    r = study(state)
    every = descriptors()
    for d in every:
        # a descriptor is varied where it has a span and the stimulus has its statement
        if state in d.stronger and span_of(state, d.kind, d.key) is not None \
                and r.node(*slot_of(d)) is not None:
            r = _vary(state, d, r, x)
    pauses = descriptor(PAUSE, "")
    extra = r.count(RETREAT) - study(state).count(RETREAT)
    if extra > 0 and state not in pauses.stronger:
        r = r.with_value(pauses, study(state).count(PAUSE) + extra,
                         f"study {study(state).count(PAUSE)}; one more per added retreat "
                         "(a retreat starts and ends at a pause)")
    for d in every:
        if r.present(d) and d.name not in r.notes:
            r = r.noted(d.name, f"the study's value (no clear perceived effect on {state})"
                        if state in d.no_effect else "the study's value (not varied)")
    if state is State.INACTIVE:
        r = r.noted(descriptor(PAUSE, "duration").name, "the shipped inactive hold (not a "
                    "stimulus of the study; intensity does not change it)")
    return r


# --- blends -----------------------------------------------------------------------------


def blend_weights(C: float, V: float) -> dict[State, float]:
    """Barycentric weights of (C, V) in its triangle of the plane: hesitant at the centre
    and the two canonical corners of the side the point faces. Zero-weight states are
    left out; the weights sum to 1."""
    corners = [s for s in State if s is not State.HESITANT]
    ang = math.atan2(V, C)
    best: tuple[State, State] | None = None
    for first, second in zip(corners, corners[1:] + corners[:1], strict=True):
        pa, pb = CANONICAL[first], CANONICAL[second]
        lo, hi = math.atan2(pa[1], pa[0]), math.atan2(pb[1], pb[0])
        if (ang - lo) % (2 * math.pi) <= (hi - lo) % (2 * math.pi) + 1e-12:
            best = (first, second)
    assert best is not None
    a, b = best
    (xa, ya), (xb, yb) = CANONICAL[a], CANONICAL[b]
    det = xa * yb - xb * ya
    wa, wb = (C * yb - xb * V) / det, (xa * V - C * ya) / det
    w = {State.HESITANT: 1.0 - wa - wb, a: wa, b: wb}
    return {s: max(0.0, x) for s, x in w.items() if x > 1e-12}


def _reads_as(text: str, state: State) -> bool:
    """The text lints without errors or warnings and its C-V inference gives ``state``."""
    res = lint_source(text, "<synth>")
    bad = [d for d in res.diagnostics if d.severity.value in ("error", "warning")]
    return not bad and res.cv is not None and res.cv.state is state


def _with_reading(text: str) -> str:
    """The text with a comment, above its header, giving the point lint infers."""
    p = lint_source(text, "<synth>").cv
    if p is None:
        return text
    line = (f"# It reads as {p.state} at C={p.C:+.2f}, V={p.V:+.2f} (the C-V inference of "
            "`aouc lint`).\n")
    at = text.index("\nbehaviour ") + 1
    return text[:at] + line + text[at:]


@cached(maxsize=64)
def _floor(state: State, limits: Limits) -> float:
    """The weakest intensity (to 1/100) from which ``state`` reads as itself on the arm:
    an arm that cannot perform a study value (e.g. the fearful retreat's 2 m/s^2) may
    weaken the weakest intensities past the state's border."""
    def ok(i: float) -> bool:
        return _reads_as(render(fit(recipe(state, i), limits), state, i, limits, used=i),
                         state)

    if ok(0.0):
        return 0.0
    lo, hi = 0.0, 1.0
    if not ok(hi):
        fitted = fit(recipe(state, hi), limits)
        why = [note[note.index("reduced from"):] for note in fitted.notes.values()
               if "reduced from" in note]  # what the arm narrowed, if that is why
        raise AouError(diag(I504, f"no intensity of `{state}` reads as {state} on "
                            f"{limits.robot}" + (f": {why[0]}" if why else ""), _WHERE))
    while hi - lo > 0.01:
        mid = (lo + hi) / 2
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return math.ceil(hi * 100) / 100


def synthesize(state: State | str | None = None, C: float | None = None,
               V: float | None = None, intensity: float = STUDY_INTENSITY,
               robot: str | None = None, *, goal: tuple[float, float, float] | None = None,
               verify: bool = True) -> str:
    """The ``.aou`` text of a state (or of the C-V point ``(C, V)``) at ``intensity``.

    Args:
        state: one of the five states; or None with ``C`` and ``V`` in [-1, 1].
        intensity: in [0, 1]; :data:`STUDY_INTENSITY` gives the study's stimulus.
        robot: the arm to fit (default ``panda``, the language's default robot).
        goal: the goal in the robot's base frame [m] (default: the robot's).
        verify: compile the file (checks included) and, if it fails on the arm, lower the
            intensity to the highest that compiles (:func:`compiled` keeps the build).
            Without it, only the limits of :mod:`aou_dsl.synth.arm_fit` are kept.

    Raises:
        AouError: I501 for a state, point or intensity out of range; V109 for an unknown
            robot; the reach's own diagnostics when no intensity compiles on the arm.
    """
    intensity = _check_intensity(intensity)
    if state is not None and (C is not None or V is not None):
        raise AouError(diag(I504, "give a state or a C-V point, not both", _WHERE))
    if state is None and (C is None or V is None):
        raise AouError(diag(I504, "give a state, or both C and V", _WHERE))
    for name, x in (("C", C), ("V", V)):
        if x is not None and not (isinstance(x, int | float) and -1.0 <= x <= 1.0):
            raise AouError(diag(I504, f"{name} must be a number in [-1, 1], found {x!r}",
                                _WHERE))
    limits = fit_limits(robot or "panda", _goal(goal))
    st = _state(state) if state is not None else None
    point = (float(C), float(V)) if st is None else None  # type: ignore[arg-type]
    why = None
    for _ in range(_REFITS):
        lo = _floor(st, limits) if st is not None else 0.0
        make = _maker(st, point, intensity, limits)
        i_eff = max(intensity, lo)
        text = make(i_eff)
        why = _failure(text) if verify else None
        reached = why.refusal.achieved if why is not None and isinstance(
            why.refusal, AccelerationShort) else None
        if not reached:
            break
        # somewhere on this reach the joints reach less than on the probe's line
        limits = replace(limits, accel=min(significant(0.9 * float(reached), DIGITS),
                                           significant(0.9 * limits.accel, DIGITS)))
    if why is not None:
        text = _lowered(make, i_eff, lo, why, (st, limits) if st is not None else None)
    return _with_reading(text)


#: How often a file is refitted to an acceleration its compile found out of reach.
_REFITS = 4


def _maker(st: State | None, point: tuple[float, float] | None, intensity: float,
           limits: Limits):
    """The text of the request at an intensity ``i`` (``why``: why not a stronger one)."""
    if st is not None:
        return lambda i, why=None: render(fit(recipe(st, i), limits), st, intensity, limits,
                                          used=i, why=why)
    assert point is not None
    return lambda i, why=None: _point_text(point[0], point[1], intensity, i, limits, why)


#: Compile warnings that mean the arm cannot perform a declared value.
_LIMIT_CODES = frozenset({C304, C308, C309, C311})


@cached(maxsize=1)
def _session() -> Session:
    """The warm session synthesis and the live regulator build in: arms loaded once, the
    last builds kept, a changed text re-solving only the episodes it changed."""
    from ..driver.session import Session

    return Session(keep=32)


def compiled(text: str) -> BuildResult:
    """The build of a synthesized text (robot and goal are in it), the checks included, as
    ``aouc compile`` makes it; kept for the texts made last."""
    return _session().build(text)


def _failure(text: str) -> Diagnostic | None:
    """Why the text does not compile cleanly on its arm (None when it does)."""
    res = compiled(text)
    bad = [d for d in res.diagnostics
           if d.severity.value == "error" or d.code in _LIMIT_CODES]
    if bad:
        return bad[0]
    if res.document is None:
        return diag(C305, "the build made no trajectory", _WHERE)
    return None


@cached(maxsize=64)
def _ceiling(probe: Keyed) -> float | None:
    """:func:`_highest` kept per state, arm and lowest intensity (``probe.key``)."""
    make, lo = probe.value
    return _highest(make, lo)


def _highest(make, lo: float) -> float | None:
    """The highest intensity in [``lo``, 1], to 1/100, whose file compiles (bisection:
    stronger files ask more of the arm); None when ``lo`` fails."""
    if _failure(make(lo)) is not None:
        return None
    a, b = lo, 1.0
    while b - a > 0.01:
        mid = (a + b) / 2
        a, b = (mid, b) if _failure(make(mid)) is None else (a, mid)
    return math.floor(a * 100) / 100


def _lowered(make, intensity: float, lo: float, why: Diagnostic,
             key: tuple[State, Limits] | None) -> str:
    """``make`` at the highest intensity in [``lo``, 1] that compiles, below ``intensity``
    (which failed for ``why``); found by bisection over that fixed range, and kept per
    state and arm.

    Raises:
        AouError: the failure, when even ``lo`` fails.
    """
    best = _highest(make, lo) if key is None else _ceiling(Keyed((*key, lo), (make, lo)))
    if best is None:
        raise AouError(diag(why.code, f"no intensity of this behaviour compiles on the arm: "
                            f"{why.message}", _WHERE))
    return make(min(best, intensity), why)


def _goal(goal) -> tuple[float, float, float] | None:
    if goal is None:
        return None
    try:
        x, y, z = (float(v) for v in goal)
    except (TypeError, ValueError):
        raise AouError(diag(I504, f"the goal must be three numbers (x, y, z) [m], found "
                            f"{goal!r}", _WHERE)) from None
    if not all(math.isfinite(v) for v in (x, y, z)):
        raise AouError(diag(I504, f"the goal must be finite, found {goal!r}", _WHERE))
    return x, y, z


def _state(state: State | str) -> State:
    try:
        return State(state)
    except ValueError:
        raise AouError(diag(I504, f"unknown state `{state}`: expected one of "
                            f"{', '.join(s.value for s in State)}", _WHERE)) from None


def _point_text(C: float, V: float, intensity: float, used: float, limits: Limits,
                why: Diagnostic | None) -> str:
    """The blend for (C, V) at intensity ``used`` (see the module's docstring)."""
    nearest = classify(C, V)
    w0 = blend_weights(C, V)
    recipes = {s: recipe(s, max(used, _floor(s, limits))) for s in w0}
    for power in (1, 2, 4, 8, 16):
        w = {s: x ** power for s, x in w0.items()}
        total = sum(w.values())
        w = {s: x / total for s, x in w.items()}
        text = render(fit(Recipe.blend(recipes, w), limits), nearest, intensity, limits,
                      point=(C, V, w), used=used, why=why)
        if _reads_as(text, nearest):
            return text
    i_eff = max(used, _floor(nearest, limits))
    return render(fit(recipe(nearest, i_eff), limits), nearest, intensity, limits,
                  point=(C, V, {nearest: 1.0}), used=i_eff, why=why)
