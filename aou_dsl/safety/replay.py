"""Replaying a trajectory in PyBullet: is it safe to send to an arm next to a person?

**Kinematic replay** (every sample; `aouc compile` runs it by default):

- joint position, velocity and acceleration limits (:mod:`.limits`);
- self-collision between links that are neither adjacent (joined directly, or through
  links without a collision shape) nor listed in the robot's ``allowed_contacts``;
- contact with the target, a cube at the goal that nothing may touch (the task is a
  pre-grasp), and with the table plane (the robot's base stands on it and is exempt);
- agreement of two kinematics engines: the end-effector pose of the URDF (as PyBullet
  loads it) against Pinocchio's, within 1 mm and 0.5 deg.

Contacts and clearances are PyBullet's exact distances, asked only where they can have
changed enough to matter (:mod:`.sweep`): the verdicts, first samples of contact and
clearances are those of a query at every sample. The end-effector pose of every sample
comes from the replay's own kinematics of the URDF (:mod:`.fk`), compared with
Pinocchio's at every sample and with PyBullet's wherever PyBullet was put.

**Dynamic replay** (`aouc check`): the arm follows the trajectory under position control
with gravity, physics stepped at 1 kHz, each motor's force capped at the URDF effort
limit; its tracking error is a check of its own (:data:`.torque.TRACKING_LIMIT`). The
joint torques the trajectory needs come from inverse dynamics (:mod:`.torque`), not from
the capped motors (which can never read back more than their cap), and are checked
against the URDF effort limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..core.codes import R410
from ..core.memo import cached
from ..core.options import SceneOptions
from ..core.trajectory import Trajectory
from ..robot.load import load_arm, robot_key
from ..robot.scene import Scene, urdf_path
from .limits import Check, check_limits
from .sweep import CONTACT_MARGIN, QUERY_RANGE, Geometry, Memo, Sweep, geometry
from .urdf_fk import Chain, columns_fk, urdf_chain

__all__ = ["CheckReport", "check_scene", "replay"]

#: PyBullet and Pinocchio must agree on the end-effector pose within these.
AGREE_POSITION = 1e-3  # m
AGREE_ROTATION = 0.5  # deg
#: Self-clearance is sampled at this rate [Hz]; contacts are checked at every sample.
CLEARANCE_RATE = 10.0
#: Self-clearance counts link pairs nearer than this [m].
SELF_RANGE = 0.1
#: PyBullet's end-effector pose is compared at every sample the contact search puts
#: PyBullet in, and at least at this many samples spread over the motion.
AGREE_SPOTS = 32
#: Physics rate of the dynamic replay [Hz].
PHYSICS_RATE = 1000.0
#: The check that nothing touches the target cube at the goal.
TARGET_CONTACT = "target-contact"


@dataclass
class CheckReport:
    """The verdicts of every check, the clearances and the engines' agreement."""

    robot: str
    checks: list[Check]
    clearances: dict[str, float | None] = field(default_factory=dict)
    agreement: dict[str, float] = field(default_factory=dict)
    dynamic: dict[str, float] | None = None
    #: The checks that could not run (target-contact without a goal or a target cube),
    #: each with the reason in its detail: neither passed nor failed, so not in ``checks``.
    not_run: list[Check] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return all(c.ok for c in self.checks)

    def failed(self) -> list[Check]:
        return [c for c in self.checks if not c.ok]

    def to_json(self) -> dict:
        """The report as JSON; ``not_run`` (each check's name and why) only when a check
        could not run, so a report where every check ran is as before."""
        out = {"ok": self.ok, "robot": self.robot,
               "checks": [c.to_json() for c in self.checks],
               "clearances": self.clearances, "agreement": self.agreement,
               "dynamic": self.dynamic}
        if self.not_run:
            out["not_run"] = [{"name": c.name, "detail": c.detail} for c in self.not_run]
        return out


def _link_name(scene: Scene, j: int) -> str:
    if j == -1:
        return scene.pb.getBodyInfo(scene.body, physicsClientId=scene.client)[0].decode()
    return scene.pb.getJointInfo(scene.body, j, physicsClientId=scene.client)[12].decode()


