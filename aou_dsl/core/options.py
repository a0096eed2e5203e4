"""What a build is asked to do, in one frozen, typed, picklable object.

:class:`BuildOptions` travels from :func:`aou_dsl.compile` and the command line through
the builder, the worker pool and a Dask cluster unchanged: a worker process receives
every setting its parent had, ``--package-dir`` included, and nothing is read from a
module's state.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from typing import Any

__all__ = ["CONTROLLERS", "BuildOptions", "SceneOptions", "package_dirs"]

#: Motion generators whose rates and published limits ``controller`` can add to the checks.
CONTROLLERS = ("franka", "ur")


def package_dirs(dirs: Iterable[str | os.PathLike] | None) -> tuple[str, ...]:
    """Folders for ``package://`` meshes as absolute paths, in the order given."""
    return tuple(os.path.abspath(os.fspath(d)) for d in (dirs or ()))


@dataclass(frozen=True)
class SceneOptions:
    """The scene around the robot.

    Attributes:
        target_size: edge of the cube at the goal, which nothing may touch [m].
        table_height: height of the table plane in the base frame [m]; None for no table.
        package_dirs: folders searched first for the robot's ``package://`` meshes.
    """

    target_size: float = 0.05
    table_height: float | None = 0.0
    package_dirs: tuple[str, ...] = ()


@dataclass(frozen=True)
class BuildOptions:
    """How to build a behaviour.

    Attributes:
        robot: a built-in arm's name or a robot file's path; overrides the file's
            ``robot`` line (None: the file's).
        package_dirs: folders searched first for ``package://`` meshes (absolute).
        rate: output sample rate [Hz]; None for the compiler's default (250).
        check: run the safety replay (a trajectory that fails it has no document).
        scene: the scene the checks use (its ``package_dirs`` are this object's).
        collision_check: False accepts a robot without collision shapes (C312).
        controller: ``"franka"`` or ``"ur"``: that motion generator's limits are checked too.
        fit: change what the arm cannot give to what it can (``--fit``; the rule is in
            :mod:`aou_dsl.fit.plan`, for a reach :mod:`aou_dsl.fit.reach`),
            each change a C314 warning.
    """

    robot: str | None = None
    package_dirs: tuple[str, ...] = ()
    rate: float | None = None
    check: bool = True
    scene: SceneOptions = field(default_factory=SceneOptions)
    collision_check: bool = True
    controller: str | None = None
    fit: bool = False

    def __post_init__(self) -> None:
        dirs = package_dirs(self.package_dirs)
        object.__setattr__(self, "package_dirs", dirs)
        if self.scene.package_dirs != dirs:
            object.__setattr__(self, "scene", replace(self.scene, package_dirs=dirs))
        if self.rate is not None and not (isinstance(self.rate, (int, float))
                                          and math.isfinite(self.rate) and self.rate > 0):
            raise ValueError(f"rate must be a positive number of Hz, found {self.rate!r}")
        if self.controller is not None and self.controller not in CONTROLLERS:
            raise ValueError(f"controller must be one of {', '.join(CONTROLLERS)}, "
                             f"found {self.controller!r}")

    def replace(self, **changes: Any) -> BuildOptions:
        """A copy with ``changes`` (unknown names raise TypeError)."""
        return replace(self, **changes)
