"""A rollout -> joint motion of the arm, checked and measured like a compiled trajectory.

The hand's poses are solved by the compiler's inverse kinematics
(:func:`aou_dsl.robot.ik.solve_path`, gaze locked on the new goal since the poses
are), warm-started from the sequence's start configuration. A hold repeats the joint
configuration of its pose (a pause is all joints at rest); a shiver adds its offset to
the shiver joint, as the compiler does. Velocities and accelerations are differentiated
from the positions (the shiver's are analytic). Then the same safety replay as
``aouc compile`` (:func:`aou_dsl.safety.replay.replay`) and the same measurement
(:func:`aou_dsl.measuring.measured.measure`); each descriptor is compared with the
scaling rule's prediction within the descriptor's tolerance.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.diagnostics import AouError, Diagnostic, Span, diag, has_errors
from .export import DmpSequence
from .rollout import Rollout, roll

__all__ = ["Solved", "solve", "to_trajectory"]


@dataclass
class Solved:
    """A sequence rolled out, solved, checked and measured.

    ``ok`` when it passed every check and measures as predicted (D605 warnings aside)."""

    rollout: Rollout
    trajectory: Any = None
    measured: Any = None
    checks: list = field(default_factory=list)
    diagnostics: list[Diagnostic] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return self.trajectory is not None and not has_errors(self.diagnostics)


def _rot(quat: np.ndarray) -> np.ndarray:
    import pytransform3d.rotations as pr

    return np.array([pr.matrix_from_quaternion(q) for q in quat])


def _follow(arm: Any, pos: np.ndarray, rot: np.ndarray, q: np.ndarray
            ) -> tuple[np.ndarray, int, str]:
    """Damped least squares along dense poses, each solve warm-started from the last, with
    no pull toward a posture (a pull at every millisecond would swing the null space):
    the redundancy moves only as the hand does. Returns the joint path (N, n), and the
    index of the first pose it could not follow (-1: none) with why."""
    import pinocchio as pin

    model, data, fid = arm.model, arm.model.createData(), arm.frame_id
    out = np.empty((len(pos), arm.n))
    damped = 1e-8 * np.eye(6)
    for i in range(len(pos)):
        target = pin.SE3(rot[i], pos[i])
        for _ in range(30):
            pin.computeJointJacobians(model, data, q)
            dm = pin.updateFramePlacement(model, data, fid).actInv(target)
            err = pin.log6(dm).vector
            if float(np.abs(err).max()) < 1e-9:
                break
            je = -pin.Jlog6(dm.inverse()) @ pin.getFrameJacobian(model, data, fid, pin.LOCAL)
            q = q - je.T @ np.linalg.solve(je @ je.T + damped, err)
        if float(np.abs(err).max()) > 1e-6:
            return out[:i], i, "a pose lies outside the robot's workspace"
        outside = (q < arm.lower) | (q > arm.upper)
        if outside.any():
            return out[:i], i, f"{arm.joint_names[int(np.argmax(outside))]} past its limit"
        out[i] = q
    return out, -1, ""


def to_trajectory(seq: DmpSequence, ro: Rollout, where: Span) -> Any:
    """The joint trajectory of ``ro``.

    Raises:
        AouError: D603 when the inverse kinematics cannot follow the poses.
    """
    from ..core.trajectory import Trajectory
    from ..robot.ik import solve_path
    from ..robot.load import load_arm

    arm = load_arm(seq.robot, seq.ee_frame)
    rot = _rot(ro.quat)
    # The start as the compiler reaches it: by continuation from the arm's posture.
    first = solve_path(arm, [(ro.pos[0], rot[0])])
    if not first.ok:
        assert first.failure is not None
        raise AouError(diag("D603", "the arm cannot reach the rolled-out start: "
                            f"{first.failure.status.value}", where, time=0.0))
    q, bad, why = _follow(arm, ro.pos, rot, first.q[0].copy())
    if bad >= 0:
        kind = ro.parts[ro.part[bad]][0]
        raise AouError(diag("D603", f"the arm cannot follow the rolled-out {kind} at "
                            f"t={ro.t[bad]:.3f}s: {why}", where, time=float(ro.t[bad])))
    qd = np.gradient(q, ro.t, axis=0)
    qdd = np.gradient(qd, ro.t, axis=0)
    js = arm.joint_names.index(seq.shiver_joint)
    shaking = ro.shiver[0] != 0.0
    q[:, js] += ro.shiver[0]
    qd[shaking, js] = ro.shiver[1, shaking]
    qdd[shaking, js] = ro.shiver[2, shaking]
    return Trajectory(ro.t, q, tuple(arm.joint_names), seq.robot, seq.ee_frame, ro.goal,
                      qd, qdd, tuple(ro.parts), where.path, seq.behaviour)


def solve(seq: DmpSequence, *, path: str = "<dmp>", check: bool = True,
          **options: Any) -> Solved:
    """Roll ``seq`` out (``options`` as :func:`aou_dsl.dmp.rollout.roll`), solve it for
    the arm, check and measure it.

    Diagnostics: D603 (the arm cannot follow), D604 (a safety check fails: the message
    names the check, the joint and the limit), D605 (a descriptor is not what its
    scaling rule predicts).
    """
    from ..lang.descriptors import compare
    from ..measuring.measured import measure

    where = Span.whole_file(path)
    ro = roll(seq, **options)
    out = Solved(ro)
    try:
        out.trajectory = tr = to_trajectory(seq, ro, where)
    except AouError as err:
        out.diagnostics += err.diagnostics
        return out
    if check:
        from ..safety.replay import replay

        report = replay(tr)
        out.checks = report.checks
        for c in report.failed():
            limit = f", limit {c.limit:.4g}" if c.limit is not None else ""
            value = f" reaches {c.value:.4g}" if c.value is not None else ""
            out.diagnostics.append(diag(
                "D604", f"the rolled-out motion fails the {c.name} check at "
                f"t={(c.time or 0.0):.3f}s: {c.joint or ''}{value}{limit}", where,
                check=c.name, time=c.time, joint=c.joint, value=c.value, limit=c.limit))
        if has_errors(out.diagnostics):
            return out
    out.measured = m = measure(tr)
    for mm in compare(ro.predicted, m.descriptors):
        out.diagnostics.append(diag(
            "D605", f"{mm.name}: the scaling rule predicts {_fmt(mm.declared)}, measured "
            f"{_fmt(mm.measured)}", where, descriptor=mm.name, predicted=mm.declared,
            measured=mm.measured))
    return out


def _fmt(v: Any) -> str:
    return "absent" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v))
