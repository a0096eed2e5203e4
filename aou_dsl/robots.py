"""The robots aou knows: per-robot defaults and limits, as plain data (no heavy imports).

URDFs carry position, velocity and effort limits but no acceleration limits, so
the joint acceleration limits here come from the manufacturers' datasheets:

- Franka Emika Panda: "Robot and interface specifications" (Franka Control Interface
  documentation), joint acceleration limits 15, 7.5, 10, 12.5, 15, 20, 20 rad/s^2.
- Universal Robots UR5 (CB3): the datasheet gives no joint acceleration limit; the
  teach pendant's default joint acceleration is 1.4 rad/s^2 and the controller allows
  up to about 40 rad/s^2 (it limits torque, not acceleration). aou uses 3.0 rad/s^2,
  the conservative default :data:`DEFAULT_JOINT_ACCEL` for robots without a datasheet value.

Velocity limits are read from the URDF at compile time; the compiler plans at
``velocity_scale`` of them and at ``accel_scale`` of the acceleration limits, to keep a
margin. The safety checks hold the trajectory to the full limits.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["DEFAULT_JOINT_ACCEL", "DEFAULT_JOINT_JERK", "ROBOTS", "RobotSpec"]

#: Joint acceleration limit [rad/s^2] for a robot whose datasheet gives none.
DEFAULT_JOINT_ACCEL = 3.0

#: Joint jerk limit [rad/s^3] for a robot whose datasheet gives none.
DEFAULT_JOINT_JERK = 1000.0


@dataclass(frozen=True, slots=True)
class RobotSpec:
    """What aou needs to know of a robot beyond its URDF.

    Attributes:
        name: the example-robot-data name.
        ee_frame: frame whose z axis is the end-effector's forward (gaze) axis.
        arm_joints: the moving joints, in column order of the trajectory's ``q``.
        goal: default goal position in the base frame [m], shape (3,).
        start_direction: default unit direction from the goal toward the start pose.
        posture: joint configuration [rad] the redundancy is resolved toward; also the IK
            seed. Shape (len(arm_joints),).
        joint_accel: joint acceleration limits [rad/s^2], shape (len(arm_joints),).
        joint_jerk: joint jerk limits [rad/s^3], shape (len(arm_joints),); empty when
            no source gives them (then :data:`DEFAULT_JOINT_JERK` applies).
        shiver_joint: the redundant joint that shivers (rotates about the forward axis
            without moving the end-effector position).
        velocity_scale: fraction of the URDF velocity limit the compiler plans with.
        accel_scale: fraction of the acceleration limit the compiler plans with. TOPP-RA
            meets its limits at its grid points; in between, the spline's curvature can
            add a percent or so, which this margin absorbs (the checks use the full limit).
        limit_margin: distance [rad] kept from every joint position limit.
    """

    name: str
    ee_frame: str
    arm_joints: tuple[str, ...]
    goal: tuple[float, float, float]
    start_direction: tuple[float, float, float]
    posture: tuple[float, ...]
    joint_accel: tuple[float, ...]
    shiver_joint: str
    joint_jerk: tuple[float, ...] = ()
    velocity_scale: float = 0.9
    accel_scale: float = 0.95
    limit_margin: float = 0.05
    #: Link pairs allowed to touch beyond adjacent links (meshes that overlap by design).
    allowed_contacts: tuple[tuple[str, str], ...] = ()


ROBOTS: dict[str, RobotSpec] = {
    "panda": RobotSpec(
        name="panda",
        ee_frame="panda_hand_tcp",
        arm_joints=tuple(f"panda_joint{i}" for i in range(1, 8)),
        # In front of the robot at table height + 25 cm, reached from above and behind:
        # the start pose looks down and forward at the goal, as in the study's videos.
        goal=(0.55, 0.0, 0.25),
        start_direction=(-0.6, 0.0, 0.8),
        posture=(0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.785398),
        joint_accel=(15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0),
        # Same source (and libfranka's rate limiter): 7500, 3750, 5000, 6250, 7500,
        # 10000, 10000 rad/s^3.
        joint_jerk=(7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0),
        shiver_joint="panda_joint7",
        # The hand's mesh overlaps link 7's at the flange (link 8 between them has no
        # shape), and the two fingers touch when the gripper is closed.
        allowed_contacts=(("panda_link7", "panda_hand"),
                          ("panda_leftfinger", "panda_rightfinger")),
    ),
    "ur5": RobotSpec(
        name="ur5",
        ee_frame="tool0",
        arm_joints=(
            "shoulder_pan_joint",
            "shoulder_lift_joint",
            "elbow_joint",
            "wrist_1_joint",
            "wrist_2_joint",
            "wrist_3_joint",
        ),
        goal=(0.45, 0.15, 0.15),
        start_direction=(-0.6, 0.0, 0.8),
        posture=(0.3, -1.3, 1.8, -2.1, -1.5708, 0.0),
        joint_accel=(DEFAULT_JOINT_ACCEL,) * 6,
        shiver_joint="wrist_3_joint",
    ),
}
