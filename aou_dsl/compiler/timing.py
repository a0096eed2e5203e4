"""Stage 6, timing: joint paths -> time laws, under the robot's limits and the declared ones.

Every moving episode is a path ``q(s)`` over its own coordinate ``s`` (metres along the
line of sight for approach and retreat, radians of bearing for gaze, radians of roll for
tilt) and starts and ends at rest.

TOPP-RA parametrises approach, retreat and gaze time-optimally under the joint velocity
limits (URDF, scaled) and joint acceleration limits (:mod:`aou_dsl.robots`). The
declared end-effector limits enter through a *virtual joint*: ``s`` itself is appended
to the path as one more coordinate, with velocity limit ``v=`` and acceleration limit
``a=``. On a straight line the end-effector acceleration is ``s''``, so the time-optimal
law peaks at exactly the declared acceleration whenever no real joint binds first.

Tilts have a fixed duration (the tilt velocity descriptor is angle / duration); shivers
are analytic joint oscillations; pauses are exact holds.
"""

from __future__ import annotations

import functools
import importlib
import logging
import math
import sys
import types
from dataclasses import dataclass

import numpy as np

from ..kinematics import ArmModel

__all__ = [
    "JointSegment",
    "PathSegment",
    "TimeLaw",
    "TimingFailure",
    "binding_joint",
    "limit_ratios",
    "shiver_segment",
    "time_path",
]

#: Relative slack when checking a result against a limit.
LIMIT_SLACK = 1e-3


