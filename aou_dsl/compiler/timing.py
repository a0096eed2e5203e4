"""Stage 6, timing: joint paths -> time laws, under the robot's limits and the declared ones.

Every moving episode is a path ``q(s)`` over its own coordinate ``s`` (metres along the
line of sight for approach and retreat, radians of bearing for gaze, radians of roll for
tilt) and starts and ends at rest, with zero acceleration.

TOPP-RA parametrises approach, retreat and gaze time-optimally under the joint velocity
limits (URDF, scaled) and joint acceleration limits (:mod:`aou_dsl.core.robot_specs`). The
declared end-effector limits enter through a *virtual joint*: ``s`` itself is appended
to the path as one more coordinate, with velocity limit ``v=`` and acceleration limit
``a=``. On a straight line the end-effector acceleration is ``s''``, so the time-optimal
law peaks at exactly the declared acceleration whenever no real joint binds first.

TOPP-RA's law has a piecewise constant ``s''``: its jerk is infinite where ``s''``
jumps. Every law is therefore smoothed by a moving average of a few milliseconds
(:class:`~.timelaw.SmoothLaw`), the shortest that keeps every joint's jerk within
:data:`JERK_SCALE` of its limit; the peak acceleration is kept, the duration grows by
the window.

Tilts have a fixed duration (the tilt velocity descriptor is angle / duration): a
smoothed bang-bang law of exactly that duration. Shivers are analytic joint oscillations;
pauses are exact holds.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..fit.refusals import TimingFailure
from ..fit.rounding import times
from ..fit.search import largest_fitting
from ..robot.kinematics import ArmModel
from .oscillation import JointSegment, shiver_ratios, shiver_segment
from .peak_limits import (
    JERK_SCALE,
    LIMIT_SLACK,
    PEAK_RATE,
    binding_joint,
    cartesian_peak,
    jerk_ratio,
    jerk_ratios,
    limit_ratios,
    within_limits,
)
from .segment import PathSegment
from .timelaw import SmoothLaw, TimeLaw
from .topp import parametrize

__all__ = [
    "JERK_SCALE",
    "LIMIT_SLACK",
    "PEAK_RATE",
    "JointSegment",
    "PathSegment",
    "SmoothLaw",
    "TimeLaw",
    "TimingFailure",
    "binding_joint",
    "cartesian_peak",
    "fixed_segment",
    "jerk_ratio",
    "limit_ratios",
    "shiver_ratios",
    "shiver_segment",
    "tilt_segment",
    "time_path",
]

#: Shortest smoothing window [s]: two periods of a 1 kHz controller.
MIN_WINDOW = 2e-3
#: A time law reaches its declared acceleration when its peak is at least this fraction
#: of it (it is exact when nothing binds; below, C304 says what binds). Stricter than the
#: descriptors' 3 % tolerance, so a shortfall the measurement may see is explained.
REACHED = 0.99


def _smoothed(arm: ArmModel, make: Callable[[float], PathSegment], first: float,
              longest: float, keep_best: bool = False) -> PathSegment:
    """The segment ``make(window)`` with the shortest window (from ``first``, at least
    :data:`MIN_WINDOW`, at most ``longest``) whose joint jerks stay within the planned
    limits. Jerk falls as 1 / window, so each try scales the window by the jerk ratio.

    When no window keeps the jerk within the limits, the last one tried is returned; with
    ``keep_best``, the one of least jerk. (On a path whose own bends set the jerk, a longer
    window does not lower it: it shortens the rest of a fixed-duration law and raises the
    speed, acceleration and jerk there.)"""
    w = min(max(MIN_WINDOW, first), longest)
    seg = make(w)
    r = jerk_ratio(arm, seg)
    best = (r, seg)
    for _ in range(6):
        if r <= 1.0 or w >= longest:
            break
        w = min(longest, w * r * 1.05)
        seg = make(w)
        r = jerk_ratio(arm, seg)
        best = min(best, (r, seg), key=lambda x: x[0])
    if r < 0.8 and w > MIN_WINDOW:  # the first guess was generous: try a shorter window
        shorter = make(max(MIN_WINDOW, w * r * 1.05))
        if jerk_ratio(arm, shorter) <= 1.0:
            return shorter
    return best[1] if keep_best and r > 1.0 else seg


def _window_guess(arm: ArmModel, seg: PathSegment, base: TimeLaw) -> float:
    """A first window [s]: over a window ``T``, a joint whose acceleration swings by
    ``dA`` gets a jerk of about ``dA / T``. Accelerations are read at the middle of each
    interval of the base law (where ``s''`` is constant)."""
    mid = (base.t[:-1] + base.t[1:]) / 2.0
    _, _, qdd = seg.with_law(base).sample(np.concatenate([[0.0], mid, [base.duration]]))
    swing = qdd.max(axis=0) - qdd.min(axis=0)
    return float(np.max(swing / (arm.jmax * JERK_SCALE)))


def smooth(arm: ArmModel, seg: PathSegment) -> PathSegment:
    """A segment timed by a plain law, re-timed by its jerk-limited version."""
    base = seg.law.base if isinstance(seg.law, SmoothLaw) else seg.law
    return _smoothed(arm, lambda w: seg.with_law(SmoothLaw(base, w)),
                     _window_guess(arm, seg, base), base.duration)


def fixed_segment(arm: ArmModel, s_way: np.ndarray, q_way: np.ndarray, duration: float
                  ) -> PathSegment:
    """A rest-to-rest segment of exactly ``duration`` [s] along the whole path: a
    bang-bang law over ``duration - T`` smoothed over ``T`` (the tilt's law)."""
    length = float(s_way[-1])
    probe = PathSegment(s_way, q_way, TimeLaw.bang_bang(length, duration))
    base = probe.law
    assert isinstance(base, TimeLaw)
    return _smoothed(arm, lambda w: probe.with_law(
        SmoothLaw(TimeLaw.bang_bang(length, duration - w), w)),
        _window_guess(arm, probe, base), duration / 2.0, keep_best=True)


def time_path(arm: ArmModel, s_way: np.ndarray, q_way: np.ndarray, a: float, vmax: float,
              *, gridpoints: int = 80, cartesian: bool = False
              ) -> tuple[PathSegment | None, TimingFailure | None]:
    """Time a joint path rest to rest: TOPP-RA, then the jerk-limiting smoothing.

    Args:
        arm: the robot (limits).
        s_way: path coordinate at the waypoints, shape (K,), increasing from 0.
        q_way: joint waypoints, shape (K, n).
        a: limit on ``|s''|`` (the declared peak acceleration) [m/s^2 or rad/s^2].
        vmax: limit on ``|s'|`` (the speed cap) [m/s or rad/s].
        gridpoints: uniform points of TOPP-RA's grid (:func:`.topp.grid` adds more).
        cartesian: ``s`` is arc length on a straight line, and ``a`` the declared peak
            end-effector acceleration. The joint path is a spline through IK waypoints,
            so the hand's real path bends a little; its curvature adds ``p'' s'^2`` to the
            acceleration. The peak is computed exactly on the timed path and, if it
            overshoots ``a``, the path is timed once more with the virtual limit lowered
            by the overshoot.

    Returns:
        ``(segment, failure)``: the segment (None if TOPP-RA failed) and, when the
        declared acceleration could not be reached, a failure naming the binding
        constraint.
    """
    jv, ja = arm.plan_vmax.copy(), arm.plan_amax.copy()
    a_virtual = a

    def timed() -> tuple[PathSegment | None, str | None]:
        law, spline, why = parametrize(s_way, q_way, a_virtual, vmax, gridpoints, jv, ja)
        if law is None:
            return None, why
        return smooth(arm, PathSegment(s_way, q_way, law, spline=spline)), None

    seg, why = timed()
    if seg is None:
        return None, TimingFailure(why or "no time law", None)
    for _ in range(3):
        retime = False
        law = seg.law
        assert isinstance(law, SmoothLaw)
        if cartesian and law.peak_acceleration() >= REACHED * a_virtual:
            peak = cartesian_peak(arm, seg)
            if peak > a * (1.0 + 2e-3):
                a_virtual *= a / peak
                retime = True
        # TOPP-RA meets the joint limits at its grid points; between them a sharp bend
        # of the joint path (the null space turning a joint fast) can overshoot. Check
        # densely (unless a bound over the whole path rules it out), and lower the limit
        # of a joint that overshoots by its overshoot.
        rv, ra = (1.0, 1.0) if within_limits(arm, seg) else limit_ratios(arm, seg)
        if np.max(rv) > 1.0 + LIMIT_SLACK or np.max(ra) > 1.0 + LIMIT_SLACK:
            jv = jv / np.maximum(rv, 1.0)
            ja = ja / np.maximum(ra, 1.0)
            retime = True
        if not retime:
            break
        seg2, _ = timed()
        if seg2 is None:
            break
        seg = seg2
    return seg, _shortfall(arm, seg, a, a_virtual, vmax, cartesian)


def _shortfall(arm: ArmModel, seg: PathSegment, a: float, a_virtual: float, vmax: float,
               cartesian: bool) -> TimingFailure | None:
    """None when the law reaches the declared acceleration (``a_virtual``, the virtual
    limit left after the curvature correction); else what binds, in words: the joint at
    its acceleration (or velocity) limit, at least 95 % of it on the segment; else the
    jerk ramp, longer than the accelerating phase that the speed cap ends after ``v / a``
    (or that the move's length allows)."""
    law = seg.law
    assert isinstance(law, SmoothLaw)
    peak = law.peak_acceleration()
    if peak >= REACHED * a_virtual:
        return None
    achieved = cartesian_peak(arm, seg) if cartesian else peak
    rv, ra = limit_ratios(arm, seg)
    for ratios, kind in ((ra, "acceleration"), (rv, "velocity")):
        j = int(np.argmax(ratios))
        if ratios[j] >= 0.95:
            joint = arm.joint_names[j]
            return TimingFailure(f"{joint} is at its {kind} limit", joint, achieved, a)
    ms = law.window * 1e3
    if np.max(law.base.sd) >= 0.99 * vmax:
        reason = (f"the speed cap v={vmax:.3g} is reached after {vmax / a * 1e3:.3g} ms of "
                  f"acceleration, shorter than the {ms:.3g} ms the joint jerk limits need "
                  "to build the acceleration up")
    else:
        reason = (f"the move is too short to build the acceleration up within the joint "
                  f"jerk limits (a {ms:.3g} ms ramp)")
    return TimingFailure(reason, None, achieved, a)


def _fixed_excess(arm: ArmModel, seg: PathSegment) -> tuple[str, int, float, float] | None:
    """The limit a fixed-duration segment exceeds most, as ``(kind, joint, ratio, need)``
    (``need``: how much slower it must run, velocity scaling with the speed, acceleration
    with its square, jerk with its cube); None when it is within every limit."""
    rv, ra = limit_ratios(arm, seg)
    rj = jerk_ratios(arm, seg, dense=True)
    if max(rv.max(), ra.max(), rj.max()) <= 1.0 + LIMIT_SLACK:
        return None
    excess = []
    for kind, ratios, p in (("velocity", rv, 1), ("acceleration", ra, 2), ("jerk", rj, 3)):
        j = int(np.argmax(ratios))
        excess.append((kind, j, float(ratios[j]), float(ratios[j]) ** (1.0 / p)))
    return max(excess, key=lambda e: e[3])


def tilt_segment(arm: ArmModel, s_way: np.ndarray, q_way: np.ndarray, duration: float,
                 siblings: Callable[[], list[tuple[np.ndarray, np.ndarray]]] | None = None
                 ) -> tuple[PathSegment, TimingFailure | None]:
    """A tilt's segment (:func:`fixed_segment`), checked against every joint's velocity,
    acceleration and jerk limits. On failure the reason names the limit and the joint and
    gives the highest tilt velocity [deg/s] that fits (``wanted``), rounded down and
    checked on this path and on those of the statement's other episodes (``siblings``:
    ``(s_way, q_way)`` of each, asked for only on failure), since `v=` times them all."""
    seg = fixed_segment(arm, s_way, q_way, duration)
    over = _fixed_excess(arm, seg)
    if over is None:
        return seg, None
    kind, j, ratio, need = over
    angle = math.degrees(float(s_way[-1]))
    v = angle / duration
    paths = [(s_way, q_way), *(siblings() if siblings is not None else [])]

    def excess(vc: float, sw: np.ndarray, qw: np.ndarray) -> tuple[str, int, float, float] | None:
        return _fixed_excess(arm, fixed_segment(arm, sw, qw, math.degrees(sw[-1]) / vc))

    for sw, qw in paths[1:]:  # the estimate: the slowest any of them needs
        need = max(need, (excess(v, sw, qw) or ("", 0, 1.0, 1.0))[3])
    v_ok = largest_fitting(v / need, lambda vc: all(
        excess(vc, sw, qw) is None for sw, qw in paths), below=v)
    joint = arm.joint_names[j]
    reason = (f"a {angle:g} deg tilt at {v:.3g} deg/s ({duration:.2f} s) needs "
              f"{times(ratio)}x {joint}'s {kind} limit")
    if v_ok is not None:
        where = f"all {len(paths)} tilts of this statement" if len(paths) > 1 else "here"
        reason += f"; at most {v_ok:g} deg/s fits {where}"
    return seg, TimingFailure(reason, joint, v, v_ok, kind)
