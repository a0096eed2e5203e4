"""A shiver no frequency fits (C308 without a frequency: even 1 Hz, the slowest the
language has, is too fast at that amplitude) is fitted by its amplitude instead, at its
frequency, by the rule of the other values: the widest amplitude the shiver joint
follows at that frequency is its bound ``P`` (the shiver's peaks grow in proportion to
the amplitude, so ``P`` is the amplitude over its largest ratio to a limit), and the
declared amplitude is compressed under it by
:func:`~aou_dsl.compiler.fitting.compress`, an increasing map, so a variant pair keeps
its order. The change is the refusal's hint (``write `shiver 2.05deg f=2.5Hz` at line
5``) and its field ``reach`` (read by ``--fit``); an amplitude too small to be seen is not
offered.
"""

from __future__ import annotations

import math
from typing import Any

from ..core.codes import C308
from ..core.diagnostics import Severity
from ..lang.linter import lint_source
from .reach_fit import Statement, offered

__all__ = ["with_amplitude_fit"]


def with_amplitude_fit(res: Any, robot: str | None, package_dirs: tuple[str, ...]) -> Any:
    """``res`` (a build result) with its C308 that no frequency answers given the
    amplitude that fits at the declared frequency."""
    lint, b = res.lint, res.lint.behaviour
    d = next((x for x in res.diagnostics if x.code == C308 and x.severity is Severity.ERROR
              and not x.fields.get("max_frequency") and x.span.path == lint.path), None)
    if d is None or b is None or lint.source is None or lint.timeline is None:
        return res
    ep = next((e for e in lint.timeline.episodes if e.kind == "shiver" and e.span == d.span),
              None)
    st = Statement(lint.source, d.span.line, d.span.col, d.span.end_col, ("shiver",))
    if ep is None or not st.ok or st.dim != "angle":
        return res
    from ..compiler.fitting import compress
    from ..compiler.oscillation import shiver_ratios
    from ..lang.primitives import MIN_ANGLE
    from ..robot.load import load_arm

    arm = load_arm(robot or b.settings.robot, None, package_dirs)
    bound = ep.amplitude / max(shiver_ratios(arm, ep.amplitude, ep.f, ep.duration))
    stmt, text = st.with_value(compress(abs(st.value), bound))
    fitted = Statement(stmt, 1, 1, len(stmt) + 1, ("shiver",))
    if not fitted.ok or abs(fitted.value) < MIN_ANGLE or not math.isfinite(bound):
        return res
    again = lint_source(text, lint.path)
    if b.state is not None and (again.cv is None or again.cv.state != b.state):
        return res  # the smaller shiver would express another state: nothing to offer
    record = st.record(fitted.written, stmt, bound, d.fields.get("joint"),
                       d.fields.get("limit"))
    res.diagnostics = [offered(x, [record]) if x is d else x for x in res.diagnostics]
    return res
