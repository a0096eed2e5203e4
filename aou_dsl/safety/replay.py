"""Replaying a trajectory in PyBullet: is it safe to send to an arm next to a person?

**Kinematic replay** (every sample; `aouc compile` runs it by default):

- joint position, velocity and acceleration limits (:mod:`.limits`);
- self-collision between links that are neither adjacent (joined directly, or through
  links without a collision shape) nor listed in the robot's ``allowed_contacts``;
- contact with the target, a cube at the goal that nothing may touch (the task is a
  pre-grasp), and with the table plane (the robot's base stands on it and is exempt);
- agreement of two kinematics engines: the end-effector pose from PyBullet against
  Pinocchio's, within 1 mm and 0.5 deg.

**Dynamic replay** (`aouc check`): the arm follows the trajectory under position control
with gravity, physics stepped at 1 kHz; the report gives the maximum and RMS tracking
error and the joint torques against the URDF effort limits (a check).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..kinematics import load_arm
from ..trajectory import Trajectory
from .limits import Check, check_limits
from .scene import Scene, SceneOptions

__all__ = ["CheckReport", "replay"]

#: PyBullet and Pinocchio must agree on the end-effector pose within these.
AGREE_POSITION = 1e-3  # m
AGREE_ROTATION = 0.5  # deg
#: Self-clearance is sampled at this rate [Hz]; contacts are checked at every sample.
CLEARANCE_RATE = 10.0
#: Physics rate of the dynamic replay [Hz].
PHYSICS_RATE = 1000.0


@dataclass
class CheckReport:
    """The verdicts of every check, the clearances and the engines' agreement."""

    robot: str
    checks: list[Check]
    clearances: dict[str, float | None] = field(default_factory=dict)
    agreement: dict[str, float] = field(default_factory=dict)
    dynamic: dict[str, float] | None = None

    @property
    def ok(self) -> bool:
        return all(c.ok for c in self.checks)

    def failed(self) -> list[Check]:
        return [c for c in self.checks if not c.ok]

    def to_json(self) -> dict:
        return {"ok": self.ok, "robot": self.robot,
                "checks": [c.to_json() for c in self.checks],
                "clearances": self.clearances, "agreement": self.agreement,
                "dynamic": self.dynamic}


def _pairs(scene: Scene, allowed: tuple[tuple[str, str], ...]) -> list[tuple[int, int]]:
    """Link pairs that must not touch: not adjacent (through shapeless links) and not
    allowed by the robot table."""
    pb, c, body = scene.pb, scene.client, scene.body
    n = pb.getNumJoints(body, physicsClientId=c)
    parent = {j: pb.getJointInfo(body, j, physicsClientId=c)[16] for j in range(n)}
    shaped = {j for j in range(-1, n) if pb.getCollisionShapeData(body, j, physicsClientId=c)}

    def shaped_parent(j: int) -> int:
        p = parent.get(j, -1)
        while p != -1 and p not in shaped:
            p = parent.get(p, -1)
        return p

    by_name = {name: j for name, j in scene.link_index.items()}
    allowed_ids = {frozenset((by_name[a], by_name[b])) for a, b in allowed}
    links = sorted(shaped)
    out = []
    for i, a in enumerate(links):
        for b in links[i + 1:]:
            if shaped_parent(b) == a or shaped_parent(a) == b:
                continue
            if frozenset((a, b)) in allowed_ids:
                continue
            out.append((a, b))
    return out


def _base_links(scene: Scene) -> set[int]:
    """The root link and every link welded to it by fixed joints (UR5: ``world`` and
    ``base_link``): the robot stands on the table through them."""
    pb, c, body = scene.pb, scene.client, scene.body
    base = {-1}
    for j in range(pb.getNumJoints(body, physicsClientId=c)):
        info = pb.getJointInfo(body, j, physicsClientId=c)
        if info[2] == pb.JOINT_FIXED and info[16] in base:
            base.add(j)
    return base


def _link_name(scene: Scene, j: int) -> str:
    if j == -1:
        return scene.pb.getBodyInfo(scene.body, physicsClientId=scene.client)[0].decode()
    return scene.pb.getJointInfo(scene.body, j, physicsClientId=scene.client)[12].decode()


def _angle_deg(r1: np.ndarray, r2: np.ndarray) -> float:
    c = (np.trace(r1.T @ r2) - 1.0) / 2.0
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


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
    arm = load_arm(tr.robot, tr.ee_frame)
    cols = tr.columns(arm.joint_names)
    t, q = tr.t, tr.q[:, cols]
    if tr.qd is not None and tr.qdd is not None:
        qd, qdd = tr.qd[:, cols], tr.qdd[:, cols]
    else:
        qd = np.gradient(q, t, axis=0)
        qdd = np.gradient(qd, t, axis=0)
    checks = check_limits(arm, t, q, qd, qdd)
    goal = tuple(float(x) for x in tr.goal) if tr.goal is not None else None
    scene = _scene(tr.robot, goal, options or SceneOptions())
    kin_checks, clear, agree = _kinematic(scene, arm, t, q)
    checks += kin_checks
    report = CheckReport(tr.robot, checks, clear, agree)
    if dynamic:
        dyn_check, report.dynamic = _dynamic(scene, arm, t, q, qd)
        report.checks.append(dyn_check)
    return report


