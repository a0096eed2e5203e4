"""Stage 5, inverse kinematics: end-effector targets -> a continuous joint path.

Damped least squares on the full 6-D pose error ``log6(M(q)^-1 T)`` (position and the
locked gaze, roll included), with the robot's posture pulled in the null space so the
redundancy of a 7-joint arm is resolved the same way every time. Each target is solved
warm-started from the previous one, so the path is continuous (no branch flips) and
stays a margin inside the joint limits.
"""

from __future__ import annotations

import enum
import math
import operator
from dataclasses import dataclass

import numpy as np

from ..core.memo import cached
from .kinematics import ArmModel

__all__ = ["IKFailure", "IKResult", "IKStatus", "solve_path"]

POS_TOL = 1e-7  # m
ROT_TOL = 1e-6  # rad
MAX_ITER = 60
DAMPING = 1e-8
POSTURE_GAIN = 0.2
#: Newton iterations of one solve that also pull toward the posture. The pull acts in the
#: Jacobian's null space only approximately (the inverse is damped), so a solve that pulls
#: on every iteration can fail to converge and slide far along the self-motion manifold:
#: a branch flip between neighbouring waypoints. Pulling only at first keeps each solve's
#: redundancy step small and lets the remaining iterations converge.
POSTURE_ITERS = 3
#: Largest joint step of one Newton iteration [rad].
MAX_ITER_STEP = 0.2
#: Continuation steps from the posture's own pose to the first target.
SEED_STEPS = 20
#: A joint moving further than this between neighbouring waypoints is a branch flip [rad].
MAX_STEP = 0.35
#: Smallest singular value of the pose Jacobian accepted (a singularity below) [m or rad].
MIN_SINGULAR = 2e-3


class IKStatus(enum.Enum):
    """Why a path could not be followed; the values read as sentences."""

    OK = "every target was reached"
    UNREACHABLE = "a target lies outside the robot's workspace"
    JOINT_LIMIT = "a target needs a joint at or beyond its limit (with margin)"
    SINGULARITY = "the path passes through or too near a singularity"
    DISCONTINUITY = "the solution jumps between neighbouring targets (branch flip)"


@dataclass(frozen=True)
class IKFailure:
    """The first target that failed, kept for investigation."""

    status: IKStatus
    index: int
    position_error: float
    rotation_error: float
    joint: str | None = None


@dataclass(frozen=True)
class IKResult:
    """Joint path, shape (N, n), and the worst residuals over it ([m], [rad])."""

    q: np.ndarray
    worst_position_error: float
    worst_rotation_error: float
    failure: IKFailure | None = None

    @property
    def ok(self) -> bool:
        return self.failure is None


class _Solver:
    def __init__(self, arm: ArmModel):
        import pinocchio as pin

        self.pin = pin
        self.arm = arm
        self.model = arm.model
        self.data = arm.model.createData()
        margin = arm.spec.limit_margin
        self.lo = arm.lower + margin
        self.hi = arm.upper - margin
        self.posture = np.clip(np.array(arm.spec.posture), self.lo, self.hi)
        self.eye_n = np.eye(arm.n)
        # LAPACK's routines as numpy.linalg calls them (the same numbers), without the
        # checks of each call: its matrices here are small, finite and well formed.
        self.lapack = _lapack()

    def solve(self, p: np.ndarray, r: np.ndarray, q0: np.ndarray
              ) -> tuple[np.ndarray, float, float, float]:
        """One target from ``q0``: returns q, position error, rotation error, and the
        smallest singular value of the Jacobian at the solution."""
        q, pe, re, jac = self._newton(self.pin.SE3(r, p), q0.copy())
        if not math.isfinite(_SUM(jac, axis=None)):  # a NaN or an infinity in it
            return q, np.inf, np.inf, 0.0  # diverged: the caller reports it unreachable
        return q, pe, re, float(self.lapack.svd(jac, signature="d->d")[-1])

    def _newton(self, target, q: np.ndarray) -> tuple[np.ndarray, float, float, np.ndarray]:
        pin = self.pin
        fid = self.arm.frame_id
        model, data, lo, hi = self.model, self.data, self.lo, self.hi
        solve = self.lapack.solve
        for it in range(MAX_ITER + 1):
            # One pass: forward kinematics and every joint's Jacobian; then the frame's
            # placement and Jacobian from them.
            pin.computeJointJacobians(model, data, q)
            dm = pin.updateFramePlacement(model, data, fid).actInv(target)
            jac = pin.getFrameJacobian(model, data, fid, pin.LOCAL)
            err = pin.log6(dm).vector
            ep, er = err[:3], err[3:]
            pe, re = math.sqrt(ep.dot(ep)), math.sqrt(er.dot(er))  # their norms
            if (pe < POS_TOL and re < ROT_TOL) or it == MAX_ITER:
                break
            je = -pin.Jlog6(dm.inverse()) @ jac
            # The damped pseudo-inverse (the matrix is positive definite: damped).
            gram = je @ je.T
            gram += _DAMPED
            pinv = je.T @ solve(gram, _EYE6, signature="dd->d")
            dq = -pinv @ err
            if it < POSTURE_ITERS:
                dq += (self.eye_n - pinv @ je) @ (POSTURE_GAIN * (self.posture - q))
            # The largest joint step (a NaN in it makes every joint's NaN: a diverged
            # solve, reported so whatever the step).
            step = max(map(abs, dq.tolist()))
            if step > MAX_ITER_STEP:  # far from the target: Newton steps overshoot
                dq *= MAX_ITER_STEP / step
            q = np.minimum(np.maximum(q + dq, lo), hi)
        return q, pe, re, jac


