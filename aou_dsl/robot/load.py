"""A robot name or path -> a loaded robot: its spec, its URDF and its kinematic model.

``robot`` is a built-in arm's name (:data:`aou_dsl.core.robot_specs.ROBOTS`) or a path to a URDF or
a robot description file (TOML). Each robot is loaded once per process
(:func:`load_robot` is cached): the URDF is parsed, the kinematic model is built by
Pinocchio from the joints alone (no mesh is read), and what no file pins is derived
(:mod:`.derive`). :func:`scene_urdf` writes, once per process, the copy of the URDF that
PyBullet loads.
"""

from __future__ import annotations

import atexit
import functools
import hashlib
import os
import shutil
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from ..core.diagnostics import AouError, Diagnostic, Span, diag
from ..core.robot_specs import ROBOT_FILE_TYPES, ROBOTS, UNSOURCED, RobotSpec, is_robot_file
from .assemble import assemble, filled_velocities
from .urdf import GAZE_FRAME, Gaze, Urdf, gaze_offset, gaze_rpy, kinematic_xml, read_urdf, scene_xml

__all__ = ["Robot", "load_robot", "reduced_model", "robot_diagnostics", "scene_urdf",
           "set_package_dirs", "unknown_robot"]

_PACKAGE_DIRS: tuple[str, ...] = ()


def set_package_dirs(dirs: Sequence[str]) -> None:
    """Folders searched first for ``package://`` meshes, for every robot loaded after
    (the command line's ``--package-dir``)."""
    global _PACKAGE_DIRS
    _PACKAGE_DIRS = tuple(os.path.abspath(d) for d in dirs)


@dataclass(frozen=True)
class Robot:
    """A loaded robot.

    Attributes:
        spec: everything aou knows of it, pinned or derived.
        urdf: its URDF, parsed.
        model: the Pinocchio model of its arm joints (the rest locked at zero), with
            ``spec.ee_frame``.
        package_dirs: folders given for its ``package://`` meshes.
        description: the robot description file it was read from ("" for none).
        no_effort: arm joints whose URDF gives no effort limit.
        filled_velocity: velocity limits [rad/s] given to joints whose URDF has none.
        warnings: C313 diagnostics (limits from no source).
        reach_ok: whether the derived default reach passed every probe (None: pinned).
    """

    spec: RobotSpec
    urdf: Urdf
    model: Any
    package_dirs: tuple[str, ...] = ()
    description: str = ""
    no_effort: tuple[str, ...] = ()
    filled_velocity: dict[str, float] = field(default_factory=dict)
    warnings: tuple[Diagnostic, ...] = ()
    reach_ok: bool | None = None

    @property
    def collision(self) -> bool:
        """Whether any link the arm moves has collision geometry."""
        moved: set[str] = set()
        frontier = [self.urdf.joint(self.spec.arm_joints[0]).child]
        while frontier:
            link = frontier.pop()
            moved.add(link)
            frontier += [j.child for j in self.urdf.children(link)]
        return bool(moved & self.urdf.collision_links)

    @property
    def gaze(self) -> Gaze | None:
        """``(ee_link, forward, ee_offset, ee_roll)`` when aou adds the end-effector frame."""
        return gaze_of(self.spec)


def gaze_of(spec: RobotSpec) -> Gaze | None:
    """``(ee_link, forward, ee_offset, ee_roll)`` when aou adds the end-effector frame."""
    return (spec.ee_link, spec.forward, spec.ee_offset, spec.ee_roll) if spec.ee_link else None


def unknown_robot(robot: str, span: Span) -> Diagnostic:
    """V109 for a name that is neither a built-in arm nor a robot file."""
    from ..lang.values import did_you_mean

    return diag("V109", f"unknown robot `{robot}`: expected one of {', '.join(ROBOTS)}, "
                f"or a quoted path to a robot file ({' or '.join(ROBOT_FILE_TYPES)})", span,
                hint=did_you_mean(robot, ROBOTS), found=robot, valid=list(ROBOTS))


def load_robot(robot: str, package_dirs: Sequence[str] | None = None) -> Robot:
    """The robot named ``robot`` (a built-in name or a file path), loaded once.

    Args:
        robot: a name of :data:`aou_dsl.core.robot_specs.ROBOTS`, or a ``.urdf``/``.toml`` path.
        package_dirs: folders searched first for ``package://`` meshes; None for those
            of :func:`set_package_dirs`.

    Raises:
        AouError: V109 for an unknown robot or a robot file aou cannot use, I501 for a
            file that cannot be read.
    """
    dirs = _PACKAGE_DIRS if package_dirs is None else tuple(
        os.path.abspath(d) for d in package_dirs)
    return _load(robot, dirs)


@functools.cache
def _load(robot: str, dirs: tuple[str, ...]) -> Robot:
    if robot in ROBOTS:
        return _builtin(robot, dirs)
    if not is_robot_file(robot) and not os.path.isfile(robot):
        raise AouError(unknown_robot(robot, Span.whole_file(f"<robot {robot}>")))
    if robot.lower().endswith(".toml"):
        from .description import read_description

        desc = read_description(robot)
        if desc.robot:
            base = _builtin_spec(desc.robot, desc.path)
            urdf = read_urdf(_data_path(base.urdf))
            return assemble(robot, urdf, desc, (*desc.package_dirs, *dirs), base)
        return assemble(robot, read_urdf(desc.urdf), desc, (*desc.package_dirs, *dirs))
    return assemble(robot, read_urdf(robot), None, dirs)