_SCENES: dict = {}


def _scene(robot: str, goal: tuple[float, ...] | None, options: SceneOptions) -> Scene:
    """A scene per robot, goal and options, kept: loading the URDF is the slow part.
    Each replay sets the joint states and physics settings it relies on."""
    key = (robot, goal, options)
    if key not in _SCENES:
        if len(_SCENES) >= 8:
            for old in _SCENES.values():
                old.close()
            _SCENES.clear()
        _SCENES[key] = Scene(robot, goal, options)
    return _SCENES[key]


def _kinematic(scene: Scene, arm, t: np.ndarray, q: np.ndarray
               ) -> tuple[list[Check], dict, dict]:
    pb, c, body = scene.pb, scene.client, scene.body
    pairs = _pairs(scene, arm.spec.allowed_contacts)
    pair_set = {frozenset(p) for p in pairs}
    base = _base_links(scene)
    pin_pos, pin_rot = arm.fk(q)
    self_hit = target_hit = table_hit = None
    self_clear = target_clear = table_clear = math.inf
    worst_pos = worst_rot = 0.0
    worst_agree_t = None
    stride = max(1, int(round(1.0 / (CLEARANCE_RATE * float(np.median(np.diff(t)))))))
    for i, qi in enumerate(q):
        scene.set_arm(qi)
        pb.performCollisionDetection(physicsClientId=c)
        if self_hit is None:
            for cp in pb.getContactPoints(body, body, physicsClientId=c):
                if cp[8] < 0 and frozenset((cp[3], cp[4])) in pair_set:
                    self_hit = (i, cp[3], cp[4], cp[8])
                    break
        if scene.target is not None:
            d = [p[8] for p in pb.getClosestPoints(body, scene.target, 1.0,
                                                   physicsClientId=c)]
            if d:
                target_clear = min(target_clear, min(d))
                if target_hit is None and min(d) <= 0.0:
                    target_hit = (i, min(d))
        if scene.table is not None:
            d = [p[8] for p in pb.getClosestPoints(body, scene.table, 1.0, physicsClientId=c)
                 if p[3] not in base]
            if d:
                table_clear = min(table_clear, min(d))
                if table_hit is None and min(d) <= 0.0:
                    table_hit = (i, min(d))
        if i % stride == 0 or i == len(q) - 1:
            for a, b in pairs:
                for p in pb.getClosestPoints(body, body, 0.1, a, b, physicsClientId=c):
                    self_clear = min(self_clear, p[8])
        pos, rot = scene.ee_pose()
        dp = float(np.linalg.norm(pos - pin_pos[i]))
        dr = _angle_deg(rot, pin_rot[i])
        if dp > worst_pos or dr > worst_rot:
            worst_agree_t = float(t[i])
        worst_pos, worst_rot = max(worst_pos, dp), max(worst_rot, dr)

    checks = []
    if self_hit is None:
        checks.append(Check("self-collision", True, detail=f"{len(pairs)} link pairs checked"))
    else:
        i, a, b, d = self_hit
        checks.append(Check("self-collision", False, float(t[i]),
                            f"{_link_name(scene, a)} / {_link_name(scene, b)}", d, 0.0,
                            "links penetrate (distance < 0)"))
    checks.append(Check("target-contact", target_hit is None,
                        None if target_hit is None else float(t[target_hit[0]]), "target",
                        None if target_hit is None else target_hit[1], 0.0,
                        "the hand must never touch the object it is about to grasp"))
    checks.append(Check("table-contact", table_hit is None,
                        None if table_hit is None else float(t[table_hit[0]]), "table",
                        None if table_hit is None else table_hit[1], 0.0,
                        "no link but the base touches the table plane"))
    agree_ok = worst_pos <= AGREE_POSITION and worst_rot <= AGREE_ROTATION
    checks.append(Check("kinematics-agreement", agree_ok, worst_agree_t, None,
                        worst_pos, AGREE_POSITION,
                        f"PyBullet vs Pinocchio end-effector pose: {worst_pos * 1000:.4f} mm, "
                        f"{worst_rot:.4f} deg"))

    def finite(x: float) -> float | None:
        return None if math.isinf(x) else round(x, 6)

    clear = {"target": finite(target_clear), "self": finite(self_clear),
             "table": finite(table_clear)}
    agree = {"position_mm": worst_pos * 1000, "rotation_deg": worst_rot}
    return checks, clear, agree


def _dynamic(scene: Scene, arm, t: np.ndarray, q: np.ndarray, qd: np.ndarray
             ) -> tuple[Check, dict]:
    """Position control with physics; the arm starts at rest on the first sample. The
    scene is shared between replays, so gravity, time step and motors are set here."""
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
    ratio = np.abs(tau) / arm.effort
    i, j = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
    check = Check("joint-torque", bool(ratio[i, j] <= 1.0), float(ts[i]), arm.joint_names[j],
                  float(tau[i, j]), float(arm.effort[j]),
                  "torques of the dynamic replay within the URDF effort limits")
    dyn = {"physics_rate_hz": PHYSICS_RATE,
           "tracking_max_rad": float(np.abs(err).max()),
           "tracking_rms_rad": float(np.sqrt(np.mean(err ** 2))),
           "torque_max_ratio": float(ratio.max())}
    return check, dyn
