"""What the arm shows: a trajectory tracked through the arm's servos, simulated in MuJoCo.

A real arm does not play samples: each joint's servo tracks them, and tracking filters
motion (a fast shiver sent as plain set-points arrives smaller and late). This module
builds the arm from the very URDF aou compiled for (MuJoCo's ``MjSpec`` reads URDF; the
visual and collision shapes are dropped, only masses, inertias and joints matter here),
gives every arm joint the servo of the arm's table (:mod:`aou_dsl.core.servo_specs`) as
a MuJoCo position actuator (``kp``, ``kv``, force limit; the joint's armature and
damping), locks every other joint, and steps the physics at the controller's rate with
gravity, the command held between steps as a controller holds it.

Modes (:data:`~aou_dsl.core.servo_specs.MODES`), what the controller is sent:

- ``position``: the planned positions alone, ``tau = kp (q_ref - q) - kv qd``;
- ``feedforward``: positions and the velocities the trajectory carries,
  ``tau = kp (q_ref - q) + kv (qd_ref - qd)``;
- ``torque``: that, plus the torque inverse dynamics gives for the planned motion
  (gravity, inertia and the joint's damping, from the same model): computed torque.

Every torque is clipped at the servo's force limit. Before the motion the arm is held at
the first sample for :data:`SETTLE` s under the same law, so gravity's sag is settled and
not read as motion.
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass

import numpy as np

from ..core.memo import cached
from ..core.servo_specs import MODES, ServoTable, generic_table, servo_table
from ..core.trajectory import Trajectory

__all__ = ["SETTLE", "Tracked", "arm_servo", "reference", "track"]

#: Time the arm is held at the first sample before the motion [s].
SETTLE = 0.5


@dataclass(frozen=True)
class Tracked:
    """A trajectory as the arm's servos tracked it.

    Attributes:
        mode: the servo mode (of :data:`~aou_dsl.core.servo_specs.MODES`).
        trajectory: the tracked motion at the plan's sample times, positions only (a
            recording: ``aouc measure`` reads it as it reads a logged one).
        error_max, error_rms: tracking error per arm joint [rad], shape (n,), over the
            controller's steps.
        saturated: share of the controller's steps each joint spent at its force limit,
            shape (n,).
        steps: controller steps simulated (the hold before included); seconds: wall time.
    """

    mode: str
    trajectory: Trajectory
    error_max: np.ndarray
    error_rms: np.ndarray
    saturated: np.ndarray
    steps: int
    seconds: float


def arm_servo(robot: str, package_dirs: tuple[str, ...] = ()) -> tuple[ServoTable, bool]:
    """The servo table of ``robot`` and whether it is the generic one (no table known).

    A robot description's ``[servo]`` table comes first, then a built-in arm's table
    (a description that extends a built-in arm keeps its table), then the generic servo.

    Raises:
        AouError: V109 for a ``[servo]`` table that does not fit the arm.
    """
    from ..robot.load import load_robot

    r = load_robot(robot, package_dirs)
    n = len(r.spec.arm_joints)
    if r.description:
        from ..robot.description import read_description

        desc = read_description(r.description)
        if desc.servo is not None:
            return _own_table(r.description, desc.servo, n), False
        if desc.robot and servo_table(desc.robot) is not None:
            return servo_table(desc.robot), False  # type: ignore[return-value]
    table = servo_table(robot)
    return (table, False) if table is not None else (generic_table(n), True)


def _own_table(path: str, servo: dict, n: int) -> ServoTable:
    """A description's ``[servo]`` table (checked by the reader) made to the arm's
    ``n`` joints: a named published table, or the gains given (one number for every
    joint, or one per joint; kv, damping and armature 0 and the URDF's effort limits
    where it gives none; 1 kHz and every mode unless it says)."""
    from ..core.codes import V109
    from ..core.diagnostics import AouError, Span, diag
    from ..core.servo_specs import SERVOS

    def bad(message: str) -> AouError:
        return AouError(diag(V109, f"robot description `{path}`: [servo] {message}",
                             Span.whole_file(path)))

    if "table" in servo:
        table = servo_table(servo["table"])
        if table is None:
            raise bad(f"names no table aou knows: `{servo['table']}` (tables: "
                      f"{', '.join(sorted(SERVOS))})")
        if table.n != n:
            raise bad(f"table `{servo['table']}` is for {table.n} joints, the arm has {n}")
        return table
    rows = {}
    for key in ("kp", "kv", "damping", "armature", "force"):
        v = servo.get(key, (0.0,))
        if len(v) not in (1, n):
            raise bad(f"`{key}` has {len(v)} numbers: give one, or one per arm joint ({n})")
        rows[key] = tuple(v) * n if len(v) == 1 else tuple(v)
    return ServoTable(**rows, rate=servo.get("rate", 1000.0),
                      modes=servo.get("modes", MODES),
                      source=servo.get("source", f"the robot description `{path}`"))


def _model(robot: str, package_dirs: tuple[str, ...], servo: ServoTable):
    """The MuJoCo model of ``robot``'s arm with ``servo``'s actuators, and the qpos
    addresses of the arm joints (shape (n,)); kept per robot, folders and table, and the
    bytes of the robot's files (an edited URDF is a new model)."""
    from ..robot.load import robot_key

    return _built(robot_key(robot, package_dirs, meshes=False), robot, package_dirs, servo)


