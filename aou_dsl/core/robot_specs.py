"""The robots aou knows: per-robot defaults and limits, as plain data (no heavy imports).

Each built-in arm is a URDF of example-robot-data plus what the URDF does not say, each
value with where it comes from (``sources``). A user's robot is a URDF, or a robot
description file (TOML) naming one; :mod:`aou_dsl.robot` reads it and derives what no
file pins, into the same :class:`RobotSpec`.

URDFs carry position, velocity and effort limits but no acceleration limits. The
acceleration (and jerk) limits below are the manufacturers' where they publish them,
each number with its source; an arm without a source gets
:data:`DEFAULT_JOINT_ACCEL` / :data:`DEFAULT_JOINT_JERK` and a C313 warning.

Velocity limits are read from the URDF at compile time; the compiler plans at
``velocity_scale`` of them and at ``accel_scale`` of the acceleration limits, to keep a
margin. The safety checks hold the trajectory to the full limits.
"""

from __future__ import annotations

from dataclasses import dataclass

from .arm_geometry import GEOMETRY

__all__ = ["DEFAULT_JOINT_ACCEL", "DEFAULT_JOINT_JERK", "DEFAULT_JOINT_VELOCITY", "NO_SOURCE",
           "ROBOTS", "ROBOT_FILE_TYPES", "UNSOURCED", "RobotSpec", "is_robot_file"]

#: Joint acceleration limit [rad/s^2] for a robot no source gives one for: the lowest
#: of the sourced arms' planning values (Universal Robots' 5 rad/s^2 is the next).
DEFAULT_JOINT_ACCEL = 3.0

#: Joint jerk limit [rad/s^3] for a robot whose datasheet gives none.
DEFAULT_JOINT_JERK = 1000.0

#: Joint velocity limit [rad/s] for a joint whose URDF gives none, when no other joint of
#: the arm has one either (otherwise the arm's smallest).
DEFAULT_JOINT_VELOCITY = 1.0

#: What a quoted ``robot "..."`` may name: a URDF, or a robot description file.
ROBOT_FILE_TYPES = (".urdf", ".toml")


