"""Robots from files: URDFs as vendors ship them, robot description files (TOML), and the
derivation of what they do not say.

The modules, lightest first: :mod:`.table` (the built-in arms' geometry, plain data),
:mod:`.urdf` (reading and rewriting URDFs), :mod:`.chain` (the arm inside a URDF),
:mod:`.description` (robot description files), :mod:`.derive` (forward axis, shiver
joint, default reach; Pinocchio), :mod:`.load` (a robot name or path -> a loaded robot,
once per process), :mod:`.describe` (what ``aouc robot`` prints). Importing this package
imports none of them.
"""

from __future__ import annotations

from typing import Any

__all__ = ["describe_robot", "load_robot", "robot_diagnostics", "set_package_dirs"]


def __getattr__(name: str) -> Any:
    if name in ("load_robot", "robot_diagnostics", "set_package_dirs"):
        from . import load

        return getattr(load, name)
    if name == "describe_robot":
        from .summary import describe_robot

        return describe_robot
    raise AttributeError(name)