def replay(tr: Trajectory, *, options: SceneOptions | None = None,
           dynamic: bool = False) -> CheckReport:
    """Check a trajectory (compiled or read from a file).

    Velocities and accelerations the trajectory lacks are differentiated from its
    positions; columns of joints the arm does not move are ignored.

    Args:
        tr: the trajectory; its goal is where the target cube stands.
        options: the scene (target size, table height).
        dynamic: also replay with physics (slower).

    Raises:
        AouError: R402 when the trajectory lacks a joint of the robot.
    """
    arm = load_arm(tr.robot, tr.ee_frame, tr.package_dirs, tr.ee_definition)
    cols = tr.columns(arm.joint_names)
    _bound(tr)
    t0 = float(tr.t[0])  # the replay runs from 0 (the arm at rest at the first sample)
    t, q = tr.t - t0, np.ascontiguousarray(tr.q[:, cols], dtype=float)
    if tr.qd is not None and tr.qdd is not None:
        qd, qdd = tr.qd[:, cols], tr.qdd[:, cols]
    else:
        qd = np.gradient(q, t, axis=0)
        qdd = np.gradient(qd, t, axis=0)
    checks = check_limits(arm, t, q, qd, qdd)
    goal = tuple(float(x) for x in tr.goal) if tr.goal is not None else None
    options = options or SceneOptions(package_dirs=tr.package_dirs)
    key = robot_key(tr.robot, options.package_dirs)
    scene, geo = _check_scene(tr.robot, options, key)
    if scene.target is not None:  # the scene's cube stands at the goal (or far away)
        scene.pb.resetBasePositionAndOrientation(scene.target, goal or _AWAY, (0, 0, 0, 1),
                                                 physicsClientId=scene.client)
    frame = tr.ee_frame or arm.spec.ee_frame
    memo = _memo(tr.robot, options, goal, key)
    memo.trim()
    sweep = Sweep(scene, geo, q, scene.link_index.get(frame, scene.joint_index.get(frame)),
                  target=goal is not None, memo=memo)
    kin_checks, clear = _contacts(sweep, t)
    agree_check, agree = _agreement(sweep, arm, frame, t, q, key)
    not_run = []
    if goal is None or scene.target is None:  # no cube at a goal: nothing to touch
        kin_checks = [c for c in kin_checks if c.name != TARGET_CONTACT]
        not_run.append(Check(TARGET_CONTACT, True, detail=(
            "not run: the trajectory has no goal, so there is no target cube"
            if goal is None else "not run: no target cube (--target-size 0)")))
    report = CheckReport(tr.robot, checks + kin_checks + [agree_check], clear, agree,
                         not_run=not_run)
    if dynamic:
        from .torque import check_torque

        torque, ratio = check_torque(arm, t, q, qd, qdd)
        track, report.dynamic = _dynamic(scene, arm, t, q, qd)
        report.dynamic["torque_max_ratio"] = ratio
        report.checks += [torque, track]
    report.checks = [c if c.time is None else replace(c, time=round(c.time + t0, 6))
                     for c in report.checks]  # times on the file's own clock
    return report


def _bound(tr: Trajectory) -> None:
    """Refuse (R410) a trajectory whose replay at :data:`PHYSICS_RATE` would take more
    steps than a recording may have samples: the work is bounded by the time it spans."""
    from ..core.diagnostics import AouError, Span, diag
    from ..core.inputs import ENV_SAMPLES, max_samples

    longest = max_samples() / PHYSICS_RATE
    if tr.duration > longest:
        raise AouError(diag(
            R410, f"`{tr.path}` spans {tr.duration:.6g} s; a check replays at most "
            f"{longest:g} s ({max_samples():,} steps at {PHYSICS_RATE:g} Hz)",
            Span.whole_file(tr.path), hint=f"check a part of it, or raise the bound with "
            f"{ENV_SAMPLES}; are the times in seconds?", limit=longest, variable=ENV_SAMPLES))

#: Where the target cube waits when a trajectory has no goal [m].
_AWAY = (0.0, 0.0, -100.0)


def check_scene(robot: str, options: SceneOptions) -> tuple[Scene, Geometry]:
    """A scene per robot (its files' content included) and options, kept with its
    geometry: loading the URDF is the slow part. Each replay sets the joint states, the
    cube's place and the physics settings it relies on."""
    return _check_scene(robot, options, robot_key(robot, options.package_dirs))


@cached(maxsize=8)
def _check_scene(robot: str, options: SceneOptions, key: tuple) -> tuple[Scene, Geometry]:
    scene = Scene(robot, _AWAY, options, visuals=False)
    return scene, geometry(scene, load_arm(robot, None, options.package_dirs).spec.allowed_contacts)


