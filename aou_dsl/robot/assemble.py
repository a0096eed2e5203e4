"""A robot spec from a URDF, what a robot description pins, and what is derived.

Order: the arm's joints and end-effector link (:mod:`.chain`), velocity limits the URDF
lacks, the kinematic model, the forward axis, the shiver joint, the limits, the default
reach (:mod:`.derive`). Each value's source is recorded: "pinned in FILE", "URDF",
"derived: ...", or "no source: ... default".
"""

from __future__ import annotations

import math
import os
from dataclasses import fields, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..core.diagnostics import AouError, Diagnostic, Span, diag
from ..core.robot_specs import (
    DEFAULT_JOINT_ACCEL,
    DEFAULT_JOINT_JERK,
    DEFAULT_JOINT_VELOCITY,
    NO_SOURCE,
    RobotSpec,
)
from .chain import arm_joints, ee_link
from .collide import SAMPLES
from .urdf import GAZE_FRAME, MOVING, Urdf

if TYPE_CHECKING:
    from .description import Description
    from .model import Robot

__all__ = ["assemble", "default_limits_warning", "filled_velocities"]

_SPEC_FIELDS = {f.name for f in fields(RobotSpec)}


def filled_velocities(urdf: Urdf, joints: tuple[str, ...]) -> dict[str, float]:
    """Velocity limits for the arm joints whose URDF gives none (or zero): the arm's
    smallest given limit, or :data:`DEFAULT_JOINT_VELOCITY` [rad/s]."""
    given = [urdf.joint(j).velocity for j in joints]
    known = [v for v in given if v is not None and v > 0]
    fill = min(known) if known else DEFAULT_JOINT_VELOCITY
    return {j: fill for j, v in zip(joints, given, strict=True) if v is None or v <= 0}


def default_limits_warning(spec: RobotSpec, urdf: Urdf, description: str, *, accel: bool,
                           jerk: bool, velocity: dict[str, float]) -> Diagnostic:
    """C313: which limits are defaults, and which file to write to pin them."""
    what = []
    if accel:
        what.append(f"joint acceleration ({DEFAULT_JOINT_ACCEL:g} rad/s^2)")
    if jerk:
        what.append(f"joint jerk ({DEFAULT_JOINT_JERK:g} rad/s^3)")
    if velocity:
        what.append(f"joint velocity of {', '.join(velocity)} "
                    f"({next(iter(velocity.values())):g} rad/s)")
    keys = " and ".join(k for k, on in (("joint_accel", accel), ("joint_jerk", jerk),
                                        ("joint_velocity", bool(velocity))) if on)
    if description:
        hint = f"add {keys} to `{description}`"
    elif spec.name == os.path.basename(spec.name) and not spec.name.endswith(".urdf"):
        toml = f"{spec.name}.toml"
        hint = (f"write `{toml}` with `robot = \"{spec.name}\"` and {keys} from your "
                f"controller's documentation, then use it: `robot \"{toml}\"` in the file "
                f"or `--robot {toml}`")
    else:
        toml = os.path.splitext(spec.name)[0] + ".toml"
        hint = (f"write `{toml}` with `urdf = \"{os.path.basename(urdf.path)}\"` and "
                f"{keys}, then use it: `robot \"{toml}\"` in the file or `--robot {toml}`")
    return diag("C313", f"robot `{spec.name}`: no sourced {' or '.join(what)} limit; aou "
                "plans with its conservative default", Span.whole_file(urdf.path),
                hint=hint, defaults=[k for k in keys.split(" and ")])


def _bad(urdf: Urdf, where: str, message: str) -> AouError:
    return AouError(diag("V109", message, Span.whole_file(where or urdf.path)))


def _check_names(urdf: Urdf, pins: dict[str, Any], joints: tuple[str, ...], where: str
                 ) -> None:
    names = {j.name: j for j in urdf.joints}
    for j in joints:
        if j not in names or names[j].type not in MOVING:
            raise _bad(urdf, where, f"`{j}` is not a moving joint of "
                       f"`{os.path.basename(urdf.path)}`")
    for key in ("posture", "joint_accel", "joint_jerk", "joint_velocity"):
        v = pins.get(key)
        if isinstance(v, tuple) and len(v) != len(joints):
            raise _bad(urdf, where, f"`{key}` has {len(v)} values; the arm has "
                       f"{len(joints)} joints ({', '.join(joints)})")
    for key in ("ee_frame", "ee_link"):
        if pins.get(key) and pins[key] not in urdf.links and pins[key] != GAZE_FRAME:
            raise _bad(urdf, where, f"`{key}` `{pins[key]}` is not a link of "
                       f"`{os.path.basename(urdf.path)}`")
    if pins.get("shiver_joint") and pins["shiver_joint"] not in joints:
        raise _bad(urdf, where, f"`shiver_joint` `{pins['shiver_joint']}` is not an arm "
                   f"joint ({', '.join(joints)})")


