"""The robot layer: any arm, from a built-in name, a URDF as vendors ship it or a robot
description file (TOML), to a kinematic model, IK and a PyBullet scene.

The modules, lightest first: :mod:`.urdf` (reading and rewriting URDFs), :mod:`.chain`
(the arm inside a URDF), :mod:`.description` (robot description files),
:mod:`.kinematics` (the arm's Pinocchio model), :mod:`.batch_fk` (forward kinematics of
many samples at once), :mod:`.geometry` (gaze-locked poses around the goal), :mod:`.ik`,
:mod:`.bullet` (PyBullet, imported quietly), :mod:`.collide`, :mod:`.derive` (forward
axis, shiver joint, default reach), :mod:`.model` (a loaded robot), :mod:`.assemble`,
:mod:`.load` (a robot name or path -> a loaded robot, cached per process and per set of
package folders), :mod:`.scene` (a PyBullet world holding the robot), :mod:`.summary`
(what ``aouc robot`` prints). Other layers use :func:`load_robot`, :func:`load_arm`,
:func:`robot_diagnostics` and :func:`describe_robot`. Importing this package imports none
of them.
"""

from __future__ import annotations

from typing import Any

__all__ = ["describe_robot", "load_robot", "robot_diagnostics"]


def __getattr__(name: str) -> Any:
    if name in ("load_robot", "robot_diagnostics"):
        from . import load as loader

        return getattr(loader, name)
    if name == "describe_robot":
        from .summary import describe_robot

        return describe_robot
    raise AttributeError(name)
