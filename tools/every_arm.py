"""The table of every robot example-robot-data ships, for tools/robots_report.py: which
are fixed-base arms, how many joints aou derives for their arm, and their status with aou.

What is read from the data package itself: each entry's URDF, whether example-robot-data
loads it with a free-flying root, and the chain of moving joints aou derives from the
root (:func:`aou_dsl.robot.chain.arm_joints`). What was found by hand, for entries that
are not built in, is in :data:`FOUND` (a test keeps every entry of the data package in
the table, so a new entry shows up as "not yet tried").
"""

from __future__ import annotations

import os

__all__ = ["FOUND", "every_arm"]

#: What was found for entries that are not built-in arms, by entry.
FOUND = {
    "so100": "5 arm joints: holding the hand's position, its line of sight and its roll "
             "takes 6",
    "so101": "5 arm joints: holding the hand's position, its line of sight and its roll "
             "takes 6",
    "bravo7_no_ee": "loads (continuous joints without velocity limits, 3 of 6 joints within "
                    "[0, 3.5] rad), but no configuration was found from which the default "
                    "reach stays inside the joint ranges with the links apart: pin a "
                    "shorter reach in a robot description",
    "bravo7_gripper": "as bravo7_no_ee, with a gripper",
    "talos_arm": "loads from its URDF (6 arm joints derived); the derived default reach "
                 "fails its probes: pin `goal`, `from` and `posture` in a robot description",
    "panda_collision": "the Panda with capsules for collision shapes: use `panda`",
    "baxter": "two arms on a torso: name one arm's joints (`arm_joints`) in a robot "
              "description; not yet tried",
    "ur3": "example-robot-data's `ur3` loads a UR5 model; aou's `ur3` (counted here) is "
           "the UR3's URDF, `ur_description/urdf/ur3_robot.urdf`",
}
#: Kinds of the entries that are not fixed-base arms, by the words of their names.
KINDS = (("hand", "a hand"), ("pendulum", "a pendulum"), ("twodof", "a two-joint test arm"),
         ("finger", "a finger"), ("tiago", "a mobile manipulator"),
         ("alex", "a humanoid upper body"))


def _urdf(loader) -> str:
    import example_robot_data as erd

    sub = f"{loader.path}/{loader.urdf_subpath}/{loader.urdf_filename}"
    return os.path.join(erd.getModelPath(sub), sub)


def _facts(name: str, loader) -> tuple[str, str, int | str]:
    """(the URDF below the data folder, the root, the arm joints aou derives or the code
    of why it derives none)."""
    from aou_dsl.core.diagnostics import AouError
    from aou_dsl.robot.chain import arm_joints
    from aou_dsl.robot.urdf import read_urdf

    where = f"{loader.path}/{loader.urdf_subpath}/{loader.urdf_filename}"
    root = "free-flying" if getattr(loader, "free_flyer", False) else "fixed"
    try:
        joints: int | str = len(arm_joints(read_urdf(_urdf(loader))))
    except AouError as err:
        d = err.diagnostics[0]
        joints = "none: " + ("the chain branches" if "branches" in d.message else
                             f"{d.code}, the file does not read")
    return where, root, joints


def _status(name: str, root: str, joints: int | str, built: dict[str, str]) -> str:
    if name in built:
        return built[name] + (f"; {FOUND[name]}" if name in FOUND else "")
    if name in FOUND:
        return FOUND[name]
    kind = next((k for word, k in KINDS if word in name), None)
    if root == "free-flying":
        return f"not a fixed-base arm ({kind or 'a free-flying base'})"
    if kind:
        return f"not a fixed-base arm ({kind})"
    return "not yet tried"


def every_arm(built: dict[str, str]) -> list[str]:
    """The table's lines; ``built`` holds the status of each built-in arm."""
    import example_robot_data.robots_loader as rl

    lines = ["### Every robot of example-robot-data", "",
             "| entry | URDF | base | arm joints aou derives | status |",
             "|---|---|---|---|---|"]
    for name, loader in sorted(rl.ROBOTS.items()):
        where, root, joints = _facts(name, loader)
        status = _status(name, root, joints, built)
        lines.append(f"| `{name}` | `{where}` | {root} | {joints} | {status} |")
    return lines + [""]
