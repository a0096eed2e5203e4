"""Stage 5, inverse kinematics: end-effector targets -> a continuous joint path.

Damped least squares on the full 6-D pose error ``log6(M(q)^-1 T)`` (position and the
locked gaze, roll included), with the robot's posture pulled in the null space so the
redundancy of a 7-joint arm is resolved the same way every time. Each target is solved
warm-started from the previous one, so the path is continuous (no branch flips) and
stays a margin inside the joint limits.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np

from ..kinematics import ArmModel

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

    def solve(self, p: np.ndarray, r: np.ndarray, q0: np.ndarray
              ) -> tuple[np.ndarray, float, float, float]:
        """One target from ``q0``: returns q, position error, rotation error, and the
        smallest singular value of the Jacobian at the solution."""
        pin = self.pin
        target = pin.SE3(r, p)
        q = q0.copy()
        n = len(q)
        fid = self.arm.frame_id
        eye6 = np.eye(6)
        for it in range(MAX_ITER + 1):
            # One pass: forward kinematics and every joint's Jacobian; then the frame's
            # placement and Jacobian from them.
            pin.computeJointJacobians(self.model, self.data, q)
            dm = pin.updateFramePlacement(self.model, self.data, fid).actInv(target)
            jac = pin.getFrameJacobian(self.model, self.data, fid, pin.LOCAL)
            err = pin.log6(dm).vector
            pe, re = float(np.linalg.norm(err[:3])), float(np.linalg.norm(err[3:]))
            if (pe < POS_TOL and re < ROT_TOL) or it == MAX_ITER:
                break
            je = -pin.Jlog6(dm.inverse()) @ jac
            pinv = je.T @ np.linalg.solve(je @ je.T + DAMPING * eye6, eye6)
            dq = -pinv @ err
            if it < POSTURE_ITERS:
                dq += (np.eye(n) - pinv @ je) @ (POSTURE_GAIN * (self.posture - q))
            step = np.max(np.abs(dq))
            if step > MAX_ITER_STEP:  # far from the target: Newton steps overshoot
                dq *= MAX_ITER_STEP / step
            q = np.clip(q + dq, self.lo, self.hi)
        if not np.all(np.isfinite(jac)):
            return q, np.inf, np.inf, 0.0  # diverged: the caller reports it unreachable
        sigma = float(np.linalg.svd(jac, compute_uv=False)[-1])
        return q, pe, re, sigma


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
    for i, (p, r) in enumerate(targets):
        if not (np.all(np.isfinite(p)) and np.all(np.isfinite(r))):
            return IKResult(out[:i], worst_p, worst_r,
                            IKFailure(IKStatus.UNREACHABLE, i, np.inf, np.inf))
        q_new, pe, re, sigma = solver.solve(p, r, q)
        failure = None
        if not (np.all(np.isfinite(q_new)) and np.isfinite(pe) and np.isfinite(re)):
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
        elif i > 0 and np.max(np.abs(q_new - q)) > MAX_STEP:
            j = arm.joint_names[int(np.argmax(np.abs(q_new - q)))]
            failure = IKFailure(IKStatus.DISCONTINUITY, i, pe, re, j)
        if failure is not None:
            return IKResult(out[:i], worst_p, worst_r, failure)
        out[i] = q = q_new
        worst_p, worst_r = max(worst_p, pe), max(worst_r, re)
    return IKResult(out, worst_p, worst_r)