@dataclass(frozen=True, slots=True)
class RobotSpec:
    """What aou needs to know of a robot beyond its URDF.

    Attributes:
        name: the robot as the user named it: a built-in name, or a robot file's path.
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
        allowed_contacts: link pairs allowed to touch beyond adjacent links (meshes that
            overlap by design).
        urdf: the URDF: a path inside example-robot-data's ``robots`` folder for a
            built-in arm, an absolute path otherwise.
        ee_link: the URDF link ``ee_frame`` is welded to when aou adds ``ee_frame``
            (its z axis then is the link's ``forward`` axis); empty when ``ee_frame`` is
            the URDF's own link.
        forward: the axis of ``ee_link`` (or of ``ee_frame``) that looks forward.
        ee_offset: how far [m] ahead of ``ee_link`` along ``forward`` aou puts
            ``ee_frame`` (a tool's tip beyond the link's origin).
        ee_roll: the turn [rad] of ``ee_frame`` about ``forward``: which way is up for
            the hand when the gaze is locked.
        joint_velocity: velocity limits [rad/s] overriding the URDF's; empty for none.
        sources: where each value comes from, ``(field, text)`` pairs.
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
    allowed_contacts: tuple[tuple[str, str], ...] = ()
    urdf: str = ""
    ee_link: str = ""
    forward: str = "+z"
    ee_offset: float = 0.0
    ee_roll: float = 0.0
    joint_velocity: tuple[float, ...] = ()
    sources: tuple[tuple[str, str], ...] = ()

    def source(self, key: str) -> str:
        """Where the value of field ``key`` comes from ("" when unknown)."""
        return dict(self.sources).get(key, "")


# --- Sourced limits ---------------------------------------------------------------------
# Each number with its source. "No source" means the manufacturer publishes none that
# we found; the arm then plans with the conservative default and says so (C313).

#: Franka Emika Panda: "Robot and interface specifications", Franka Control Interface
#: documentation (frankaemika.github.io/docs/control_parameters.html): joint acceleration
#: limits [rad/s^2] and jerk limits [rad/s^3]; libfranka's rate limiter uses the same
#: (franka/rate_limiting.h, kMaxJointAcceleration, kMaxJointJerk).
PANDA_ACCEL = (15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0)
PANDA_JERK = (7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0)
PANDA_SOURCE = "Franka Control Interface, Robot and interface specifications"

#: Universal Robots (UR3, UR5, UR10, CB3): 5 rad/s^2 on every joint, Universal Robots'
#: own planning value (Universal_Robots_ROS2_Driver, ur_moveit_config/config/
#: joint_limits.yaml, "chosen conservatively to work in most use cases"; pull request
#: 645). The robot itself limits torque, not acceleration (ur_description
#: config/ur5/joint_limits.yaml: "acceleration limits are not publicly available").
#: No jerk limit is published.
UR_ACCEL = 5.0
UR_SOURCE = ("Universal Robots' ROS 2 driver, ur_moveit_config joint_limits.yaml "
             "(5 rad/s^2, chosen conservatively)")

#: UFactory xArm7: 20 rad/s^2 on every joint (xarm_ros2, xarm_moveit_config/config/
#: xarm7/joint_limits.yaml, max_acceleration: 20.0). No jerk limit is published.
XARM_ACCEL = 20.0
XARM_SOURCE = "UFactory xarm_ros2, xarm_moveit_config/config/xarm7/joint_limits.yaml"

#: Kinova Jaco2 6-DOF (j2s6s200, example-robot-data's `kinova`): no source. Kinova's own
#: configuration for this arm (kinova-ros, j2s6s200_moveit_config/config/joint_limits.yaml)
#: sets has_acceleration_limits: false; the 8.6 rad/s^2 of ros2_kortex is the Gen3's,
#: another arm.
#: Unitree Z1 and Reach Robotics Bravo 7: no source found.
NO_SOURCE = ("no source: the manufacturer publishes no such limit; "
             "aou's conservative default")

LIMITS: dict[str, dict] = {
    "panda": {"joint_accel": PANDA_ACCEL, "joint_jerk": PANDA_JERK},
    "ur3": {"joint_accel": (UR_ACCEL,) * 6},
    "ur3_limited": {"joint_accel": (UR_ACCEL,) * 6},
    "ur3_gripper": {"joint_accel": (UR_ACCEL,) * 6},
    "ur5": {"joint_accel": (UR_ACCEL,) * 6},
    "ur5_limited": {"joint_accel": (UR_ACCEL,) * 6},
    "ur5_gripper": {"joint_accel": (UR_ACCEL,) * 6},
    "ur10": {"joint_accel": (UR_ACCEL,) * 6},
    "ur10_limited": {"joint_accel": (UR_ACCEL,) * 6},
    "xarm7": {"joint_accel": (XARM_ACCEL,) * 7},
    "kinova": {"joint_accel": (DEFAULT_JOINT_ACCEL,) * 6},
    "z1": {"joint_accel": (DEFAULT_JOINT_ACCEL,) * 6},
    "bravo7_no_ee": {"joint_accel": (DEFAULT_JOINT_ACCEL,) * 6},
    "bravo7_gripper": {"joint_accel": (DEFAULT_JOINT_ACCEL,) * 6},
}

_LIMIT_SOURCES = {"panda": PANDA_SOURCE, "xarm7": XARM_SOURCE,
                  **{n: UR_SOURCE for n in LIMITS if n.startswith("ur")}}


def _spec(name: str, fields: dict) -> RobotSpec:
    limits = LIMITS[name]
    src = _LIMIT_SOURCES.get(name, NO_SOURCE)
    sources = (("joint_accel", src),
               ("joint_jerk", src if "joint_jerk" in limits else NO_SOURCE),
               *fields.pop("sources", ()))
    return RobotSpec(name=name, **fields, **limits, sources=sources)


ROBOTS: dict[str, RobotSpec] = {name: _spec(name, dict(fields))
                                for name, fields in GEOMETRY.items() if name in LIMITS}

#: Arms whose limits come from no source (planned with the defaults, with a C313 warning).
UNSOURCED = frozenset(n for n in ROBOTS if n not in _LIMIT_SOURCES)


def is_robot_file(robot: str) -> bool:
    """Whether ``robot`` names a robot file (a path) rather than a built-in arm."""
    return robot not in ROBOTS and (robot.lower().endswith(ROBOT_FILE_TYPES)
                                    or "/" in robot or "\\" in robot)
