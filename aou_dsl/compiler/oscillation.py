"""Shivers: an analytic oscillation of the robot's shiver joint about a held configuration.

A shiver of peak-to-peak amplitude ``A`` at ``f`` Hz is ``(A/2) sin(2 pi f t)`` under an
envelope that fades it in over the first cycle and out over the last
(:func:`shiver_offset`). It is the same curve for every amplitude and frequency, scaled:
``x(t) = A g(f t)``. So its peak speed, acceleration and jerk grow exactly as ``A f``,
``A f^2`` and ``A f^3``, and the check against the joint's limits, and the highest
frequency that fits, need no sampling of the episode itself.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.memo import cached
from ..fit.refusals import TimingFailure
from ..fit.rounding import times
from ..fit.search import largest_fitting
from ..lang.primitives import LOOK_SHIVER_F, VISIBLE_SHIVER
from ..robot.kinematics import ArmModel
from .peak_limits import JERK_SCALE, LIMIT_SLACK

__all__ = ["JointSegment", "shiver_offset", "shiver_ratios", "shiver_segment"]


class JointSegment:
    """A hold or a shiver: the held configuration plus an analytic offset on one joint."""

    def __init__(self, q_hold: np.ndarray, duration: float, joint: int = 0,
                 amplitude: float = 0.0, f: float = 0.0):
        self.q_hold, self._duration = np.asarray(q_hold, dtype=float), duration
        self.joint, self.amplitude, self.f = joint, amplitude, f

    @property
    def duration(self) -> float:
        return self._duration

    @property
    def n(self) -> int:
        """The number of joints."""
        return len(self.q_hold)

    def sample(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n = len(tau)
        q = np.tile(self.q_hold, (n, 1))
        qd = np.zeros_like(q)
        qdd = np.zeros_like(q)
        if self.amplitude:
            x, xd, xdd, _ = shiver_offset(tau, self.amplitude, self.f, self.duration)
            q[:, self.joint] += x
            qd[:, self.joint] = xd
            qdd[:, self.joint] = xdd
        return q, qd, qdd

    def positions(self, tau: np.ndarray) -> np.ndarray:
        """Joint positions at local times, (len(tau), n): :meth:`sample`'s first."""
        q = np.tile(self.q_hold, (len(tau), 1))
        if self.amplitude:
            q[:, self.joint] += shiver_offset(tau, self.amplitude, self.f, self.duration)[0]
        return q