def _builtin_spec(name: str, where: str) -> RobotSpec:
    if name not in ROBOTS:
        raise AouError(unknown_robot(name, Span.whole_file(where)))
    return ROBOTS[name]


def _data_path(sub: str) -> str:
    """A file inside example-robot-data's ``robots`` folder."""
    import example_robot_data as erd

    return os.path.join(erd.getModelPath(sub), sub)


def _builtin(name: str, dirs: tuple[str, ...]) -> Robot:
    spec = ROBOTS[name]
    urdf = read_urdf(_data_path(spec.urdf))
    filled = filled_velocities(urdf, spec.arm_joints)
    model = reduced_model(urdf, spec.arm_joints, filled, gaze_of(spec))
    warnings = []
    if name in UNSOURCED or not spec.joint_jerk:
        from .assemble import default_limits_warning

        warnings.append(default_limits_warning(
            spec, urdf, "", accel=name in UNSOURCED, jerk=not spec.joint_jerk,
            velocity=filled))
    no_effort = tuple(j for j in spec.arm_joints if urdf.joint(j).effort is None)
    return Robot(spec, urdf, model, dirs, "", no_effort, filled, tuple(warnings))


def reduced_model(urdf: Urdf, joints: Sequence[str], velocity: dict[str, float],
                  gaze: Gaze | None) -> Any:
    """The Pinocchio model of ``joints`` (every other joint welded at zero), built from
    the URDF's kinematics only; with :data:`GAZE_FRAME` when ``gaze`` is given.

    Raises:
        AouError: V109 when Pinocchio cannot build it, or its joints are not ``joints``.
    """
    import numpy as np
    import pinocchio as pin

    try:
        model = pin.buildModelFromXML(kinematic_xml(urdf, joints, velocity))
    except (RuntimeError, ValueError) as exc:
        raise AouError(diag("V109", f"`{os.path.basename(urdf.path)}`: Pinocchio cannot "
                            f"build its kinematics: {exc}", Span.whole_file(urdf.path))
                       ) from None
    names = tuple(model.names[1:])
    if names != tuple(joints):
        raise AouError(diag(
            "V109", f"`{os.path.basename(urdf.path)}`: the arm's joints from the base "
            f"outward are {', '.join(names)}; expected {', '.join(joints)}",
            Span.whole_file(urdf.path), hint="list `arm_joints` from the base outward"))
    if gaze is not None:  # added here, not in the XML: link and joint names may clash
        from .kinematics import frame_id

        parent = frame_id(model, gaze[0])
        f = model.frames[parent]
        turn = pin.SE3(pin.rpy.rpyToMatrix(*gaze_rpy(gaze[1], gaze[3])),
                       np.array(gaze_offset(gaze[1], gaze[2])))
        model.addFrame(pin.Frame(GAZE_FRAME, f.parentJoint, parent, f.placement * turn,
                                 pin.FrameType.OP_FRAME))
    return model


def robot_diagnostics(robot: str, *, collision_check: bool = True,
                      span: Span | None = None) -> list[Diagnostic]:
    """What a build says about its robot: C313 warnings (limits from no source) and,
    unless ``collision_check`` is False, C312 when the arm has no collision geometry.
    They point at ``span`` (where the robot was named: the ``robot`` line, the command
    line) when given, else at the file a user would edit: the robot description, the
    user's URDF, or for a built-in arm ``<robot NAME>`` (its URDF is installed data).

    Raises:
        AouError: as :func:`load_robot`.
    """
    r = load_robot(robot)
    out = list(r.warnings)
    if collision_check and not r.collision:
        out.append(diag(
            "C312", f"robot `{robot}` has no collision geometry on the links its arm moves: "
            "self-collision and contact with the target and the table cannot be checked",
            Span.whole_file(r.urdf.path),
            hint="add <collision> shapes to the URDF, or compile with --no-collision-check "
                 "(the output then records that collisions were not checked)"))
    if span is None and (r.description or robot in ROBOTS):
        span = Span.whole_file(r.description or f"<robot {robot}>")
    if span is not None:
        out = [Diagnostic(d.code, d.severity, d.message, span, d.hint, d.fields)
               for d in out]
    return out


_TMP: list[str] = []


def _tmp_dir() -> str:
    if not _TMP:
        _TMP.append(tempfile.mkdtemp(prefix="aou-robots-"))
        atexit.register(shutil.rmtree, _TMP[0], True)
    return _TMP[0]


@functools.cache
def _scene_file(robot: str, dirs: tuple[str, ...], visuals: bool) -> str:
    r = _load(robot, dirs)
    text, missing = scene_xml(r.urdf, r.package_dirs, r.gaze, visuals=visuals)
    if missing:
        raise AouError(diag(
            "V109", f"robot `{robot}`: {len(missing)} mesh file(s) not found, first "
            f"`{missing[0]}`", Span.whole_file(r.urdf.path),
            hint="give the folder of the package (or one holding it) with --package-dir, "
                 "or in ROS_PACKAGE_PATH, or `package_dirs` in a robot description"))
    digest = hashlib.sha256(text.encode()).hexdigest()[:12]
    stem = os.path.splitext(os.path.basename(r.urdf.path))[0]
    path = os.path.join(_tmp_dir(), f"{stem}-{digest}.urdf")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return path


def scene_urdf(robot: str, *, visuals: bool = False) -> str:
    """The path of the URDF PyBullet loads for ``robot``: mesh paths absolute, the
    end-effector frame added when aou adds one, visual shapes only if ``visuals``.

    Raises:
        AouError: V109 when a mesh the copy needs cannot be found.
    """
    return _scene_file(robot, _PACKAGE_DIRS, visuals)
