"""A rollout -> joint motion of the arm, checked and measured like a compiled trajectory.

The hand's poses are solved by the compiler's inverse kinematics
(:func:`aou_dsl.robot.ik.solve_path`, gaze locked on the new goal since the poses
are): at waypoints spaced as the compiler's, with its pull toward the arm's posture, then
every sample exactly from the spline through them (:func:`_reference`), so that the
redundancy is resolved as in a compile and never drifts. A hold repeats the joint
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

from ..core.codes import D603, D604, D605
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
    """Rotation matrices (N, 3, 3) of quaternions ``(w, x, y, z)`` (N, 4): pytransform3d's
    ``matrix_from_quaternion`` (the same arithmetic, so the same bits) on all rows at
    once; one call per sample cost a sixth of a live intensity change."""
    norm = np.linalg.norm(quat, axis=1)
    q = quat / np.where(norm == 0.0, 1.0, norm)[:, None]
    w, x, y, z = q.T
    x2, y2, z2 = 2.0 * x * x, 2.0 * y * y, 2.0 * z * z
    xy, xz, yz = 2.0 * x * y, 2.0 * x * z, 2.0 * y * z
    xw, yw, zw = 2.0 * x * w, 2.0 * y * w, 2.0 * z * w
    rows = [[1.0 - y2 - z2, xy - zw, xz + yw], [xy + zw, 1.0 - x2 - z2, yz - xw],
            [xz - yw, yz + xw, 1.0 - x2 - y2]]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=1)


def _progress(pos: np.ndarray, quat: np.ndarray) -> np.ndarray:
    """The hand's progress along the path at every sample, counted in the compiler's
    waypoint spacings (:data:`aou_dsl.compiler.pipeline.STEP_LENGTH` of travel,
    ``STEP_ANGLE`` of turn, whichever is more): constant through a hold."""
    from ..compiler.pipeline import STEP_ANGLE, STEP_LENGTH

    dp = np.linalg.norm(np.diff(pos, axis=0), axis=1) / STEP_LENGTH
    da = 2.0 * np.linalg.norm(np.diff(quat, axis=0), axis=1) / STEP_ANGLE
    return np.concatenate([[0.0], np.cumsum(np.maximum(dp, da))])


def _reference(arm: Any, pos: np.ndarray, quat: np.ndarray, rot: np.ndarray,
               seed: np.ndarray) -> tuple[np.ndarray, int, str]:
    """Joint positions near each pose that resolve the arm's redundancy as the compiler
    does: its inverse kinematics (the posture pulled in the null space) at waypoints one
    spacing apart along the hand's path, from ``seed`` (the first pose's solution), and
    a cubic spline through them over the progress, so that a hold keeps one
    configuration and a long sequence does not drift along the self-motion. Returns
    them (N, n), and the first sample that could not be reached (-1: none) with why."""
    import pytransform3d.rotations as pr
    from scipy.interpolate import CubicSpline

    from ..robot.ik import solve_path

    c = _progress(pos, quat)
    if c[-1] < 1e-9:
        return np.tile(seed, (len(pos), 1)), -1, ""
    steps = max(1, int(np.ceil(c[-1] - 1e-6)))
    at = np.linspace(0.0, c[-1], steps + 1)
    moving = np.concatenate([[True], np.diff(c) > 0])  # the first sample of each hold
    cm = c[moving]
    p = np.column_stack([np.interp(at, cm, pos[moving, j]) for j in range(3)])
    q4 = np.column_stack([np.interp(at, cm, quat[moving, j]) for j in range(4)])
    targets = [(p[k], pr.matrix_from_quaternion(q4[k] / np.linalg.norm(q4[k])))
               for k in range(1, len(at))]
    got = solve_path(arm, targets, seed)
    if not got.ok:
        assert got.failure is not None
        bad = int(np.searchsorted(c, at[1 + got.failure.index]))
        return np.empty((0, arm.n)), min(bad, len(c) - 1), got.failure.status.value
    return CubicSpline(at, np.vstack([seed, got.q]), axis=0)(c), -1, ""


def _follow(arm: Any, pos: np.ndarray, rot: np.ndarray, ref: np.ndarray
            ) -> tuple[np.ndarray, int, str]:
    """Damped least squares to each pose from its reference configuration
    (:func:`_reference`), without a pull: the exact pose, the redundancy the
    reference's. Returns the joint path (N, n), and the index of the first pose it
    could not follow (-1: none) with why."""
    import pinocchio as pin

    model, data, fid = arm.model, arm.model.createData(), arm.frame_id
    out = np.empty((len(pos), arm.n))
    damped = 1e-8 * np.eye(6)
    converged = False
    held = np.concatenate([[False], np.all(pos[1:] == pos[:-1], axis=1)
                           & np.all(rot[1:] == rot[:-1], axis=(1, 2))
                           & np.all(ref[1:] == ref[:-1], axis=1)])
    for i in range(len(pos)):
        if converged and held[i]:
            out[i] = out[i - 1]  # a hold: the pose the last solve reached already
            continue
        q = ref[i].copy()
        target = pin.SE3(rot[i], pos[i])
        for _ in range(30):
            pin.computeJointJacobians(model, data, q)
            dm = pin.updateFramePlacement(model, data, fid).actInv(target)
            err = pin.log6(dm).vector
            converged = float(np.abs(err).max()) < 1e-9
            if converged:
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


def _unchanged(ro: Rollout, prior: Rollout) -> int:
    """How many first samples of ``ro`` are those of ``prior``: same time, pose, part and
    shiver."""
    n = min(len(ro.t), len(prior.t))
    same = ((ro.t[:n] == prior.t[:n]) & (ro.part[:n] == prior.part[:n])
            & np.all(ro.pos[:n] == prior.pos[:n], axis=1)
            & np.all(ro.quat[:n] == prior.quat[:n], axis=1)
            & np.all(ro.shiver[:, :n] == prior.shiver[:, :n], axis=0))
    return int(np.argmin(same)) if not same.all() else n


def to_trajectory(seq: DmpSequence, ro: Rollout, where: Span,
                  reuse: tuple[Rollout, Any] | None = None) -> Any:
    """The joint trajectory of ``ro``.

    Args:
        reuse: a rollout of the same sequence and its joint trajectory (made by this
            function): the samples ``ro`` shares with it from the start keep their
            joint positions, and only the rest is solved, continued from the last kept
            one (a running behaviour whose later parts changed, :mod:`.intensity`).

    Raises:
        AouError: D603 when the inverse kinematics cannot follow the poses.
    """
    from ..core.trajectory import Trajectory
    from ..robot.ik import solve_path
    from ..robot.load import load_arm

    arm = load_arm(seq.robot, seq.ee_frame)
    js = arm.joint_names.index(seq.shiver_joint)
    keep = _unchanged(ro, reuse[0]) if reuse is not None else 0
    if keep > 1:
        assert reuse is not None
        kept = np.array(reuse[1].q[:keep], dtype=float)
        kept[:, js] -= reuse[0].shiver[0, :keep]
        seed = kept[-1].copy()
    else:
        keep, kept = 0, np.empty((0, arm.n))
        first = solve_path(arm, [(ro.pos[0], _rot(ro.quat[:1])[0])])
        if not first.ok:
            assert first.failure is not None
            raise AouError(diag(D603, "the arm cannot reach the rolled-out start: "
                                f"{first.failure.status.value}", where, time=0.0))
        seed = first.q[0].copy()
    pos, quat = ro.pos[keep:], ro.quat[keep:]
    rot = _rot(quat)
    ref, bad, why = _reference(arm, pos, quat, rot, seed)
    if bad < 0:
        q, bad, why = _follow(arm, pos, rot, ref)
    if bad >= 0:
        bad += keep
        kind = ro.parts[ro.part[bad]][0]
        raise AouError(diag(D603, f"the arm cannot follow the rolled-out {kind} at "
                            f"t={ro.t[bad]:.3f}s: {why}", where, time=float(ro.t[bad])))
    q = np.vstack([kept, q])
    qd = np.gradient(q, ro.t, axis=0)
    qdd = np.gradient(qd, ro.t, axis=0)
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
                D604, f"the rolled-out motion fails the {c.name} check at "
                f"t={(c.time or 0.0):.3f}s: {c.joint or ''}{value}{limit}", where,
                check=c.name, time=c.time, joint=c.joint, value=c.value, limit=c.limit))
        if has_errors(out.diagnostics):
            return out
    out.measured = m = measure(tr)
    for mm in compare(ro.predicted, m.descriptors):
        out.diagnostics.append(diag(
            D605, f"{mm.name}: the scaling rule predicts {_fmt(mm.declared)}, measured "
            f"{_fmt(mm.measured)}", where, descriptor=mm.name, predicted=mm.declared,
            measured=mm.measured))
    return out


def _fmt(v: Any) -> str:
    return "absent" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v))
