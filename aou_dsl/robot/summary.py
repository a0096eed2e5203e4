"""What aou knows of a robot, and where each value comes from (``aouc robot NAME|PATH``).

:func:`describe_robot` returns a JSON-able dict and its text rendering. The dict's
``toml`` is a robot description that pins every value as loaded: saved beside the URDF
(its ``urdf`` line names it), it makes the next load skip the derivations, and it is
the place to correct one.
"""

from __future__ import annotations

import math
import os
from typing import Any

from ..core.robot_specs import DEFAULT_JOINT_JERK, NO_SOURCE, ROBOTS, RobotSpec
from .load import load_robot
from .model import Robot

__all__ = ["describe_robot", "robot_toml"]

_ORDER = ("arm_joints", "ee_frame", "forward", "ee_offset", "ee_roll", "shiver_joint",
          "goal", "start_direction", "posture", "joint_accel", "joint_jerk",
          "allowed_contacts")
_LIMITS = ("joint_accel", "joint_jerk", "joint_velocity")
_SCALES = ("velocity_scale", "accel_scale", "limit_margin")
_DEFAULTS = RobotSpec("", "", (), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (), (), "")


def _round(v: Any) -> Any:
    if isinstance(v, float):
        return round(v, 6)
    if isinstance(v, tuple | list):
        return [_round(x) for x in v]
    return v


def _joints(r: Robot) -> list[dict[str, Any]]:
    spec, m = r.spec, r.model
    jerk = spec.joint_jerk or (None,) * len(spec.arm_joints)
    vel = spec.joint_velocity or tuple(float(v) for v in m.velocityLimit)
    out = []
    for i, name in enumerate(spec.arm_joints):
        j = r.urdf.joint(name)
        out.append({
            "name": name, "type": j.type,
            "lower": _round(float(m.lowerPositionLimit[i])),
            "upper": _round(float(m.upperPositionLimit[i])),
            "velocity": _round(float(vel[i])),
            "velocity_source": "pinned" if spec.joint_velocity else
            ("filled in (the URDF gives none)" if name in r.filled_velocity else "URDF"),
            "acceleration": spec.joint_accel[i], "jerk": jerk[i],
            "effort": None if name in r.no_effort else _round(float(m.effortLimit[i])),
        })
    return out


def describe_robot(robot: str, package_dirs: tuple[str, ...] = ()
                   ) -> tuple[dict[str, Any], str]:
    """A robot (a built-in name, or a URDF or robot description path) as aou loads it.

    Returns:
        a JSON-able dict (values, and ``sources``: where each comes from) and a text
        rendering of it.

    Raises:
        AouError: as :func:`aou_dsl.robot.load.load_robot`.
    """
    r = load_robot(robot, package_dirs)
    spec = r.spec
    kind = ("built-in" if robot in ROBOTS else
            "robot description" if r.description else "URDF")
    values = {k: _round(getattr(spec, k)) for k in _ORDER}
    if not spec.joint_jerk:  # the limit planned with, said to be aou's by its source
        values["joint_jerk"] = [DEFAULT_JOINT_JERK] * len(spec.arm_joints)
    doc: dict[str, Any] = {
        "robot": robot, "kind": kind, "urdf": r.urdf.path,
        "description": r.description or None,
        **values,
        "ee_link": spec.ee_link or None,
        "joints": _joints(r),
        "collision_geometry": r.collision,
        "missing_meshes": _missing_meshes(r),
        "reach_found": r.reach_ok,
        "sources": {k: spec.source(k) for k in _ORDER if spec.source(k)},
        "warnings": [{"code": d.code, "message": d.message, "hint": d.hint}
                     for d in r.warnings],
        "toml": robot_toml(r),
    }
    return doc, _text(doc)


def _missing_meshes(r: Any) -> list[str]:
    """The mesh paths of the URDF that name no regular file (the checks need them)."""
    from .urdf import scene_xml

    return scene_xml(r.urdf, r.package_dirs, None, visuals=False)[1]