@dataclass(frozen=True)
class TimeLaw:
    """``s(t)`` with constant ``s''`` between grid points (TOPP-RA's own output form).

    Attributes:
        s: grid of the path coordinate, shape (K,), increasing.
        sd: path speed at the grid points, shape (K,); zero at both ends.
        t: time at the grid points [s], shape (K,).
        u: path acceleration on each interval, shape (K - 1,).
    """

    s: np.ndarray
    sd: np.ndarray
    t: np.ndarray
    u: np.ndarray

    @classmethod
    def from_speeds(cls, s: np.ndarray, sd: np.ndarray) -> TimeLaw:
        ds = np.diff(s)
        mean = sd[:-1] + sd[1:]
        if np.any(mean <= 0):
            raise ValueError("path speed is zero on an interval")
        dt = 2.0 * ds / mean
        u = (sd[1:] ** 2 - sd[:-1] ** 2) / (2.0 * ds)
        return cls(s, sd, np.concatenate([[0.0], np.cumsum(dt)]), u)

    @classmethod
    def bang_bang(cls, length: float, duration: float) -> TimeLaw:
        """Rest to rest over ``length`` in exactly ``duration``: accelerate, decelerate."""
        peak = 2.0 * length / duration
        return cls.from_speeds(np.array([0.0, length / 2, length]), np.array([0.0, peak, 0.0]))

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    def __call__(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``s, s', s''`` at local times ``tau`` (clipped to [0, duration])."""
        tau = np.clip(tau, 0.0, self.duration)
        i = np.clip(np.searchsorted(self.t, tau, side="right") - 1, 0, len(self.u) - 1)
        dt = tau - self.t[i]
        u = self.u[i]
        sd = self.sd[i] + u * dt
        s = self.s[i] + self.sd[i] * dt + 0.5 * u * dt * dt
        return s, sd, u


class PathSegment:
    """A timed joint path: ``q(t) = path(s(t))``, shape (n,) per sample.

    ``spline`` may have more columns than joints (TOPP-RA's path carries the virtual
    coordinate last); only the first ``n`` are the joints.
    """

    def __init__(self, s_way: np.ndarray, q_way: np.ndarray, law: TimeLaw, spline=None):
        from scipy.interpolate import CubicSpline

        self.n = q_way.shape[1]
        self.spline = CubicSpline(s_way, q_way, axis=0) if spline is None else spline
        self.d1 = self.spline.derivative(1)
        self.d2 = self.spline.derivative(2)
        self.law = law

    @property
    def duration(self) -> float:
        return self.law.duration

    def sample(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Joint positions, velocities, accelerations at local times; each (len(tau), n)."""
        s, sd, sdd = self.law(tau)
        n = self.n
        qs, qss = self.d1(s)[:, :n], self.d2(s)[:, :n]
        return (self.spline(s)[:, :n], qs * sd[:, None],
                qss * (sd * sd)[:, None] + qs * sdd[:, None])


class JointSegment:
    """A hold or a shiver: the held configuration plus an analytic offset on one joint."""

    def __init__(self, q_hold: np.ndarray, duration: float, joint: int = 0,
                 amplitude: float = 0.0, f: float = 0.0):
        self.q_hold, self._duration = np.asarray(q_hold, dtype=float), duration
        self.joint, self.amplitude, self.f = joint, amplitude, f

    @property
    def duration(self) -> float:
        return self._duration

    def sample(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n = len(tau)
        q = np.tile(self.q_hold, (n, 1))
        qd = np.zeros_like(q)
        qdd = np.zeros_like(q)
        if self.amplitude:
            x, xd, xdd = _shiver_offset(tau, self.amplitude, self.f, self.duration)
            q[:, self.joint] += x
            qd[:, self.joint] = xd
            qdd[:, self.joint] = xdd
        return q, qd, qdd


def _shiver_offset(tau: np.ndarray, amplitude: float, f: float, duration: float
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(A/2) sin(2 pi f t) e(t)``: a sine whose envelope ``e`` rises as sin^2 over the
    first cycle and falls over the last, so it starts and ends at rest; the middle cycles
    have the full peak-to-peak amplitude ``A``."""
    w = 2.0 * math.pi * f
    ramp = 1.0 / f
    tau = np.clip(tau, 0.0, duration)
    edge = np.minimum(tau, duration - tau)  # time from the nearer end
    sign = np.where(tau <= duration - tau, 1.0, -1.0)  # d(edge)/dt
    inside = edge < ramp
    k = math.pi / (2.0 * ramp)
    e = np.where(inside, np.sin(k * edge) ** 2, 1.0)
    ed = np.where(inside, k * np.sin(2.0 * k * edge) * sign, 0.0)
    edd = np.where(inside, 2.0 * k * k * np.cos(2.0 * k * edge), 0.0)
    a = amplitude / 2.0
    s, c = np.sin(w * tau), np.cos(w * tau)
    x = a * s * e
    xd = a * (w * c * e + s * ed)
    xdd = a * (-w * w * s * e + 2.0 * w * c * ed + s * edd)
    return x, xd, xdd


@dataclass(frozen=True)
class TimingFailure:
    """Why an episode could not be timed as declared; ``joint`` is the binding one."""

    reason: str
    joint: str | None
    achieved: float | None = None
    wanted: float | None = None


class _LazyModule(types.ModuleType):
    """Stands in for a module until one of its attributes is used, then imports it."""

    def __getattr__(self, attr: str):
        return getattr(importlib.import_module(self.__name__), attr)


def _import_toppra():
    """toppra, imported without matplotlib.

    toppra's algorithm module imports ``matplotlib.pyplot`` at its top, for plotting
    helpers aou never calls; that import costs every compile a fraction of a second. While
    toppra is imported, lazy stand-ins take matplotlib's place in ``sys.modules``; they
    are removed right after, so a later ``import matplotlib`` (``aouc plot``) is the real
    one, and toppra's own reference imports it only if it is ever used.
    """
    if "toppra" in sys.modules:
        return sys.modules["toppra"]
    stubs: dict[str, types.ModuleType] = {}
    if "matplotlib" not in sys.modules:
        stubs["matplotlib"] = _LazyModule("matplotlib")
        stubs["matplotlib.pyplot"] = _LazyModule("matplotlib.pyplot")
        setattr(stubs["matplotlib"], "pyplot", stubs["matplotlib.pyplot"])  # noqa: B010
        sys.modules.update(stubs)
    try:
        import toppra
        import toppra.algorithm  # noqa: F401
        import toppra.constraint  # noqa: F401
    finally:
        for name, stub in stubs.items():
            if sys.modules.get(name) is stub:
                del sys.modules[name]
    return toppra


@functools.lru_cache(maxsize=256)
def _constraints(jv: tuple[float, ...], ja: tuple[float, ...], a: float, vmax: float):
    """TOPP-RA's joint velocity and acceleration constraints, the virtual joint last.
    They do not depend on the path, and building one formats its limits as text (slow),
    so they are made once per set of limits."""
    constraint = _import_toppra().constraint
    vlim = np.column_stack([-np.append(jv, vmax), np.append(jv, vmax)])
    alim = np.column_stack([-np.append(ja, a), np.append(ja, a)])
    return (constraint.JointVelocityConstraint(vlim),
            constraint.JointAccelerationConstraint(alim))


def binding_joint(arm: ArmModel, seg: PathSegment) -> tuple[str, float]:
    """The joint that comes nearest (or furthest past) its planned velocity or
    acceleration limit on a segment, and that ratio."""
    rv, ra = limit_ratios(arm, seg)
    ratio = np.maximum(rv, ra)
    j = int(np.argmax(ratio))
    return arm.joint_names[j], float(ratio[j])


#: The Cartesian peak is checked at least this often [Hz] (the default output rate):
#: between sparser instants a bend of the joint path can overshoot unseen.
PEAK_RATE = 250.0


def cartesian_peak(arm: ArmModel, seg: PathSegment, samples: int = 100) -> float:
    """Peak translational acceleration of the end-effector on a segment [m/s^2]: the
    classical acceleration ``J q'' + J' q'`` from Pinocchio, at ``samples`` instants or
    :data:`PEAK_RATE`, whichever is denser."""
    import pinocchio as pin

    model, data = arm.model, arm.model.createData()
    n = max(samples, int(math.ceil(seg.duration * PEAK_RATE)) + 1)
    q, qd, qdd = seg.sample(np.linspace(0.0, seg.duration, n))
    peak = 0.0
    for qi, vi, ai in zip(q, qd, qdd, strict=True):
        pin.forwardKinematics(model, data, qi, vi, ai)
        pin.updateFramePlacements(model, data)
        acc = pin.getFrameClassicalAcceleration(model, data, arm.frame_id,
                                                pin.LOCAL_WORLD_ALIGNED).linear
        peak = max(peak, float(np.linalg.norm(acc)))
    return peak


def time_path(arm: ArmModel, s_way: np.ndarray, q_way: np.ndarray, a: float, vmax: float,
              *, gridpoints: int = 80, cartesian: bool = False
              ) -> tuple[PathSegment | None, TimingFailure | None]:
    """Time a joint path rest to rest with TOPP-RA.

    Args:
        arm: the robot (limits).
        s_way: path coordinate at the waypoints, shape (K,), increasing from 0.
        q_way: joint waypoints, shape (K, n).
        a: limit on ``|s''|`` (the declared peak acceleration) [m/s^2 or rad/s^2].
        vmax: limit on ``|s'|`` (the speed cap) [m/s or rad/s].

        cartesian: ``s`` is arc length on a straight line, and ``a`` the declared peak
            end-effector acceleration. The joint path is a spline through IK waypoints,
            so the hand's real path bends a little; its curvature adds ``p'' s'^2`` to the
            acceleration. The peak is computed exactly on the timed path and, if it
            overshoots ``a``, the path is timed once more with the virtual limit lowered
            by the overshoot.

    Returns:
        ``(segment, failure)``: the segment (None if TOPP-RA failed) and, when the
        declared acceleration could not be reached, a failure naming the binding joint.
    """
    jv, ja = arm.plan_vmax.copy(), arm.plan_amax.copy()
    a_virtual = a
    seg, fail = _toppra(arm, s_way, q_way, a_virtual, vmax, gridpoints, jv, ja)
    for _ in range(3):
        if seg is None:
            break
        retime = False
        if cartesian and fail is None:
            peak = cartesian_peak(arm, seg)
            if peak > a * (1.0 + 2e-3):
                a_virtual *= a / peak
                retime = True
        # TOPP-RA meets the joint limits at its grid points; between them a sharp bend
        # of the joint path (the null space turning a joint fast) can overshoot. Check
        # densely, and lower the limit of a joint that overshoots by its overshoot.
        rv, ra = limit_ratios(arm, seg)
        if rv.max() > 1.0 + LIMIT_SLACK or ra.max() > 1.0 + LIMIT_SLACK:
            jv = jv / np.maximum(rv, 1.0)
            ja = ja / np.maximum(ra, 1.0)
            retime = True
        if not retime:
            break
        seg2, fail2 = _toppra(arm, s_way, q_way, a_virtual, vmax, gridpoints, jv, ja)
        if seg2 is None:
            break
        seg, fail = seg2, (fail2 if not cartesian or fail2 is None or fail is not None
                           else None)
    return seg, fail


def limit_ratios(arm: ArmModel, seg: PathSegment, samples: int = 1500
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Per joint, the largest velocity and acceleration over the planned limits on a
    segment sampled densely (finer than any output rate); shapes (n,)."""
    tau = np.linspace(0.0, seg.duration, samples)
    _, qd, qdd = seg.sample(tau)
    return (np.abs(qd).max(axis=0) / arm.plan_vmax, np.abs(qdd).max(axis=0) / arm.plan_amax)


def _toppra(arm: ArmModel, s_way: np.ndarray, q_way: np.ndarray, a: float, vmax: float,
            gridpoints: int, jv: np.ndarray, ja: np.ndarray
            ) -> tuple[PathSegment | None, TimingFailure | None]:
    toppra = _import_toppra()
    algo = toppra.algorithm
    logging.getLogger("toppra").setLevel(logging.ERROR)
    aug = np.column_stack([q_way, s_way])
    path = toppra.SplineInterpolator(s_way, aug)
    # A uniform grid plus every waypoint: the spline's second derivative is piecewise
    # linear, so its extremes sit at the waypoints (knots), which the grid must include.
    grid = np.union1d(np.linspace(s_way[0], s_way[-1], gridpoints), s_way)
    inst = algo.TOPPRA(list(_constraints(tuple(jv), tuple(ja), a, vmax)),
                       path, gridpoints=grid, solver_wrapper="seidel")
    try:
        _, sd, _, _ = inst.compute_parameterization(0.0, 0.0, return_data=True)
    except Exception as exc:  # toppra raises bare exceptions on degenerate input
        return None, TimingFailure(f"TOPP-RA failed: {exc}", None)
    if inst.problem_data.return_code != algo.ParameterizationReturnCode.Ok or sd is None:
        return None, TimingFailure(f"TOPP-RA: {inst.problem_data.return_code}", None)
    sd = np.asarray(sd, dtype=float)
    sd[0] = sd[-1] = 0.0
    try:
        law = TimeLaw.from_speeds(grid, sd)
    except ValueError:  # the path speed is zero inside the path: no motion can follow it
        return None, TimingFailure("TOPP-RA: the path speed drops to zero inside the path",
                                   None)
    seg = PathSegment(s_way, q_way, law, spline=path.cspl)
    peak = float(np.max(np.abs(seg.law.u)))
    if peak < a * 0.97:
        return seg, TimingFailure("joint limits bind before the declared acceleration",
                                  binding_joint(arm, seg)[0], peak, a)
    return seg, None


def shiver_segment(arm: ArmModel, q_hold: np.ndarray, amplitude: float, f: float,
                   duration: float) -> tuple[JointSegment, TimingFailure | None]:
    """An oscillation of the robot's shiver joint about ``q_hold``; checked against that
    joint's velocity and acceleration limits."""
    j = arm.joint_names.index(arm.spec.shiver_joint)
    seg = JointSegment(q_hold, duration, j, amplitude, f)
    tau = np.linspace(0.0, duration, max(200, int(duration * f * 40)))
    _, xd, xdd = _shiver_offset(tau, amplitude, f, duration)
    r_v = float(np.max(np.abs(xd))) / arm.plan_vmax[j]  # scales with f
    r_a = float(np.max(np.abs(xdd))) / arm.plan_amax[j]  # scales with f^2
    if max(r_v, r_a) > 1.0 + LIMIT_SLACK:
        f_ok = f * min(1.0 / max(r_v, 1e-12), 1.0 / math.sqrt(max(r_a, 1e-12)))
        which = "acceleration" if r_a >= r_v else "velocity"
        return seg, TimingFailure(
            f"a {math.degrees(amplitude):g} deg shiver at {f:g} Hz needs "
            f"{max(r_v, r_a):.1f}x {arm.spec.shiver_joint}'s {which} limit; at most about "
            f"{f_ok:.2g} Hz at this amplitude", arm.spec.shiver_joint, f, f_ok)
    return seg, None
