"""aou: a declarative language and compiler for expressive robot-arm motion.

The public API (see docs/api.md)::

    import aou_dsl
    result = aou_dsl.lint("behaviours/hesitant.aou")        # diagnostics, C-V point
    build = aou_dsl.compile("behaviours/hesitant.aou")      # trajectory, descriptors
    measured = aou_dsl.measure("recording.csv", robot="panda", goal=(0.55, 0, 0.25))

Importing the package is cheap: the numerical stages (Pinocchio, TOPP-RA, PyBullet)
load only when a function that needs them runs.
"""

from __future__ import annotations

from typing import Any

from .version import __version__ as __version__

__all__ = [
    "REGISTRY",
    "AouError",
    "BuildOptions",
    "BuildResult",
    "CheckReport",
    "Descriptors",
    "Diagnostic",
    "FileResult",
    "Measured",
    "Session",
    "Trajectory",
    "check",
    "compile",
    "lint",
    "lint_paths",
    "measure",
    "read_trajectory",
]

#: name -> module that defines it, imported on first use.
_LAZY = {
    "REGISTRY": "lang.descriptors", "Descriptors": "lang.descriptors",
    "AouError": "core.diagnostics", "Diagnostic": "core.diagnostics",
    "BuildOptions": "core.options", "Trajectory": "core.trajectory",
    "BuildResult": "driver.builder", "Session": "driver.session", "FileResult": "lang.linter",
    "CheckReport": "safety.replay", "Measured": "measuring.measured",
    "check": "api", "compile": "api", "lint": "api", "lint_paths": "api",
    "measure": "api", "read_trajectory": "api",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        module = importlib.import_module(f".{_LAZY[name]}", __name__)  # safe: table _LAZY
        value = getattr(module, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'aou_dsl' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])
