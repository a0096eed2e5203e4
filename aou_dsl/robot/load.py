"""A robot name or path -> a loaded robot: its spec, its URDF and its kinematic model.

``robot`` is a built-in arm's name (:data:`aou_dsl.core.robot_specs.ROBOTS`) or a path to a URDF or
a robot description file (TOML). Each robot is loaded once per process
(:func:`load_robot` is cached): the URDF is parsed, the kinematic model is built by
Pinocchio from the joints alone (no mesh is read), and what no file pins is derived
(:mod:`.derive`). :func:`scene_urdf` writes, once per process, the copy of the URDF that
PyBullet loads.

"Once" means once per content: every cache of a loaded robot is keyed by
:func:`robot_key`, which holds the digest of each file the robot is made from (the
robot description, the URDF, the meshes). A file edited while a tool runs makes the next
look-up load the robot again.
"""

from __future__ import annotations

import atexit
import hashlib
import os
import shutil
import tempfile
from collections.abc import Sequence
from dataclasses import replace

from ..core.codes import C312, R402, V109
from ..core.diagnostics import AouError, Diagnostic, Span, diag
from ..core.memo import cached, files_key, table
from ..core.options import package_dirs as package_dirs_of
from ..core.robot_specs import ROBOT_FILE_TYPES, ROBOTS, UNSOURCED, RobotSpec, is_robot_file
from ..core.trajectory import FrameDefinition
from .assemble import assemble, filled_velocities
from .kinematics import ArmModel, arm_model, frame_id
from .model import Robot, gaze_of, reduced_model
from .urdf import read_urdf, scene_xml

__all__ = ["Robot", "load_arm", "load_robot", "robot_diagnostics", "robot_key",
           "scene_urdf", "unknown_robot"]

#: Per robot and package folders: the files it was last made from and their digests.
_FILES = table("aou_dsl.robot.load.robot_files", 64)

def unknown_robot(robot: str, span: Span) -> Diagnostic:
    """V109 for a name that is neither a built-in arm nor a robot file."""
    from ..lang.values import robot_hint

    return diag(V109, f"unknown robot `{robot}`: expected one of {', '.join(ROBOTS)}, "
                f"or a quoted path to a robot file ({' or '.join(ROBOT_FILE_TYPES)})", span,
                hint=robot_hint(robot, ROBOTS), found=robot, valid=list(ROBOTS))


def load_robot(robot: str, package_dirs: Sequence[str] = ()) -> Robot:
    """The robot named ``robot`` (a built-in name or a file path), loaded once.

    Args:
        robot: a name of :data:`aou_dsl.core.robot_specs.ROBOTS`, or a ``.urdf``/``.toml`` path.
        package_dirs: folders searched first for ``package://`` meshes (the command
            line's ``--package-dir``, :attr:`BuildOptions.package_dirs`).

    Raises:
        AouError: V109 for an unknown robot or a robot file aou cannot use, I501 for a
            file that cannot be read.
    """
    dirs = package_dirs_of(package_dirs)
    return _load(robot, dirs, robot_key(robot, dirs, meshes=False))


def robot_key(robot: str, package_dirs: Sequence[str] = (), *, meshes: bool = True
              ) -> tuple:
    """What a loaded ``robot`` depends on: each file it is made from (the robot file,
    the URDF it names and, with ``meshes``, the URDF's meshes:
    :func:`~.files_read.robot_files`) with the SHA-256 of its bytes. A cache of anything
    made from the robot holds it in its key; what is made from the joints alone (the
    arm's model, its limits) does without the meshes.

    One ``stat`` per file: the files are found again only when one of them changed (a
    description may then name another URDF), and a file is hashed only when its
    ``stat`` changed (:func:`~aou_dsl.core.memo.file_digest`). Never raises: a file
    that cannot be read has the digest "" (the load says what is wrong with it)."""
    dirs = package_dirs_of(package_dirs)
    kept = _FILES.get((robot, dirs))
    if kept is not None:
        paths, key, head = kept
        if meshes and files_key(paths) == key:
            return key
        if not meshes and files_key(paths[:head]) == key[:head]:
            return key[:head]
    from .files_read import robot_files

    missing: list[str] = []
    try:
        paths = tuple(robot_files(robot, dirs, missing))
    except Exception:  # noqa: BLE001 - the load itself says what is wrong
        paths = () if robot in ROBOTS else (robot,)
    key = files_key(paths)
    head = min(len(paths), (0 if robot in ROBOTS else 1) + 1)  # the robot file, its URDF
    if not missing:  # a mesh not there yet is looked for again at the next call
        _FILES.put((robot, dirs), (paths, key, head))
    return key if meshes else key[:head]


@cached(maxsize=16)
def _load(robot: str, dirs: tuple[str, ...], key: tuple) -> Robot:
    """The robot, loaded; ``key`` (:func:`robot_key`) keeps the cache true to the files."""
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


