"""The built-in arms' geometry: URDF, end-effector, joints, default reach and posture.

Plain data. The limits (with their sources) are in :mod:`aou_dsl.core.robot_specs`. Values whose
source says "reach search" were found by aou's derivation (:mod:`aou_dsl.robot.derive`,
what ``aouc robot PATH`` prints for the URDF) and pinned here, so every run uses the same
ones and no run pays for the search. Arms of example-robot-data that are not here, and
why: docs/robots.md.
"""

from __future__ import annotations

import math

__all__ = ["GEOMETRY"]

_UR = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
       "wrist_2_joint", "wrist_3_joint")
_SEARCH = "aou's reach search on this URDF (aouc robot), pinned"
_QUARTER = math.pi / 2
_JAWS_UR = "the gripper's jaws end 6 cm ahead of the flange (its collision boxes)"
_JAWS_Z1 = "the gripper's jaws end about 15 cm ahead of the stator (collision shapes)"


def _searched(*more: tuple[str, str]) -> tuple[tuple[str, str], ...]:
    """Sources of an arm whose default reach the search found."""
    return (("goal", _SEARCH), ("start_direction", _SEARCH), ("posture", _SEARCH), *more)


_URDF_EE = "the URDF's tool frame (z forward)"

GEOMETRY: dict[str, dict] = {
    "panda": {
        "urdf": "panda_description/urdf/panda.urdf",
        "ee_frame": "panda_hand_tcp",
        "arm_joints": tuple(f"panda_joint{i}" for i in range(1, 8)),
        # In front of the robot at table height + 25 cm, reached from above and behind:
        # the start pose looks down and forward at the goal, as in the study's videos.
        "goal": (0.55, 0.0, 0.25),
        "start_direction": (-0.6, 0.0, 0.8),
        "posture": (0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.785398),
        "shiver_joint": "panda_joint7",
        # The hand's mesh overlaps link 7's at the flange (link 8 between them has no
        # shape), and the two fingers touch when the gripper is closed.
        "allowed_contacts": (("panda_link7", "panda_hand"),
                             ("panda_leftfinger", "panda_rightfinger")),
        "sources": (("goal", "the study's set-up"), ("start_direction", "the study's set-up"),
                    ("posture", "a ready pose of the arm"), ("ee_frame", _URDF_EE)),
    },
    "ur5": {
        "urdf": "ur_description/urdf/ur5_robot.urdf",
        "ee_frame": "tool0",
        "arm_joints": _UR,
        "goal": (0.45, 0.15, 0.15),
        "start_direction": (-0.6, 0.0, 0.8),
        "posture": (0.3, -1.3, 1.8, -2.1, -1.5708, 0.0),
        "shiver_joint": "wrist_3_joint",
        "sources": (("goal", "chosen by hand"), ("posture", "chosen by hand"),
                    ("ee_frame", _URDF_EE)),
    },
    "ur3": {
        "urdf": "ur_description/urdf/ur3_robot.urdf",
        "ee_frame": "tool0",
        "arm_joints": _UR,
        "goal": (0.423, 0.0, 0.211),
        "start_direction": (-0.6, 0.0, 0.8),
        "posture": (-0.6182, -2.0093, 1.5238, -1.6339, -1.2157, -3.6588),
        "shiver_joint": "wrist_3_joint",
        "sources": _searched(("ee_frame", "the URDF's tool flange frame (z forward)")),
    },
    "ur3_limited": {
        "urdf": "ur_description/urdf/ur3_joint_limited_robot.urdf",
        "ee_frame": "aou_ee",
        "ee_link": "tool0", "forward": "+z", "ee_offset": 0.0, "ee_roll": _QUARTER,
        "arm_joints": _UR,
        "goal": (0.423, 0.0, 0.211),
        "start_direction": (-0.6, 0.0, 0.8),
        "posture": (-0.6182, -0.6123, -1.5238, 0.0167, -1.2157, 1.0535),
        "shiver_joint": "wrist_3_joint",
        "sources": _searched(("ee_frame", "the URDF's tool flange frame (z forward)")),
    },
    "ur3_gripper": {
        "urdf": "ur_description/urdf/ur3_gripper.urdf",
        "ee_frame": "aou_ee",
        "ee_link": "tool0", "forward": "+z", "ee_offset": 0.06, "ee_roll": _QUARTER,
        "arm_joints": _UR,
        "goal": (0.544, 0.0, 0.227),
        "start_direction": (-0.8, 0.0, 0.6),
        "posture": (-0.6321, -0.4451, -1.7497, -0.1979, -1.0785, 1.1568),
        "shiver_joint": "wrist_3_joint",
        "sources": _searched(("ee_offset", _JAWS_UR)),
    },
    "ur5_limited": {
        "urdf": "ur_description/urdf/ur5_joint_limited_robot.urdf",
        "ee_frame": "tool0",
        "arm_joints": _UR,
        "goal": (0.744, 0.0, 0.3),
        "start_direction": (-1.0, 0.0, 0.0),
        "posture": (-0.3065, -1.6393, 1.9462, -0.3069, 1.2642, 0.0),
        "shiver_joint": "wrist_3_joint",
        "sources": _searched(("ee_frame", "the URDF's tool flange frame (z forward)")),
    },
    "ur5_gripper": {
        "urdf": "ur_description/urdf/ur5_gripper.urdf",
        "ee_frame": "aou_ee",
        "ee_link": "tool0", "forward": "+z", "ee_offset": 0.06, "ee_roll": 0.0,
        "arm_joints": _UR,
        "goal": (0.78, 0.0, 0.3),
        "start_direction": (-1.0, 0.0, 0.0),
        "posture": (-0.3291, -1.7009, 2.0009, -0.3, 1.2417, 0.0),
        "shiver_joint": "wrist_3_joint",
        "sources": _searched(("ee_offset", _JAWS_UR)),
    },
    "ur10": {
        "urdf": "ur_description/urdf/ur10_robot.urdf",
        "ee_frame": "tool0",
        "arm_joints": _UR,
        "goal": (0.876, 0.0, 0.3),
        "start_direction": (-0.6, 0.0, 0.8),
        "posture": (-0.2588, -1.592, 1.9366, 3.7405, -1.4167, -3.3503),
        "shiver_joint": "wrist_3_joint",
        "sources": _searched(("ee_frame", "the URDF's tool flange frame (z forward)")),
    },
    "ur10_limited": {
        "urdf": "ur_description/urdf/ur10_joint_limited_robot.urdf",
        "ee_frame": "tool0",
        "arm_joints": _UR,
        "goal": (0.876, 0.0, 0.3),
        "start_direction": (-0.8, 0.0, 0.6),
        "posture": (-0.2959, -1.4926, 1.688, 0.4697, 1.3354, -0.1809),
        "shiver_joint": "wrist_3_joint",
        "sources": _searched(("ee_frame", "the URDF's tool flange frame (z forward)")),
    },
    "xarm7": {
        "urdf": "xarm_description/urdf/xarm7.urdf",
        "ee_frame": "link_eef",
        "arm_joints": tuple(f"joint{i}" for i in range(1, 8)),
        "goal": (0.41, 0.0, 0.205),
        "start_direction": (-0.6, 0.0, 0.8),
        "posture": (0.9527, -1.3815, -0.5413, 0.4176, -0.9769, 1.2644, -0.8006),
        "shiver_joint": "joint7",
        "sources": _searched(("ee_frame", "the URDF's end-effector frame (z forward)")),
    },
    "kinova": {
        "urdf": "kinova_description/robots/kinova.urdf",
        "ee_frame": "aou_ee",
        "ee_link": "j2s6s200_end_effector", "forward": "+x", "ee_offset": 0.0, "ee_roll": 0.0,
        "arm_joints": tuple(f"j2s6s200_joint_{i}" for i in range(1, 7)),
        "goal": (0.552, 0.0, 0.376),
        "start_direction": (-0.6, 0.0, 0.8),
        "posture": (-1.5249, 2.992, 1.9101, 3.1138, 1.7249, -3.1006),
        "shiver_joint": "j2s6s200_joint_6",
        "sources": _searched(("forward", "derived: the end-effector frame looks along x")),
    },
    "z1": {
        "urdf": "z1_description/urdf/z1.urdf",
        "ee_frame": "aou_ee",
        "ee_link": "gripperStator", "forward": "+x", "ee_offset": 0.15, "ee_roll": 0.0,
        "arm_joints": tuple(f"joint{i}" for i in range(1, 7)),
        "goal": (0.658, 0.0, 0.235),
        "start_direction": (-0.8, 0.0, 0.6),
        "posture": (0.0, 1.5622, -2.0567, 1.138, -0.0, 0.0),
        "shiver_joint": "joint6",
        "sources": _searched(("ee_offset", _JAWS_Z1)),
    },
}
