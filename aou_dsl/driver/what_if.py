"""The motion a file declares where the arm's limits refuse it: planned with the arm's
joint velocity, acceleration and jerk limits lifted (:data:`LIFT` times higher; its
reach, joint ranges and effort as they are), so that ``aouc check --track`` can say what
the servos would show if the controller were sent that motion anyway. A what-if only:
the file still fails, and nothing of it is written."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..core.codes import C304, C308, C309
from ..core.diagnostics import Diagnostic, Severity, has_errors
from ..lang.linter import lint_file

if TYPE_CHECKING:
    from ..core.trajectory import Trajectory

__all__ = ["LIFT", "LIMIT_REFUSALS", "declared_motion", "refused_by_limits"]

#: How much higher the lifted limits are: far above what any motion of the language
#: needs, so that none of them binds and the plan follows the declared values.
LIFT = 1000.0

#: The refusals of the arm's velocity, acceleration and jerk limits (a move short of its
#: acceleration, a shiver or a tilt too fast): the ones lifting those limits answers.
LIMIT_REFUSALS = frozenset({C304, C308, C309})


def refused_by_limits(diagnostics: list[Diagnostic]) -> bool:
    """Whether the file fails and every error is a refusal of the arm's limits."""
    errors = [d for d in diagnostics if d.severity is Severity.ERROR]
    return bool(errors) and all(d.code in LIMIT_REFUSALS for d in errors)


def declared_motion(path: str, robot: str | None = None,
                    package_dirs: tuple[str, ...] = ()) -> Trajectory | None:
    """The motion ``path`` declares, planned on ``robot`` (None: the file's) with its
    limits lifted; None when the file cannot be planned so either (an error of its
    own, a pose out of reach: what lifting the limits does not answer)."""
    from ..compiler.pipeline import CompileOptions, compile_behaviour
    from ..core.options import package_dirs as absolute

    lint = lint_file(path)
    b, tl = lint.behaviour, lint.timeline
    if b is None or tl is None or has_errors(lint.diagnostics):
        return None
    if robot is not None:
        b = b.replace(settings=b.settings.replace(robot=robot))
    res = compile_behaviour(b, CompileOptions(package_dirs=absolute(package_dirs),
                                              lift=LIFT), tl)
    if not res.ok or res.trajectory is None:
        return None
    return res.trajectory.with_(path=path)