def shiver_offset(tau: np.ndarray, amplitude: float, f: float, duration: float
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(A/2) sin(2 pi f t) e(t)`` and its first three derivatives: a sine whose envelope
    ``e`` rises as sin^2 over the first cycle and falls over the last, so it starts and
    ends at rest with zero acceleration; the middle cycles have the full peak-to-peak
    amplitude ``A``."""
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
    eddd = np.where(inside, -4.0 * k**3 * np.sin(2.0 * k * edge) * sign, 0.0)
    a = amplitude / 2.0
    s, c = np.sin(w * tau), np.cos(w * tau)
    x = a * s * e
    xd = a * (w * c * e + s * ed)
    xdd = a * (-w * w * s * e + 2.0 * w * c * ed + s * edd)
    xddd = a * (-w**3 * c * e - 3.0 * w * w * s * ed + 3.0 * w * c * edd + s * eddd)
    return x, xd, xdd, xddd


@cached(maxsize=64)
def _unit_peaks(cycles: float) -> tuple[float, float, float]:
    """Peak speed, acceleration and jerk of a shiver of unit peak-to-peak amplitude at
    1 Hz lasting ``cycles`` cycles. Any shiver is this one scaled, ``x(t) = A g(f t)``:
    its peaks are ``A f``, ``A f^2`` and ``A f^3`` times these, exactly. They lie in the
    first and last two cycles (where the envelope changes, beside a full cycle); sampled
    10 000 times a cycle, they are exact to about 1e-6."""
    head = np.linspace(0.0, min(cycles, 2.0), 20001)
    tail = np.linspace(max(0.0, cycles - 2.0), cycles, 20001)
    _, xd, xdd, xddd = shiver_offset(np.concatenate([head, tail]), 1.0, 1.0, cycles)
    return (float(np.max(np.abs(xd))), float(np.max(np.abs(xdd))),
            float(np.max(np.abs(xddd))))


def shiver_ratios(arm: ArmModel, amplitude: float, f: float, duration: float
                  ) -> tuple[float, float, float]:
    """A shiver's peak speed, acceleration and jerk over its joint's planned limits."""
    j = arm.joint_names.index(arm.spec.shiver_joint)
    pv, pa, pj = _unit_peaks(round(duration * f, 6))
    return (amplitude * f * pv / arm.plan_vmax[j], amplitude * f * f * pa / arm.plan_amax[j],
            amplitude * f**3 * pj / (arm.jmax[j] * JERK_SCALE))


def _fits(ratios: tuple[float, ...]) -> bool:
    return max(ratios) <= 1.0 + LIMIT_SLACK


def _suggestions(arm: ArmModel, amplitude: float, f: float, duration: float, need: float
                 ) -> tuple[float | None, list[str]]:
    """The highest frequency that fits at ``amplitude`` (None when none is found), and
    the changes to suggest in words, each one that keeps the shiver's look: that
    frequency if it is not under the slowest shiver that looks like one
    (:data:`~aou_dsl.lang.primitives.LOOK_SHIVER_F`, or ``f`` when it is slower), else the
    widest amplitude at ``f`` or, if that is too narrow to see, at that slowest shiver."""
    cycles = duration * f  # the same `for` at another frequency: the same peaks
    f_ok = largest_fitting(f / need, lambda fc: _fits(
        shiver_ratios(arm, amplitude, fc, cycles / fc)), below=f)
    floor = min(f, LOOK_SHIVER_F)
    ways = []
    if f_ok is not None and f_ok >= floor:
        ways.append(f"at most {f_ok:g} Hz fits at this amplitude")
    least = math.degrees(VISIBLE_SHIVER)
    for fa in (f,) if ways or floor == f else (f, floor):
        def fits(deg: float, fa: float = fa) -> bool:
            return _fits(shiver_ratios(arm, math.radians(deg), fa, cycles / fa))

        widest = math.degrees(amplitude) / max(shiver_ratios(arm, amplitude, fa, cycles / fa))
        a_ok = largest_fitting(widest, fits, below=widest * 1.001)
        if a_ok is not None and a_ok >= least:
            ways.append(f"at most {a_ok:g} deg at {fa:g} Hz")
            break
    if not ways:
        ways.append(f"not even a {least:g} deg shiver at {floor:g} Hz fits, and a slower "
                    "one would read as slow rolls")
    return f_ok, ways


def shiver_segment(arm: ArmModel, q_hold: np.ndarray, amplitude: float, f: float,
                   duration: float) -> tuple[JointSegment, TimingFailure | None]:
    """An oscillation of the robot's shiver joint about ``q_hold``; checked against that
    joint's velocity, acceleration and jerk limits (planned fractions). On failure the
    reason names the limit and says what fits instead, each value rounded down and
    checked; ``wanted`` is the highest frequency that fits at this amplitude (even one
    slower than the language allows: a caller may shrink the amplitude instead)."""
    j = arm.joint_names.index(arm.spec.shiver_joint)
    seg = JointSegment(q_hold, duration, j, amplitude, f)
    ratios = shiver_ratios(arm, amplitude, f, duration)
    if _fits(ratios):
        return seg, None
    need = [r ** (1.0 / p) for r, p in zip(ratios, (1, 2, 3), strict=True)]
    k = int(np.argmax(need))
    f_ok, ways = _suggestions(arm, amplitude, f, duration, need[k])
    joint, which = arm.spec.shiver_joint, ("velocity", "acceleration", "jerk")[k]
    reason = (f"a {math.degrees(amplitude):g} deg shiver at {f:g} Hz needs "
              f"{times(ratios[k])}x {joint}'s {which} limit; " + ", or ".join(ways))
    return seg, TimingFailure(reason, joint, f, f_ok, which)
