"""The Python API: lint, compile, check and measure, each returning records.

Everything ``aouc`` does goes through these functions; the command line only parses
arguments, calls them, prints and maps exit codes. A problem of the input is never an
exception from ``lint`` or ``compile``: it is a diagnostic in the result. ``check`` and
``measure`` raise :class:`~aou_dsl.core.diagnostics.AouError` (with its diagnostics) when
their input cannot be read.

Example::

    import aou_dsl

    build = aou_dsl.compile("behaviours/hesitant.aou")
    if build.ok:
        print(build.measured.descriptors["pause_count"])   # 5
        trajectory = build.trajectory                       # t, q, qd, qdd, joint_names
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from .core.options import BuildOptions, SceneOptions
from .core.options import package_dirs as package_dirs_of
from .driver.builder import BuildResult, build_file, build_source
from .lang.linter import FileResult, lint_file, lint_paths, lint_source

if TYPE_CHECKING:
    from .core.trajectory import Trajectory
    from .measuring.measured import Measured
    from .safety.replay import CheckReport

__all__ = ["check", "compile", "lint", "lint_paths", "measure", "read_trajectory"]

Source = str | os.PathLike


def lint(path: Source | None = None, *, source: str | None = None) -> FileResult:
    """Lint a ``.aou`` file (``path``) or source text (``source``; ``path`` then only
    names it in diagnostics)."""
    if source is not None:
        return lint_source(source, os.fspath(path) if path is not None else "<string>")
    if path is None:
        raise TypeError("lint() needs a path or source=")
    return lint_file(os.fspath(path))


def compile(path: Source | None = None, *, source: str | None = None,  # noqa: A001
            robot: str | None = None, rate: float | None = None, check: bool = True,
            target_size: float = 0.05, table_height: float | None = 0.0,
            collision_check: bool = True, controller: str | None = None,
            package_dirs: Sequence[Source] = (), fit: bool = False,
            options: BuildOptions | None = None) -> BuildResult:
    """Lint, compile, check and measure one behaviour.

    Args:
        path: a ``.aou`` file; or ``source`` text.
        robot: overrides the file's ``robot`` line.
        rate: output sample rate [Hz] (default 250).
        check: run the safety replay (a trajectory that fails it has no document).
        target_size, table_height: the scene the checks use [m] (None: no table).
        collision_check: False accepts a robot without collision shapes (C312); the
            document's ``checks.collision_checked`` then says so.
        controller: ``"franka"`` or ``"ur"``: also check that motion generator's rate and
            published limits (joint jerk at 1 kHz against the robot's is always checked).
        package_dirs: folders searched first for the robot's ``package://`` meshes.
        fit: change what the arm cannot give to what it can (C314 warnings; the
            result's ``fitted_source`` is the fitted file).
        options: all of the above in one :class:`~aou_dsl.core.options.BuildOptions`
            (when given, the other keywords are not read).

    Returns:
        A :class:`~aou_dsl.driver.builder.BuildResult`: ``ok``, ``diagnostics``, ``trajectory``,
        ``declared`` and ``measured`` descriptors, the output ``document``.
    """
    if options is None:
        options = BuildOptions(
            robot=robot, rate=rate, check=check, collision_check=collision_check,
            controller=controller, package_dirs=package_dirs_of(package_dirs), fit=fit,
            scene=SceneOptions(target_size=target_size, table_height=table_height))
    if source is not None:
        return build_source(source, os.fspath(path) if path is not None else "<string>",
                            options)
    if path is None:
        raise TypeError("compile() needs a path or source=")
    return build_file(os.fspath(path), options)


def read_trajectory(path: Source, *, robot: str | None = None,
                    goal: tuple[float, float, float] | str | None = None,
                    ee_frame: str | None = None, angle_unit: str | None = None,
                    time_unit: str | None = None,
                    package_dirs: Sequence[Source] = ()) -> Trajectory:
    """A trajectory from a file: aou's JSON or NPZ, or a CSV recording (which needs
    ``robot``); a ``.aou`` file is compiled. ``goal`` (or ``"final"``: the end-effector's
    last position) and ``ee_frame`` override the file's; ``angle_unit="deg"`` and
    ``time_unit="ms"`` read a recording in those units (docs/measure.md); ``package_dirs``
    are the folders of the robot's ``package://`` meshes, kept with the trajectory."""
    from .driver.builder import load_motion

    return load_motion(os.fspath(path), robot=robot, goal=goal, ee_frame=ee_frame,
                       angle_unit=angle_unit, time_unit=time_unit,
                       package_dirs=package_dirs_of(package_dirs))


def _trajectory(what: Trajectory | Source, **options: Any) -> Trajectory:
    from .core.trajectory import Trajectory

    return what if isinstance(what, Trajectory) else read_trajectory(what, **options)


def measure(what: Trajectory | Source, **options: Any) -> Measured:
    """The eleven descriptors of a trajectory (or of a file, read with
    :func:`read_trajectory`'s ``options``), its episodes and its C-V point."""
    from .measuring.measured import measure as measure_trajectory

    return measure_trajectory(_trajectory(what, **options))


def check(what: Trajectory | Source, *, dynamic: bool = True, target_size: float = 0.05,
          table_height: float | None = 0.0, controller: str | None = None,
          **options: Any) -> CheckReport:
    """The safety replay of a trajectory (or a file) in PyBullet: limits, collisions,
    contacts, kinematics agreement and, with ``dynamic``, torques under physics.

    The motion as a controller reads it (joint jerk at its rate, interpolated between the
    samples as a ``joint_trajectory_controller`` does) is checked too when ``controller``
    is named, or when the trajectory carries velocities (a compiled one); a recording of
    positions alone is too noisy for a third derivative unless asked."""
    from .safety.controllers import controller_checks
    from .safety.replay import replay

    tr = _trajectory(what, **options)
    scene = SceneOptions(target_size=target_size, table_height=table_height,
                         package_dirs=tr.package_dirs)
    report = replay(tr, options=scene, dynamic=dynamic)
    if controller is not None or tr.qd is not None:
        report.checks += controller_checks(tr, controller)
    return report


