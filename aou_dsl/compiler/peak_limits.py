"""How near a timed segment comes to the robot's limits: joint velocity, acceleration and
jerk against the planned limits, and the end-effector's peak acceleration.

The timing stage (:mod:`.timing`) checks every segment it makes with these, densely (finer
than any output rate); :func:`within_limits` rules the joint checks out at once when a
bound over the whole path is already within the limits.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..robot.kinematics import ArmModel
from .timelaw import SmoothLaw

if TYPE_CHECKING:
    from .segment import PathSegment

__all__ = ["JERK_SCALE", "LIMIT_SLACK", "PEAK_RATE", "binding_joint", "cartesian_peak",
           "jerk_ratio", "jerk_ratios", "limit_ratios", "within_limits"]

#: Relative slack when checking a result against a limit.
LIMIT_SLACK = 1e-3
#: Fraction of the joint jerk limits the time laws are planned with (the checks hold the
#: trajectory to the full limits).
JERK_SCALE = 0.9


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
    :data:`PEAK_RATE`, whichever is denser.

    The magnitudes of all instants are computed at once with numpy
    (:meth:`ArmModel.acceleration_norms`), equal to Pinocchio's up to rounding; the
    instants within rounding of the largest are then computed again by Pinocchio, so the
    peak is Pinocchio's, to the last bit, as if every instant had been."""
    import pinocchio as pin

    model, data = arm.model, arm.model.createData()
    n = max(samples, int(math.ceil(seg.duration * PEAK_RATE)) + 1)
    q, qd, qdd = seg.sample(np.linspace(0.0, seg.duration, n))
    norms = arm.acceleration_norms(q, qd, qdd)
    if norms is not None:
        top = float(norms.max())
        near = np.flatnonzero(norms >= top - (1e-9 * top + 1e-12))
        q, qd, qdd = q[near], qd[near], qdd[near]
    peak = 0.0
    for qi, vi, ai in zip(q, qd, qdd, strict=True):
        pin.forwardKinematics(model, data, qi, vi, ai)
        pin.updateFramePlacements(model, data)
        acc = pin.getFrameClassicalAcceleration(model, data, arm.frame_id,
                                                pin.LOCAL_WORLD_ALIGNED).linear
        peak = max(peak, float(np.linalg.norm(acc)))
    return peak


def limit_ratios(arm: ArmModel, seg: PathSegment, samples: int = 1500
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Per joint, the largest velocity and acceleration over the planned limits on a
    segment sampled densely (finer than any output rate); shapes (n,)."""
    tau = np.linspace(0.0, seg.duration, samples)
    _, qd, qdd = seg.sample(tau)
    return (np.abs(qd).max(axis=0) / arm.plan_vmax, np.abs(qdd).max(axis=0) / arm.plan_amax)


#: A dense look at a segment's jerk samples it this often [Hz] (a controller's rate)...
JERK_RATE = 1000.0
#: ... at least this many times, at most this many.
JERK_SAMPLES = (1500, 20000)


def jerk_ratios(arm: ArmModel, seg: PathSegment, dense: bool = False) -> np.ndarray:
    """Per joint, the largest jerk over the planned jerk limits (``JERK_SCALE`` of the
    robot's) on a segment, seen at every piece of its smoothed law; shape (n,).

    With ``dense``, also at :data:`JERK_RATE`: where the joint path itself bends sharply
    (an arm turning its null space), its jerk ``q_sss s'^3`` peaks inside a piece of the
    law, not at its ends; a controller's check of the trajectory sees it there."""
    law = seg.law
    jerk = (seg.path_jerk(*law.probed()) if isinstance(law, SmoothLaw)
            else seg.jerk(np.linspace(0.0, seg.duration, 1500)))
    if dense:
        lo, hi = JERK_SAMPLES
        n = min(hi, max(lo, math.ceil(seg.duration * JERK_RATE) + 1))
        jerk = np.concatenate([jerk, seg.jerk(np.linspace(0.0, seg.duration, n))])
    return np.abs(jerk).max(axis=0) / (arm.jmax * JERK_SCALE)


def jerk_ratio(arm: ArmModel, seg: PathSegment) -> float:
    """The largest joint jerk over the planned jerk limits on a segment."""
    return float(np.max(jerk_ratios(arm, seg)))


def within_limits(arm: ArmModel, seg: PathSegment) -> bool:
    """True when no joint can exceed its planned velocity or acceleration limit anywhere
    on the segment, by a bound over the whole path: ``|q'| <= max|q_s| max s'`` and
    ``|q''| <= max|q_ss| (max s')^2 + max|q_s| max|s''|`` (a smoothed law's speed and
    acceleration are averages of its base law's, never beyond them). The path's
    derivatives are piecewise quadratic and linear: their largest magnitudes are at the
    ends of each piece or a quadratic's vertex, exactly. False says only that the bound
    does not decide: :func:`limit_ratios` then looks."""
    law = seg.law
    base = law.base if isinstance(law, SmoothLaw) else law
    sd, u = float(np.max(base.sd)), float(np.max(np.abs(base.u)))
    h = np.diff(seg.spline.x)[:, None]
    c1, c2 = seg.d1.c, seg.d2.c  # (3, pieces, n): q_s quadratic, (2, pieces, n): q_ss linear
    a, b, c = c1[0], c1[1], c1[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(a != 0.0, -b / (2.0 * a), -1.0)
    inside = (vertex > 0.0) & (vertex < h)
    vertex = np.where(inside, vertex, 0.0)
    qs = np.max(np.abs(np.stack([c, a * h * h + b * h + c,
                                 np.where(inside, (a * vertex + b) * vertex + c, 0.0)])),
                axis=(0, 1))
    qss = np.max(np.abs(np.stack([c2[1], c2[0] * h + c2[1]])), axis=(0, 1))
    rv = qs * sd / arm.plan_vmax
    ra = (qss * sd * sd + qs * u) / arm.plan_amax
    return bool(np.all(np.isfinite(rv)) and np.all(np.isfinite(ra)) and rv.max() <= 1.0
                and ra.max() <= 1.0)
