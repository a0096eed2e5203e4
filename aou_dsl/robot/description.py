"""Robot description files: a TOML file that names a URDF (or a built-in arm) and pins
what aou would otherwise derive.

.. code-block:: toml

    urdf = "my_arm.urdf"            # relative to this file; or: robot = "ur5"
    package_dirs = ["../share"]     # where package:// meshes live (relative to this file)
    arm_joints = ["j1", "j2", "j3", "j4", "j5", "j6"]
    ee_frame = "tool0"              # a link of the URDF
    forward = "+z"                  # the axis of ee_frame that looks forward
    ee_offset = 0.0                 # m: the tool's tip this far ahead of ee_frame
    ee_roll = 0.0                   # rad: turn of the hand about its forward axis
    shiver_joint = "j6"
    posture = [0.0, -1.2, 1.6, -2.0, -1.57, 0.0]    # rad
    goal = [0.45, 0.1, 0.2]         # m, in the base frame
    from = [-0.6, 0.0, 0.8]         # direction from the goal toward the start
    joint_accel = 8.0               # rad/s^2: one number, or one per arm joint
    joint_jerk = [4000.0, 4000.0, 4000.0, 8000.0, 8000.0, 8000.0]   # rad/s^3
    joint_velocity = 2.0            # rad/s, overrides the URDF's
    allowed_contacts = [["link6", "gripper_base"]]
    [sources]                       # optional: where your numbers come from
    joint_accel = "vendor datasheet, rev. 3, table 2"

Every key but ``urdf``/``robot`` is optional. Values are checked here (types, lengths,
signs); names are checked against the URDF when the robot loads.
"""

from __future__ import annotations

import difflib
import math
import os
import re
import tomllib
from dataclasses import dataclass, field
from typing import Any

from ..core.diagnostics import AouError, Span, diag
from ..core.files import read_text

__all__ = ["KEYS", "Description", "read_description"]

_VEC3 = ("goal", "from")
_RATES = ("joint_accel", "joint_jerk", "joint_velocity")
_SCALARS = ("limit_margin", "velocity_scale", "accel_scale", "ee_offset")
_ANGLES = ("ee_roll",)
_NAMES = ("ee_frame", "shiver_joint", "forward")
#: Every key a robot description may have.
KEYS = ("urdf", "robot", "package_dirs", "arm_joints", "posture", "allowed_contacts",
        "sources", *_NAMES, *_VEC3, *_RATES, *_SCALARS, *_ANGLES)
FORWARD = ("+x", "-x", "+y", "-y", "+z", "-z")


@dataclass(frozen=True)
class Description:
    """A robot description file, checked.

    Attributes:
        path: the file, absolute.
        urdf: the URDF it names, absolute; "" when it extends a built-in arm.
        robot: the built-in arm it extends; "" when it names a URDF.
        package_dirs: folders of ``package://`` meshes, absolute.
        pins: the values it pins, by :class:`~aou_dsl.core.robot_specs.RobotSpec` field
            (``from`` is ``start_direction``; a single rate is kept as a float).
        sources: its ``[sources]`` table.
    """

    path: str
    urdf: str
    robot: str
    package_dirs: tuple[str, ...] = ()
    pins: dict[str, Any] = field(default_factory=dict)
    sources: dict[str, str] = field(default_factory=dict)


def _line(text: str, key: str) -> int:
    m = re.search(rf"^\s*{re.escape(key)}\s*=", text, re.MULTILINE)
    return text.count("\n", 0, m.start()) + 1 if m else 1


def _error(path: str, text: str, key: str | None, message: str, hint: str | None = None
           ) -> AouError:
    line = _line(text, key) if key else 1
    return AouError(diag("V109", f"robot description `{os.path.basename(path)}`: {message}",
                         Span(path, line, 1, line, 2), hint=hint))


def _numbers(value: Any) -> list[float] | None:
    if isinstance(value, bool) or not isinstance(value, list):
        return None
    if not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        return None
    out = [float(v) for v in value]
    return out if all(math.isfinite(v) for v in out) else None