def _rates(value: Any, n: int) -> tuple[float, ...]:
    return tuple(value) if isinstance(value, tuple) else (float(value),) * n


def _pins(desc: Description | None, base: RobotSpec | None) -> tuple[dict, dict, str]:
    """The pinned values, their sources, and the description file's path."""
    pins: dict[str, Any] = {}
    src: dict[str, str] = {}
    if base is not None:
        pins = {f: getattr(base, f) for f in _SPEC_FIELDS
                if f not in ("name", "urdf", "sources") and getattr(base, f) not in ((), "")}
        pins["allowed_contacts"] = base.allowed_contacts  # none is a value here too
        src = dict(base.sources) | {k: f"built-in `{base.name}`" for k in pins
                                    if k not in dict(base.sources)}
    if desc is None:
        return pins, src, ""
    if "ee_frame" in desc.pins:  # a new end-effector: its forward axis is not the base's
        for k in ("ee_link", "forward"):
            pins.pop(k, None)
    if "arm_joints" in desc.pins:
        for k in ("posture", "shiver_joint", "joint_accel", "joint_jerk", "joint_velocity"):
            pins.pop(k, None)
    pins |= desc.pins
    name = os.path.basename(desc.path)
    src |= {k: desc.sources.get(k, f"pinned in {name}") for k in desc.pins}
    if "start_direction" in desc.pins and "from" in desc.sources:
        src["start_direction"] = desc.sources["from"]
    return pins, src, desc.path


def assemble(name: str, urdf: Urdf, desc: Description | None, dirs: tuple[str, ...],
             base: RobotSpec | None = None) -> Robot:
    """The robot ``name`` from ``urdf``, pinned by ``desc`` (and the built-in ``base``
    it extends), the rest derived. See the module's docstring."""
    from . import derive
    from .kinematics import frame_id
    from .model import Robot, reduced_model

    pins, src, where = _pins(desc, base)
    joints = tuple(pins.get("arm_joints") or arm_joints(urdf))
    src.setdefault("arm_joints", "derived: the chain of moving joints from the root")
    _check_names(urdf, pins, joints, where)
    velocity = filled_velocities(urdf, joints) if "joint_velocity" not in pins else {}
    link = pins.get("ee_link") or pins.get("ee_frame") or ee_link(urdf, joints)
    src.setdefault("ee_frame", "derived: the last link of the chain")
    model = reduced_model(urdf, joints, velocity, None)
    q_mid = np.clip(np.zeros(len(joints)), model.lowerPositionLimit,
                    model.upperPositionLimit)
    if pins.get("forward"):
        forward = pins["forward"]
    else:
        forward, src["forward"] = derive.forward_axis(model, q_mid, frame_id(model, link))
    offset = float(pins.get("ee_offset", 0.0))
    roll = float(pins.get("ee_roll", 0.0))
    model = _gazing(urdf, joints, velocity, (link, forward, offset, roll)) or model
    frame = GAZE_FRAME if model.existFrame(GAZE_FRAME) else link
    shiver = pins.get("shiver_joint")
    if not shiver:
        shiver, src["shiver_joint"] = derive.shiver_joint(model, q_mid,
                                                          frame_id(model, frame), "+z")
    n = len(joints)
    src.setdefault("joint_accel", NO_SOURCE)
    src.setdefault("joint_jerk", NO_SOURCE)
    spec = RobotSpec(
        name=name, ee_frame=frame, arm_joints=joints, goal=(0.5, 0.0, 0.25),
        start_direction=(-0.6, 0.0, 0.8), posture=tuple(q_mid),
        joint_accel=_rates(pins.get("joint_accel", DEFAULT_JOINT_ACCEL), n),
        shiver_joint=shiver, joint_jerk=_rates(pins["joint_jerk"], n)
        if "joint_jerk" in pins else (), urdf=urdf.path,
        ee_link=link if frame == GAZE_FRAME else "", forward=forward, ee_offset=offset,
        ee_roll=roll,
        joint_velocity=_rates(pins["joint_velocity"], n) if "joint_velocity" in pins else (),
        **{k: pins[k] for k in ("velocity_scale", "accel_scale", "limit_margin",
                                "allowed_contacts") if k in pins})
    spec, model, reach_ok = _reach(spec, model, urdf, pins, src, dirs, velocity)
    spec = replace(spec, sources=tuple(sorted(src.items())))
    warnings: tuple[Diagnostic, ...] = ()
    if "joint_accel" not in pins or "joint_jerk" not in pins or velocity:
        warnings = (default_limits_warning(spec, urdf, where, accel="joint_accel" not in pins,
                                           jerk="joint_jerk" not in pins, velocity=velocity),)
    no_effort = tuple(j for j in joints if urdf.joint(j).effort is None)
    return Robot(spec, urdf, model, dirs, where, no_effort, velocity, warnings, reach_ok)