@cached(maxsize=8)
def _built(key: tuple, robot: str, package_dirs: tuple[str, ...], servo: ServoTable):
    import mujoco

    from ..core.codes import V109
    from ..core.diagnostics import AouError, Span, diag
    from ..robot.load import load_arm, load_robot

    r = load_robot(robot, package_dirs)
    arm = load_arm(robot, None, package_dirs)
    text = re.sub(r"<(visual|collision)\b.*?</\1>|<(visual|collision)\b[^>]*/>", "",
                  r.urdf.text, flags=re.S)
    try:
        spec = mujoco.MjSpec.from_string(text)
        spec.option.timestep = 1.0 / servo.rate
        spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        arm_joints = set(arm.joint_names)
        for eq in list(spec.equalities):  # a URDF's mimic joints: the gripper's
            spec.delete(eq)
        for joint in list(spec.joints):
            if joint.name not in arm_joints:
                spec.delete(joint)  # grippers and the like: welded where they stand
        by_name = {j.name: j for j in spec.joints}
        for k, name in enumerate(arm.joint_names):
            joint = by_name[name]
            joint.armature, joint.frictionloss = servo.armature[k], 0.0
            joint.damping = [servo.damping[k], 0.0, 0.0]  # linear damping alone
            force = servo.force[k] or float(arm.effort[k])
            act = spec.add_actuator(name=f"servo_{name}", target=name,
                                    trntype=mujoco.mjtTrn.mjTRN_JOINT)
            act.set_to_position(kp=servo.kp[k], kv=servo.kv[k])
            act.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
            if np.isfinite(force) and force > 0:
                act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
                act.forcerange = [-force, force]
        model = spec.compile()
    except (ValueError, KeyError) as err:  # MuJoCo's own parse and compile errors
        raise AouError(diag(V109, f"robot `{robot}`: MuJoCo cannot build its arm for "
                            f"tracking: {err}", Span.whole_file(f"<robot {robot}>"))) from err
    adr = np.array([model.jnt_qposadr[model.joint(n).id] for n in arm.joint_names])
    dof = np.array([model.jnt_dofadr[model.joint(n).id] for n in arm.joint_names])
    return model, adr, dof