def robot_diagnostics(robot: str, *, collision_check: bool = True, span: Span | None = None,
                      package_dirs: Sequence[str] = ()) -> list[Diagnostic]:
    """What a build says about its robot: C313 warnings (limits from no source) and,
    unless ``collision_check`` is False, C312 when the arm has no collision geometry.
    They point at ``span`` (where the robot was named: the ``robot`` line, the command
    line) when given, else at the file a user would edit: the robot description, the
    user's URDF, or for a built-in arm ``<robot NAME>`` (its URDF is installed data).

    Raises:
        AouError: as :func:`load_robot`.
    """
    r = load_robot(robot, package_dirs)
    out = list(r.warnings)
    if collision_check and not r.collision:
        out.append(diag(
            C312, f"robot `{robot}` has no collision geometry on the links its arm moves: "
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


@cached(maxsize=1)
def _tmp_dir() -> str:
    """This process's folder for the copies PyBullet loads (``aou-robots-PID-...``),
    removed at exit; those of processes that were killed are removed here first."""
    from ..core.files import sweep_stale

    sweep_stale(tempfile.gettempdir(), "aou-robots-")
    path = tempfile.mkdtemp(prefix=f"aou-robots-{os.getpid()}-")
    atexit.register(shutil.rmtree, path, True)
    return path


@cached(maxsize=16)
def _scene_file(robot: str, dirs: tuple[str, ...], visuals: bool, key: tuple) -> str:
    """:func:`scene_urdf` of the robot whose files (meshes included) are ``key``."""
    r = load_robot(robot, dirs)
    text, missing = scene_xml(r.urdf, r.package_dirs, r.gaze, visuals=visuals)
    if missing:
        raise AouError(diag(
            V109, f"robot `{robot}`: {len(missing)} mesh file(s) not found, first "
            f"`{missing[0]}`", Span.whole_file(r.urdf.path),
            hint="give the folder of the package (or one holding it) with --package-dir, "
                 "or in ROS_PACKAGE_PATH, or `package_dirs` in a robot description; or "
                 "compile with --no-check (the checks are then skipped, and the output "
                 "says so)"))
    digest = hashlib.sha256(text.encode()).hexdigest()[:12]
    stem = os.path.splitext(os.path.basename(r.urdf.path))[0]
    path = os.path.join(_tmp_dir(), f"{stem}-{digest}.urdf")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return path


def scene_urdf(robot: str, *, visuals: bool = False, package_dirs: Sequence[str] = ()) -> str:
    """The path of the URDF PyBullet loads for ``robot``: mesh paths absolute, the
    end-effector frame added when aou adds one, visual shapes only if ``visuals``.

    Raises:
        AouError: V109 when a mesh the copy needs cannot be found.
    """
    dirs = package_dirs_of(package_dirs)
    return _scene_file(robot, dirs, visuals, robot_key(robot, dirs))


def load_arm(robot: str, ee_frame: str | None = None,
             package_dirs: tuple[str, ...] = (),
             frame: FrameDefinition | None = None) -> ArmModel:
    """The arm of ``robot`` (a built-in name or a robot file's path), its kinematics built
    from the URDF's joints alone (no mesh is read), once per process.

    ``frame``, when given, defines ``ee_frame`` (a trajectory file's
    ``ee_frame_definition``): the frame is placed as it says, so a file compiled for an
    arm aou knew, with a frame aou added, measures on the same arm loaded from its URDF.

    Raises:
        AouError: V109 for an unknown robot or a robot file aou cannot use (I501 when it
            cannot be read), R402 for a frame the model lacks (listing the valid ones).
    """
    key = robot_key(robot, package_dirs, meshes=False)
    return _arm(robot, ee_frame, package_dirs, frame, key)


@cached(maxsize=64)
def _arm(robot: str, ee_frame: str | None, package_dirs: tuple[str, ...],
         frame: FrameDefinition | None, key: tuple) -> ArmModel:
    """:func:`load_arm` of the robot whose files are ``key``; the arm's
    :attr:`~.kinematics.ArmModel.key` says all of it, for the caches of what is made
    from the arm."""
    dirs = package_dirs_of(package_dirs)
    r = _load(robot, dirs, key)
    arm = replace(arm_model(r.spec, r.model, no_effort=r.no_effort),
                  key=(robot, dirs, ee_frame, frame, key))
    if frame is not None and not frame.is_link and (ee_frame in (None, frame.name)):
        from .identity import with_frame

        return with_frame(arm, frame, f"<robot {robot}>")
    if ee_frame is None or ee_frame == r.spec.ee_frame:
        return arm
    fid = frame_id(r.model, ee_frame)
    if fid < 0:
        valid = sorted({f.name for f in r.model.frames})
        raise AouError(diag(R402, f"robot `{robot}` has no frame `{ee_frame}`",
                            Span.whole_file(f"<robot {robot}>"),
                            hint=f"frames: {', '.join(valid)}", valid=valid))
    return replace(arm, frame_id=fid)
