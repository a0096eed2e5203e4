"""The arm inside a URDF: which joints move it and where its end-effector is.

A vendor's URDF is a tree: the arm, a gripper (fingers, jaws), a mounting block, tool
frames. The arm is the chain of moving joints from the root: at each link the walk
follows the one child branch that still holds arm joints; gripper joints (named with
``finger``, ``gripper``, ``jaw`` or ``claw``) are not arm joints and stay locked. The
end-effector is the last link of the chain: from the link after the last arm joint the
walk follows fixed joints (not into finger or jaw links), to the deepest, then the
farthest, frame. A robot description file names either when the guess is wrong.
"""

from __future__ import annotations

import math
import os

from ..core.diagnostics import AouError, Span, diag
from .urdf import Joint, Urdf

__all__ = ["arm_joints", "ee_link", "is_gripper"]

#: Words that mark a joint or link as part of a gripper, not of the arm.
GRIPPER_WORDS = ("finger", "gripper", "jaw", "claw")


def is_gripper(name: str) -> bool:
    lower = name.lower()
    return any(w in lower for w in GRIPPER_WORDS)


def _arm_joint(j: Joint) -> bool:
    return j.moving and not is_gripper(j.name)


def _holds_arm(urdf: Urdf, j: Joint, memo: dict[str, bool]) -> bool:
    """Whether ``j`` or a joint below it is an arm joint."""
    if j.name not in memo:
        memo[j.name] = _arm_joint(j) or any(_holds_arm(urdf, c, memo)
                                            for c in urdf.children(j.child))
    return memo[j.name]


def arm_joints(urdf: Urdf) -> tuple[str, ...]:
    """The moving joints of the arm, from the base outward.

    Raises:
        AouError: V109 when the tree branches into two arms, or has no arm joint.
    """
    memo: dict[str, bool] = {}
    link, out = urdf.root, []
    while True:
        branches = [j for j in urdf.children(link) if _holds_arm(urdf, j, memo)]
        if not branches:
            break
        if len(branches) > 1:
            names = ", ".join(f"`{j.child}`" for j in branches)
            raise AouError(diag(
                "V109", f"`{_base(urdf)}` branches at link `{link}` into several arms "
                f"({names}); aou moves one", Span.whole_file(urdf.path),
                hint="name the arm's joints with `arm_joints = [...]` in a robot "
                     "description file (.toml) beside the URDF"))
        j = branches[0]
        if _arm_joint(j):
            out.append(j.name)
        link = j.child
    if not out:
        raise AouError(diag("V109", f"`{_base(urdf)}` has no joint that moves an arm",
                            Span.whole_file(urdf.path)))
    return tuple(out)


def _base(urdf: Urdf) -> str:
    return os.path.basename(urdf.path)


def ee_link(urdf: Urdf, joints: tuple[str, ...]) -> str:
    """The end-effector link: the last link of the chain after the last arm joint."""
    link = urdf.joint(joints[-1]).child
    while True:
        fixed = [j for j in urdf.children(link)
                 if j.type == "fixed" and not _finger(j)]
        if not fixed:
            return link
        link = max(fixed, key=lambda j: (_depth(urdf, j), math.dist(j.xyz, (0, 0, 0)),
                                         -urdf.joints.index(j))).child


def _finger(j: Joint) -> bool:
    """A fixed joint into a finger or jaw (a gripper's mount is still followed)."""
    lower = (j.name + " " + j.child).lower()
    return "finger" in lower or "jaw" in lower or "claw" in lower


def _depth(urdf: Urdf, j: Joint) -> int:
    """How many fixed joints (not into fingers) lie on the longest path below ``j``."""
    below = [c for c in urdf.children(j.child) if c.type == "fixed" and not _finger(c)]
    return 1 + max((_depth(urdf, c) for c in below), default=0)
