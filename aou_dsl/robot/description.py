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
    [servo]                         # optional: the joints' servos, for --track
    kp = [3000.0, 3000.0, 3000.0, 1000.0, 1000.0, 1000.0]   # N m/rad
    kv = 100.0                      # N m s/rad: one number, or one per arm joint
    damping = 1.0                   # N m s/rad
    armature = 0.1                  # kg m^2
    force = [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]          # N m (default: the URDF's)
    rate = 500.0                    # Hz, the controller's
    modes = ["position", "feedforward"]
    source = "identified on our arm, report 12"
    # or: table = "kinova_gen3", a published table aou knows

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

from ..core.codes import V109
from ..core.diagnostics import AouError, Span, diag
from ..core.inputs import read_input_text

__all__ = ["KEYS", "SERVO_KEYS", "Description", "read_description"]

_VEC3 = ("goal", "from")
_RATES = ("joint_accel", "joint_jerk", "joint_velocity")
_SCALARS = ("limit_margin", "velocity_scale", "accel_scale", "ee_offset")
_ANGLES = ("ee_roll",)
_NAMES = ("ee_frame", "shiver_joint", "forward")
#: Every key a robot description may have.
KEYS = ("urdf", "robot", "package_dirs", "arm_joints", "posture", "allowed_contacts",
        "sources", *_NAMES, *_VEC3, *_RATES, *_SCALARS, *_ANGLES, "servo")
#: The keys of a ``[servo]`` table: gains and the like (one number, or one per arm
#: joint), the controller's rate, its modes, the source, or a published table's name.
SERVO_GAINS = ("kp", "kv", "damping", "armature", "force")
SERVO_KEYS = (*SERVO_GAINS, "rate", "modes", "source", "table")
_SERVO_MODES = ("position", "feedforward", "torque")
FORWARD = ("+x", "-x", "+y", "-y", "+z", "-z")
#: The ranges numbers may take: key -> (least, greatest, least included, in words).
_RANGES: dict[str, tuple[float, float, bool, str]] = {
    "velocity_scale": (0.0, 1.0, False, "a fraction above 0 and at most 1"),
    "accel_scale": (0.0, 1.0, False, "a fraction above 0 and at most 1"),
    "limit_margin": (0.0, 1.0, True, "a number from 0 to 1 [rad]"),
    "ee_offset": (0.0, 2.0, True, "a number from 0 to 2 [m]"),
    "ee_roll": (-2 * math.pi, 2 * math.pi, True, "a number from -2 pi to 2 pi [rad]"),
}
#: Greatest joint rate (velocity, acceleration, jerk) a description may give.
_MAX_RATE = 1e7
#: Greatest posture angle [rad] and goal coordinate [m].
_MAX_POSTURE, _MAX_GOAL = 100.0, 10.0


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
    servo: dict[str, Any] | None = None


def _line(text: str, key: str) -> int:
    m = re.search(rf"^\s*{re.escape(key)}\s*=", text, re.MULTILINE)
    return text.count("\n", 0, m.start()) + 1 if m else 1


def _error(path: str, text: str, key: str | None, message: str, hint: str | None = None
           ) -> AouError:
    line = _line(text, key) if key else 1
    return AouError(diag(V109, f"robot description `{os.path.basename(path)}`: {message}",
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
    if key == "servo":
        return _check_servo(value)
    return _check_number(key, value)


def _check_servo(value: Any) -> tuple[Any, str | None]:
    """A ``[servo]`` table: its gains as tuples, checked; None and what is wrong."""
    if not isinstance(value, dict):
        return None, f"must be a table with keys {', '.join(SERVO_KEYS)}"
    out: dict[str, Any] = {}
    for k, v in value.items():
        if k not in SERVO_KEYS:
            return None, f"has an unknown key `{k}` (keys: {', '.join(SERVO_KEYS)})"
        if k in SERVO_GAINS:
            nums = _numbers([v] if isinstance(v, int | float) and not isinstance(v, bool)
                            else v)
            if not nums or min(nums) < 0 or max(nums) > _MAX_RATE:
                return None, (f"`{k}` must be a number from 0 to {_MAX_RATE:g}, or a list "
                              "of them (one per arm joint)")
            if k == "kp" and min(nums) <= 0:
                return None, "`kp` must be above 0"
            out[k] = tuple(nums)
        elif k == "rate":
            ok = isinstance(v, int | float) and not isinstance(v, bool) and 1 <= v <= 1e5
            if not ok:
                return None, "`rate` must be a number of Hz from 1 to 100000"
            out[k] = float(v)
        elif k == "modes":
            if not isinstance(v, list) or not v or any(m not in _SERVO_MODES for m in v):
                return None, f"`modes` must be a list of {', '.join(_SERVO_MODES)}"
            out[k] = tuple(v)
        elif not isinstance(v, str) or not v:
            return None, f"`{k}` must be a non-empty text"
        else:
            out[k] = v
    if "table" not in out and "kp" not in out:
        return None, "needs `kp` (and the other gains), or `table`, a published table's name"
    return out, None


def _check_number(key: str, value: Any) -> tuple[Any, str | None]:
    if key in _RANGES:
        low, high, closed, words = _RANGES[key]
        ok = isinstance(value, int | float) and not isinstance(value, bool) and \
            math.isfinite(value) and (low <= value if closed else low < value) and \
            value <= high
        return (float(value), None) if ok else (None, f"must be {words}")
    if key in _RATES:
        if isinstance(value, int | float) and not isinstance(value, bool):
            value = [value]
        nums = _numbers(value)
        if nums is None or not nums or min(nums) <= 0 or max(nums) > _MAX_RATE:
            return None, (f"must be a positive number up to {_MAX_RATE:g}, or a list of "
                          "them (one per arm joint)")
        return (nums[0] if len(nums) == 1 else tuple(nums)), None
    nums = _numbers(value)
    if key == "posture":
        ok = bool(nums) and max(abs(v) for v in nums or [0]) <= _MAX_POSTURE
        return (tuple(nums or ()), None) if ok else (None, "must be a list of numbers [rad]")
    if nums is None or len(nums) != 3:
        return None, "must be a list of 3 numbers"
    if key == "from":
        norm = math.hypot(*nums)
        if norm == 0 or not math.isfinite(norm):
            return None, "must be a direction: 3 numbers, not all zero"
        return tuple(v / norm for v in nums), None
    if max(abs(v) for v in nums) > _MAX_GOAL:
        return None, f"must be 3 numbers [m], each within {_MAX_GOAL:g} m of the base"
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
    text = read_input_text(path, "robot", "the robot file")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"line (\d+)", str(exc))
        line = int(m.group(1)) if m else 1
        raise AouError(diag(V109, f"robot description `{os.path.basename(path)}` is not "
                            f"valid TOML: {exc}", Span(path, line, 1, line, 2))) from None
    except (RecursionError, ValueError) as exc:  # nested too deeply; a 5000-digit number
        what = "nested too deeply" if isinstance(exc, RecursionError) else \
            "holds a number too long to read"
        raise AouError(diag(V109, f"robot description `{os.path.basename(path)}` {what}",
                            Span.whole_file(path))) from None
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
    servo = values.pop("servo", None)
    if "from" in values:
        values["start_direction"] = values.pop("from")
    return Description(path, urdf, robot, dirs, values, sources, servo)