def reference(tr: Trajectory, cols: np.ndarray, rate: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The plan at the controller's rate, as a trajectory controller interpolates it:
    cubic Hermite between samples on the positions and velocities (velocities
    differentiated from the positions when the trajectory has none), accelerations
    linear. Returns the step times (M,) and q, qd, qdd, each (M, n)."""
    t = tr.t - tr.t[0]
    q = np.asarray(tr.q[:, cols], dtype=float)
    qd = tr.qd[:, cols] if tr.qd is not None else np.gradient(q, t, axis=0)
    qdd = tr.qdd[:, cols] if tr.qdd is not None else np.gradient(qd, t, axis=0)
    ts = np.arange(int(np.floor(t[-1] * rate + 1e-9)) + 1) / rate
    i = np.clip(np.searchsorted(t, ts, side="right") - 1, 0, len(t) - 2)
    h = (t[i + 1] - t[i])[:, None]
    s = ((ts - t[i])[:, None]) / h
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, \
        s**3 - s**2
    qr = h00 * q[i] + h10 * h * qd[i] + h01 * q[i + 1] + h11 * h * qd[i + 1]
    d00, d10, d01, d11 = 6 * s**2 - 6 * s, 3 * s**2 - 4 * s + 1, -6 * s**2 + 6 * s, \
        3 * s**2 - 2 * s
    qdr = (d00 * q[i] + d01 * q[i + 1]) / h + d10 * qd[i] + d11 * qd[i + 1]
    qddr = qdd[i] + s * (qdd[i + 1] - qdd[i])
    return ts, qr, qdr, qddr


def _commands(model, adr, dof, servo: ServoTable, mode: str, qr: np.ndarray,
              qdr: np.ndarray, qddr: np.ndarray, stride: int = 1) -> np.ndarray:
    """The position actuators' control of every step: the set-point, shifted by the
    velocity and torque terms of the mode (``kp ctrl - kp q - kv qd`` is the torque)."""
    kp, kv = np.array(servo.kp), np.array(servo.kv)
    if mode == "position":
        return qr.copy()
    u = qr + (kv / kp) * qdr
    if mode == "torque":
        import mujoco

        # Inverse dynamics at every ``stride``-th step, linear between: the plan's
        # torque is as smooth as its accelerations, sampled at the plan's rate.
        data = mujoco.MjData(model)
        at = np.unique(np.r_[np.arange(0, len(qr), stride), len(qr) - 1])
        tau = np.empty((len(at), qr.shape[1]))
        for i, k in enumerate(at):
            data.qpos[adr], data.qvel[dof], data.qacc[dof] = qr[k], qdr[k], qddr[k]
            mujoco.mj_inverse(model, data)
            tau[i] = data.qfrc_inverse[dof]
        steps = np.arange(len(qr))
        u += np.column_stack([np.interp(steps, at, tau[:, j]) for j in range(qr.shape[1])]
                             ) / kp
    return u


def track(tr: Trajectory, mode: str = "position", servo: ServoTable | None = None
          ) -> Tracked:
    """Simulate the arm tracking ``tr`` through its servos in ``mode``.

    Args:
        tr: the plan (compiled, or a trajectory file); its robot's URDF is the model.
        mode: one of :data:`~aou_dsl.core.servo_specs.MODES`.
        servo: the servo table (default: :func:`arm_servo`'s).
    """
    import mujoco

    from ..robot.load import load_arm

    if mode not in MODES:
        raise ValueError(f"unknown servo mode {mode!r}: expected one of {', '.join(MODES)}")
    servo = servo or arm_servo(tr.robot, tr.package_dirs)[0]
    arm = load_arm(tr.robot, tr.ee_frame, tr.package_dirs, tr.ee_definition)
    cols = tr.columns(arm.joint_names)
    model, adr, dof = _model(tr.robot, tr.package_dirs, servo)
    start = time.perf_counter()
    ts, qr, qdr, qddr = reference(tr, cols, servo.rate)
    step = float(np.median(np.diff(tr.t))) if len(tr.t) > 1 else 1.0 / servo.rate
    stride = max(1, int(step * servo.rate))
    u = _commands(model, adr, dof, servo, mode, qr, qdr, qddr, stride)
    data = mujoco.MjData(model)
    data.qpos[adr] = qr[0]
    hold = int(round(SETTLE * servo.rate))
    data.ctrl[:] = u[0]  # held at the first sample (a plan starts at rest)
    for _ in range(hold):
        mujoco.mj_step(model, data)
    got = np.empty_like(qr)
    force = np.empty_like(qr)
    for k in range(len(ts)):
        got[k] = data.qpos[adr]
        data.ctrl[:] = u[k]
        mujoco.mj_step(model, data)
        force[k] = data.actuator_force
    seconds = time.perf_counter() - start
    limit = np.where(model.actuator_forcelimited.astype(bool),
                     model.actuator_forcerange[:, 1], np.inf)
    err = got - qr
    q = np.array(tr.q, dtype=float)
    t = tr.t - tr.t[0]
    for j, c in enumerate(cols):
        q[:, c] = np.interp(t, ts, got[:, j])
    out = tr.with_(q=q, qd=None, qdd=None, path=f"{tr.path} tracked ({mode})")
    return Tracked(mode, out, np.abs(err).max(axis=0), np.sqrt(np.mean(err**2, axis=0)),
                   np.mean(np.abs(force) >= limit * (1 - 1e-9), axis=0),
                   hold + len(ts), seconds)