def _gazing(urdf: Urdf, joints: tuple[str, ...], velocity: dict[str, float],
            gaze: tuple[str, str, float, float]) -> Any:
    """The model with :data:`GAZE_FRAME` when the link's own z axis will not do (another
    forward axis, an offset or a roll); None when it will."""
    from .model import reduced_model

    if gaze[1] == "+z" and not gaze[2] and not gaze[3]:
        return None
    return reduced_model(urdf, joints, velocity, gaze)


#: Turns of the hand about its forward axis [rad] the reach search tries, in order.
ROLLS = (0.0, math.pi / 2, math.pi, -math.pi / 2)


def _reach(spec: RobotSpec, model: Any, urdf: Urdf, pins: dict, src: dict,
           dirs: tuple[str, ...], velocity: dict[str, float]
           ) -> tuple[RobotSpec, Any, bool | None]:
    """The spec with its goal, start direction and posture (pinned, or searched, turning
    the hand about its forward axis when no reach passes upright), the link pairs whose
    meshes overlap everywhere (pinned, or found), and the model that goes with them."""
    from .collide import collision_test

    keys = ("goal", "start_direction", "posture")
    if all(k in pins for k in keys) and "allowed_contacts" in pins:
        return replace(spec, **{k: pins[k] for k in keys}), model, None
    test = collision_test(urdf, spec.arm_joints, dirs, spec.allowed_contacts)
    try:
        if test is not None and "allowed_contacts" not in pins:
            test.learn_overlaps(np.array(model.lowerPositionLimit),
                                np.array(model.upperPositionLimit))
            spec = replace(spec, allowed_contacts=test.overlapping)
            src["allowed_contacts"] = (f"derived: link pairs touching in every one of "
                                       f"{SAMPLES} sampled configurations")
        if all(k in pins for k in keys):
            return replace(spec, **{k: pins[k] for k in keys}), model, None
        rolls = (spec.ee_roll,) if "ee_roll" in pins else ROLLS
        first = None
        for roll in rolls:
            m = model if roll == spec.ee_roll else _gazing(
                urdf, spec.arm_joints, velocity,
                (spec.ee_link or spec.ee_frame, spec.forward, spec.ee_offset, roll))
            trial = replace(spec, ee_roll=roll, ee_frame=GAZE_FRAME if roll else spec.ee_frame,
                            ee_link=spec.ee_link or (spec.ee_frame if roll else ""))
            done = _search(trial, m, pins, src, test)
            first = first or done
            if done[2]:
                if roll:
                    src["ee_roll"] = "derived: no reach passes with the hand upright"
                return done
        assert first is not None
        return first
    finally:
        if test is not None:
            test.close()


def _search(spec: RobotSpec, model: Any, pins: dict, src: dict, test: Any
            ) -> tuple[RobotSpec, Any, bool]:
    from .derive import find_reach
    from .kinematics import arm_model

    found = find_reach(arm_model(spec, model), pins.get("goal"), pins.get("start_direction"),
                       pins.get("posture"), test)
    for k in ("goal", "start_direction", "posture"):
        if k not in pins:
            src[k] = found.how
    return replace(spec, goal=found.goal, start_direction=found.start_direction,
                   posture=found.posture), model, found.ok