@cached(maxsize=8)
def _memo(robot: str, options: SceneOptions, goal: tuple[float, ...] | None,
          key: tuple) -> Memo:
    """What the sweeps in one scene with the cube at one goal measured, for the next
    replay there (a recompilation repeats most joint values: see :class:`.sweep.Memo`)."""
    return Memo()


def _contacts(sweep: Sweep, t: np.ndarray) -> tuple[list[Check], dict]:
    """Self-collision, target and table contact at every sample; the clearances (the
    self-clearance at :data:`CLEARANCE_RATE`)."""
    scene = sweep.scene
    step = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
    stride = max(1, int(round(1.0 / (CLEARANCE_RATE * step)))) if step > 0 else 1
    sweep.seed([len(t) // 2])
    checks = []
    self_clear = sweep.minimum("self", stride)
    hit = sweep.first_contact("self", lambda d: d < 0.0)
    if hit is None:
        checks.append(Check("self-collision", True,
                            detail=f"{len(sweep.geo.pairs)} link pairs checked"))
    else:
        i, p = hit
        it = sweep.items[p]
        checks.append(Check("self-collision", False, float(t[i]),
                            f"{_link_name(scene, it.a)} / {_link_name(scene, it.b)}",
                            sweep.measure(p, i), 0.0, "links penetrate (distance < 0)"))
    clear = {}
    for kind, what, detail in (
            ("target", "target", "the hand must never touch the object it is about to grasp"),
            ("table", "table", "no link but the base may touch the table plane")):
        low = sweep.minimum(kind)
        hit = None if low > CONTACT_MARGIN else sweep.first_contact(kind, lambda d: d <= 0.0)
        value = None
        if hit is not None:
            value = min(sweep.measure(p, hit[0]) for p, it in enumerate(sweep.items)
                        if it.kind == kind)
        checks.append(Check(f"{kind}-contact", hit is None,
                            None if hit is None else float(t[hit[0]]), what, value, 0.0,
                            detail))
        clear[kind] = low
    clear["self"] = self_clear if self_clear <= SELF_RANGE else math.inf

    def finite(x: float) -> float | None:
        return None if math.isinf(x) or x >= QUERY_RANGE else round(x, 6)

    return checks, {k: finite(clear[k]) for k in ("target", "self", "table")}


@cached(maxsize=16)
def _chain(robot: str, package_dirs: tuple[str, ...], frame: str, joints: tuple[str, ...],
           key: tuple) -> Chain:
    """The chain to ``frame`` in the URDF the check scene loads, per robot files (``key``,
    as :func:`~aou_dsl.robot.load.robot_key` gives it with the meshes): finding that URDF asks
    for the key again, a ``stat`` of every file the robot is made from."""
    return urdf_chain(urdf_path(robot, visuals=False, package_dirs=package_dirs)[0], frame,
                      joints)


def _agreement(sweep: Sweep, arm, frame: str, t: np.ndarray, q: np.ndarray, key: tuple
               ) -> tuple[Check, dict]:
    """The end-effector pose by the replay's own kinematics (the URDF, evaluated here)
    against the compiler's Pinocchio model at every sample (evaluated for all samples at
    once, and by Pinocchio itself at :data:`AGREE_SPOTS` samples spread over the
    motion), and against PyBullet's at every sample the replay put PyBullet in (those
    spots included)."""
    from ..robot.batch_fk import rows_fk

    spots = np.unique(np.linspace(0, len(t) - 1, AGREE_SPOTS).astype(int))
    for j in spots:
        sweep.visit(int(j))
    pos, cols = columns_fk(_chain(sweep.scene.robot, sweep.scene.options.package_dirs, frame,
                                  arm.joint_names, key), q)
    pin_pos, pin_rot = rows_fk(arm, q)
    dp = np.linalg.norm(pos - pin_pos, axis=1)
    dr = _angles_deg(cols, pin_rot)
    own_pos, own_rot = arm.fk(q[spots])  # Pinocchio's own forward kinematics
    dp[spots] = np.maximum(dp[spots], np.linalg.norm(pos[spots] - own_pos, axis=1))
    dr[spots] = np.maximum(dr[spots], _angles_deg(cols[:, :, spots], own_rot))
    if sweep.visited:
        order = sorted(sweep.visited)
        poses = [sweep.visited[j] for j in order]
        at = np.array(order)
        pb = sweep.scene.pb
        pb_pos = np.array([p for p, _ in poses])
        pb_rot = np.array([pb.getMatrixFromQuaternion(o) for _, o in poses]).reshape(-1, 3, 3)
        dp[at] = np.maximum(dp[at], np.linalg.norm(pos[at] - pb_pos, axis=1))
        dr[at] = np.maximum(dr[at], _angles_deg(cols[:, :, at], pb_rot))
    worst = int(np.argmax(np.maximum(dp / AGREE_POSITION, dr / AGREE_ROTATION)))
    worst_pos, worst_rot = float(dp.max()), float(dr.max())
    ok = worst_pos <= AGREE_POSITION and worst_rot <= AGREE_ROTATION
    check = Check("kinematics-agreement", ok, float(t[worst]), None, worst_pos, AGREE_POSITION,
                  f"end-effector pose against Pinocchio's: {worst_pos * 1000:.4f} mm, "
                  f"{worst_rot:.4f} deg (the URDF's kinematics at all {len(t)} samples, "
                  f"PyBullet's at {len(sweep.visited)} of them)")
    return check, {"position_mm": worst_pos * 1000, "rotation_deg": worst_rot}


def _angles_deg(cols: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """The angle between rotations [deg], accurate for small angles too: ``cols`` by
    columns (3, 3, N) as :func:`.urdf_fk.columns_fk` gives them, ``r2`` (N, 3, 3)."""

    # Columns as contiguous rows: a[i, k] is the rotations' [k, i] over the samples.
    a, b = cols, r2.transpose(2, 1, 0).copy()

    def rel(i: int, j: int) -> np.ndarray:  # (r1^T r2)[i, j] for every row
        return a[i, 0] * b[j, 0] + a[i, 1] * b[j, 1] + a[i, 2] * b[j, 2]

    cos = (rel(0, 0) + rel(1, 1) + rel(2, 2) - 1.0) / 2.0
    sin = np.sqrt((rel(2, 1) - rel(1, 2)) ** 2 + (rel(0, 2) - rel(2, 0)) ** 2
                  + (rel(1, 0) - rel(0, 1)) ** 2) / 2.0
    return np.degrees(np.arctan2(sin, cos))


def _dynamic(scene: Scene, arm, t: np.ndarray, q: np.ndarray, qd: np.ndarray
             ) -> tuple[Check, dict]:
    """Position control with physics; the arm starts at rest on the first sample. The
    scene is shared between replays, so gravity, time step and motors are set here.
    Returns the ``tracking-error`` check and the figures (``motor_torque_max_ratio``: the
    capped motors' torques read back, at most 1 by construction)."""
    pb, c, body = scene.pb, scene.client, scene.body
    pb.setGravity(0, 0, -9.81, physicsClientId=c)
    pb.setTimeStep(1.0 / PHYSICS_RATE, physicsClientId=c)
    scene.set_arm(q[0])
    joints = scene.arm
    steps = int(round(t[-1] * PHYSICS_RATE)) + 1
    ts = np.arange(steps) / PHYSICS_RATE
    q_ref = np.column_stack([np.interp(ts, t, q[:, j]) for j in range(arm.n)])
    qd_ref = np.column_stack([np.interp(ts, t, qd[:, j]) for j in range(arm.n)])
    forces = arm.effort.tolist()
    err = np.empty((steps, arm.n))
    tau = np.empty((steps, arm.n))
    for k in range(steps):
        pb.setJointMotorControlArray(body, joints, pb.POSITION_CONTROL,
                                     targetPositions=q_ref[k].tolist(),
                                     targetVelocities=qd_ref[k].tolist(),
                                     forces=forces, physicsClientId=c)
        pb.stepSimulation(physicsClientId=c)
        states = pb.getJointStates(body, joints, physicsClientId=c)
        err[k] = [s[0] for s in states] - q_ref[k]
        tau[k] = [s[3] for s in states]
    from .torque import check_tracking

    check = check_tracking(arm.joint_names, ts, err)
    dyn = {"physics_rate_hz": PHYSICS_RATE,
           "tracking_max_rad": float(np.abs(err).max()),
           "tracking_rms_rad": float(np.sqrt(np.mean(err ** 2))),
           "motor_torque_max_ratio": float((np.abs(tau) / arm.effort).max())}
    return check, dyn