def _text(doc: dict[str, Any]) -> str:
    lines = [f"robot {doc['robot']} ({doc['kind']})", f"  urdf: {doc['urdf']}"]
    if doc["description"]:
        lines.append(f"  description: {doc['description']}")
    for k in _ORDER:
        src = doc["sources"].get(k, "")
        lines.append(f"  {k}: {_show(doc[k])}" + (f"  [{src}]" if src else ""))
    if doc["ee_link"]:
        lines.append(f"  ({doc['ee_frame']} is added by aou on link {doc['ee_link']})")
    lines.append("  joints:")
    for j in doc["joints"]:
        effort = "none" if j["effort"] is None else f"{j['effort']:g} N m"
        jerk = (f"{DEFAULT_JOINT_JERK:g} rad/s^3 (aou's default)" if j["jerk"] is None
                else f"{j['jerk']:g} rad/s^3")
        lines.append(
            f"    {j['name']} ({j['type']}): [{j['lower']:.4g}, {j['upper']:.4g}] rad, "
            f"{j['velocity']:.4g} rad/s ({j['velocity_source']}), "
            f"{j['acceleration']:g} rad/s^2, {jerk}, effort {effort}")
    missing = doc["missing_meshes"]
    if missing and doc["collision_geometry"]:
        lines.append(f"  collision geometry: named, but its meshes are missing: "
                     f"{len(missing)} mesh file(s) not found, first `{missing[0]}`: compiling "
                     "needs them (give their package's folder with --package-dir), or "
                     "compile with --no-check")
    else:
        lines.append(f"  collision geometry: {'yes' if doc['collision_geometry'] else 'NO'}")
    if doc["reach_found"] is False:
        lines.append("  default reach: NOT FOUND (pin goal, from and posture)")
    for w in doc["warnings"]:
        lines.append(f"  {w['code']}: {w['message']}")
        if w["hint"]:
            lines.append(f"    hint: {w['hint']}")
    lines += ["", "# A robot description pinning all of the above:", doc["toml"]]
    return "\n".join(lines)


def _show(v: Any) -> str:
    if isinstance(v, list):
        return "[" + ", ".join(_show(x) for x in v) + "]"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def _toml_value(v: Any) -> str:
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return repr(round(v, 6)) if math.isfinite(v) else "0.0"
    if isinstance(v, int):
        return str(v)
    return "[" + ", ".join(_toml_value(x) for x in v) + "]"


def _builtin_of(r: Robot) -> str:
    """The built-in arm ``r`` is, or its robot description extends ("" for neither)."""
    if r.spec.name in ROBOTS:
        return r.spec.name
    if r.description:
        from .description import read_description

        return read_description(r.description).robot
    return ""


def robot_toml(r: Robot, urdf: str | None = None) -> str:
    """A robot description that pins ``r`` as loaded: read back, it loads the same robot
    (limits included). ``urdf``: the path to write in it (default: the URDF's name, for
    a file saved beside it; a built-in arm, or a description extending one, is named
    with ``robot = ...`` instead). A limit no source gives (aou's default) is written
    commented out, with its value: it stays the default, with its warning (C313), until
    a real number is pinned there."""
    spec = r.spec
    base = _builtin_of(r)
    if base and urdf is None:
        lines = [f"robot = {_toml_value(base)}"]
    else:
        lines = [f"urdf = {_toml_value(urdf or os.path.basename(r.urdf.path))}"]
    n = len(spec.arm_joints)
    pins: dict[str, Any] = {
        "arm_joints": list(spec.arm_joints),
        "ee_frame": spec.ee_link or spec.ee_frame,
        "forward": spec.forward, "ee_offset": spec.ee_offset, "ee_roll": spec.ee_roll,
        "shiver_joint": spec.shiver_joint,
        "posture": list(spec.posture), "goal": list(spec.goal),
        "from": list(spec.start_direction),  # the file's name for start_direction
        "joint_accel": list(spec.joint_accel),
        "joint_jerk": list(spec.joint_jerk or (DEFAULT_JOINT_JERK,) * n),
    }
    if spec.joint_velocity:
        pins["joint_velocity"] = list(spec.joint_velocity)
    pins["allowed_contacts"] = [list(p) for p in spec.allowed_contacts]
    for key in _SCALES:  # the compiler's margins, when not the defaults
        if getattr(spec, key) != getattr(_DEFAULTS, key):
            pins[key] = getattr(spec, key)
    unsourced = {k for k in _LIMITS if spec.source(k) == NO_SOURCE or
                 (k == "joint_jerk" and not spec.joint_jerk)}
    for k, v in pins.items():
        if k in unsourced:
            lines.append(f"# {k} = {_toml_value(v)}  # no source: aou's conservative "
                         "default; pin your arm's limits here")
        else:
            lines.append(f"{k} = {_toml_value(v)}")
    sources = {k: spec.source(k) for k in _LIMITS if k in pins and k not in unsourced
               and spec.source(k)}
    if sources:
        lines += ["[sources]", *(f"{k} = {_toml_value(v)}" for k, v in sources.items())]
    return "\n".join(lines) + "\n"