_EYE6 = np.eye(6)
_DAMPED = DAMPING * _EYE6
#: ``a.sum()`` is this reduction, called through numpy's Python-level wrapper.
_SUM = np.add.reduce


@cached(maxsize=1)
def _lapack() -> _Lapack:
    """The one :class:`_Lapack` of this process (its check runs once)."""
    return _Lapack()


class _Lapack:
    """numpy.linalg's LAPACK calls, one call each: ``solve(a, b)`` and the singular
    values ``svd(a)`` (descending). Another numpy than 2.x: its public functions."""

    def __init__(self):
        self.solve = lambda a, b, signature=None: np.linalg.solve(a, b)
        self.svd = lambda a, signature=None: np.linalg.svd(a, compute_uv=False)
        raw = getattr(np.linalg, "_umath_linalg", None)
        if raw is not None and _same_as_public(raw):
            self.solve, self.svd = raw.solve, raw.svd


def _same_as_public(raw) -> bool:
    """Whether numpy's internal calls give what its public functions give, on a sample
    (an internal interface may change between numpy versions)."""
    a = np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]])
    b = np.eye(3)
    j = np.arange(18.0).reshape(3, 6) % 5 + np.eye(3, 6)
    try:
        return bool(np.array_equal(raw.solve(a, b, signature="dd->d"), np.linalg.solve(a, b))
                    and np.array_equal(raw.svd(j, signature="d->d"),
                                       np.linalg.svd(j, compute_uv=False)))
    except (AttributeError, TypeError, ValueError):
        return False


def _seed(solver: _Solver, p: np.ndarray, r: np.ndarray) -> np.ndarray:
    """A configuration near ``(p, r)`` reached by continuation from the posture: the target
    moves in small steps from the posture's own end-effector pose, each solve warm-started.
    A far target solved in one go can land on another branch or fail."""
    pin = solver.pin
    q = solver.posture.copy()
    pin.framesForwardKinematics(solver.model, solver.data, q)
    m0 = solver.data.oMf[solver.arm.frame_id].copy()
    delta = pin.log6(m0.actInv(pin.SE3(r, p)))
    for k in range(1, SEED_STEPS + 1):
        mk = m0 * pin.exp6(delta * (k / SEED_STEPS))
        q = solver.solve(mk.translation, mk.rotation, q)[0]
    return q


def solve_path(arm: ArmModel, targets: list[tuple[np.ndarray, np.ndarray]],
               q_start: np.ndarray | None = None) -> IKResult:
    """Solve IK along ``targets`` (position (3,), rotation (3, 3)), warm-started.

    Args:
        arm: the robot.
        targets: end-effector poses in the base frame.
        q_start: seed for the first target; the robot's posture when None.

    Returns:
        An :class:`IKResult`; on failure ``q`` holds the targets solved so far.
    """
    solver = _Solver(arm)
    if q_start is None:
        q = _seed(solver, *targets[0]) if targets else solver.posture.copy()
    else:
        q = np.asarray(q_start, dtype=float)
    out = np.empty((len(targets), arm.n))
    worst_p = worst_r = 0.0
    # The checks of each target read its few floats in Python: the same tests as
    # numpy's, without an array made for each.
    for i, (p, r) in enumerate(targets):
        if not (_finite(p) and _finite(r)):
            return IKResult(out[:i], worst_p, worst_r,
                            IKFailure(IKStatus.UNREACHABLE, i, np.inf, np.inf))
        q_new, pe, re, sigma = solver.solve(p, r, q)
        failure = None
        if not (_finite(q_new) and math.isfinite(pe) and math.isfinite(re)):
            failure = IKFailure(IKStatus.UNREACHABLE, i, np.inf, np.inf)
        elif pe > 1e-4 or re > 1e-3:
            at_limit = (q_new <= solver.lo + 1e-9) | (q_new >= solver.hi - 1e-9)
            if at_limit.any():
                j = arm.joint_names[int(np.argmax(at_limit))]
                failure = IKFailure(IKStatus.JOINT_LIMIT, i, pe, re, j)
            else:
                failure = IKFailure(IKStatus.UNREACHABLE, i, pe, re)
        elif sigma < MIN_SINGULAR:
            failure = IKFailure(IKStatus.SINGULARITY, i, pe, re)
        elif i > 0 and max(map(abs, map(operator.sub, q_new.tolist(), q.tolist()))) > MAX_STEP:
            j = arm.joint_names[int(np.argmax(np.abs(q_new - q)))]
            failure = IKFailure(IKStatus.DISCONTINUITY, i, pe, re, j)
        if failure is not None:
            return IKResult(out[:i], worst_p, worst_r, failure)
        out[i] = q = q_new
        worst_p, worst_r = max(worst_p, pe), max(worst_r, re)
    return IKResult(out, worst_p, worst_r)


def _finite(x: np.ndarray) -> bool:
    """Whether every value of a small array is finite (``np.isfinite(x).all()``)."""
    values = x.ravel() if isinstance(x, np.ndarray) else np.ravel(x)
    return all(map(math.isfinite, values.tolist()))