def _check(key: str, value: Any) -> tuple[Any, str | None]:
    """The checked value of ``key``, or None and what is wrong."""
    if key in ("urdf", "robot", "ee_frame", "shiver_joint"):
        ok = isinstance(value, str) and value != ""
        return (value, None) if ok else (None, "must be a non-empty text")
    if key == "forward":
        v = f"+{value}" if isinstance(value, str) and len(value) == 1 else value
        return (v, None) if v in FORWARD else (None, f"must be one of {', '.join(FORWARD)}")
    if key in ("package_dirs", "arm_joints"):
        ok = isinstance(value, list) and bool(value) and all(
            isinstance(v, str) and v for v in value)
        return (tuple(value), None) if ok else (None, "must be a list of texts")
    if key == "allowed_contacts":
        ok = isinstance(value, list) and all(
            isinstance(p, list) and len(p) == 2 and all(isinstance(n, str) for n in p)
            for p in value)
        return (tuple(tuple(p) for p in value), None) if ok else (
            None, 'must be a list of link pairs, e.g. [["link6", "hand"]]')
    if key == "sources":
        ok = isinstance(value, dict) and all(isinstance(v, str) for v in value.values())
        return (dict(value), None) if ok else (None, "must be a table of texts")
    return _check_number(key, value)


def _check_number(key: str, value: Any) -> tuple[Any, str | None]:
    if key in _ANGLES:
        ok = isinstance(value, int | float) and not isinstance(value, bool) \
            and math.isfinite(value)
        return (float(value), None) if ok else (None, "must be a number [rad]")
    if key in _SCALARS:
        ok = isinstance(value, int | float) and not isinstance(value, bool) and value >= 0
        return (float(value), None) if ok else (None, "must be a number >= 0")
    if key in _RATES:
        if isinstance(value, int | float) and not isinstance(value, bool):
            value = [value]
        nums = _numbers(value)
        if nums is None or not nums or min(nums) <= 0:
            return None, "must be a positive number, or a list of them (one per arm joint)"
        return (nums[0] if len(nums) == 1 else tuple(nums)), None
    nums = _numbers(value)
    if key == "posture":
        return (tuple(nums), None) if nums else (None, "must be a list of numbers [rad]")
    if nums is None or len(nums) != 3:
        return None, "must be a list of 3 numbers"
    if key == "from":
        norm = math.sqrt(sum(v * v for v in nums))
        if norm == 0:
            return None, "must not be zero"
        nums = [v / norm for v in nums]
    return tuple(nums), None


#: Names ``aouc robot`` shows (its text and JSON) for what the file calls otherwise.
_FILE_NAMES = {"start_direction": "from", "ee_link": "ee_frame"}


def _did_you_mean(key: str) -> str | None:
    if key in _FILE_NAMES:
        return f"a robot file calls it `{_FILE_NAMES[key]}`"
    close = difflib.get_close_matches(key, KEYS, n=1, cutoff=0.6)
    return f"did you mean `{close[0]}`?" if close else None


def read_description(path: str) -> Description:
    """Read and check a robot description file.

    Raises:
        AouError: I501 when it cannot be read; V109 for what does not fit, at its line.
    """
    path = os.path.abspath(path)
    text = read_text(path, "the robot file")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"line (\d+)", str(exc))
        line = int(m.group(1)) if m else 1
        raise AouError(diag("V109", f"robot description `{os.path.basename(path)}` is not "
                            f"valid TOML: {exc}", Span(path, line, 1, line, 2))) from None
    return _checked(path, text, doc)


def _checked(path: str, text: str, doc: dict[str, Any]) -> Description:
    values: dict[str, Any] = {}
    for key, value in doc.items():
        if key not in KEYS:
            raise _error(path, text, key, f"unknown key `{key}`",
                         _did_you_mean(key) or f"keys: {', '.join(KEYS)}")
        checked, problem = _check(key, value)
        if problem is not None:
            raise _error(path, text, key, f"`{key}` {problem}")
        values[key] = checked
    if ("urdf" in values) == ("robot" in values):
        raise _error(path, text, None, "name the URDF (`urdf = \"arm.urdf\"`) or a built-in "
                     "arm (`robot = \"ur5\"`), one of the two")
    folder = os.path.dirname(path)
    urdf = os.path.normpath(os.path.join(folder, values.pop("urdf"))) if "urdf" in values \
        else ""
    dirs = tuple(os.path.normpath(os.path.join(folder, d))
                 for d in values.pop("package_dirs", ()))
    sources = values.pop("sources", {})
    robot = values.pop("robot", "")
    if "from" in values:
        values["start_direction"] = values.pop("from")
    return Description(path, urdf, robot, dirs, values, sources)
