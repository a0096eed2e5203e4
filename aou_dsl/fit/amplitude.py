"""A shiver no frequency fits that still looks like one (C308 without a frequency: at
its amplitude the arm follows it only slower than
:data:`~aou_dsl.lang.primitives.LOOK_SHIVER_F`, where its swings read as slow rolls) is
fitted by its amplitude instead, by the rule of the other values: the widest amplitude
the shiver joint follows at a frequency is its bound ``P`` (the shiver's peaks grow in
proportion to the amplitude, so ``P`` is the amplitude over its largest ratio to a
limit), and the declared amplitude is compressed under it by
:func:`~aou_dsl.fit.plan.compress`, an increasing map, so a variant pair keeps
its order.

The frequency tried first is the declared one (one change); when the amplitude that fits
there is narrower than a person sees (:data:`~aou_dsl.lang.primitives.VISIBLE_SHIVER`), a
declared frequency above the look's floor is lowered to the floor too, where a wider
shiver fits. The change is the refusal's hint (``write `shiver 2.05deg` at line 5``) and
its field ``reach`` (read by ``--fit``). When neither gives a shiver that is fast enough
and wide enough to look like one, and keeps the file's state, nothing is offered and the
refusal's field ``look`` says why (``--fit`` reports it as C315): a fit never turns a
shiver into a slow roll.
"""

from __future__ import annotations

import math
from typing import Any

from ..core.diagnostics import Diagnostic, Severity
from ..lang.linter import lint_source
from ..lang.primitives import SHIVER
from .reach import Statement, offered
from .refusals import ShiverTooFast, answered

__all__ = ["with_amplitude_fit"]


def _refused(res: Any, d: Diagnostic, why: str) -> Any:
    """``res`` with ``d`` saying why no shiver keeps its look (field ``look``, and its
    hint when it has none: there is no edit to offer)."""
    hint = d.hint or f"no shiver this arm follows keeps the look: {why}"
    res.diagnostics = [answered(x, hint, look=why) if x is d else x
                       for x in res.diagnostics]
    return res


def with_amplitude_fit(res: Any, robot: str | None, package_dirs: tuple[str, ...]) -> Any:
    """``res`` (a build result) with its C308 that no frequency answers given the
    amplitude that fits (at the declared frequency, else at the slowest shiver that
    looks like one), or the reason none does."""
    lint, b = res.lint, res.lint.behaviour
    d = next((x for x in res.diagnostics if isinstance(x.refusal, ShiverTooFast)
              and x.severity is Severity.ERROR and not x.refusal.max_frequency
              and x.span.path == lint.path), None)
    if d is None or b is None or lint.source is None or lint.timeline is None:
        return res
    ep = next((e for e in lint.timeline.episodes if e.kind == SHIVER and e.span == d.span),
              None)
    st = Statement(lint.source, d.span.line, d.span.col, d.span.end_col, (SHIVER,))
    if ep is None or not st.ok or st.dim != "angle":
        return res
    from ..compiler.oscillation import shiver_ratios
    from ..lang.primitives import LOOK_SHIVER_F, VISIBLE_SHIVER, Shiver, shiver_duration
    from ..robot.load import load_arm
    from .plan import compress, shiver_keys
    from .text_edits import set_value, splice, value_text

    arm = load_arm(robot or b.settings.robot, None, package_dirs)
    node = next((n for n in b.primitives if n.span == d.span), None)
    timed = isinstance(node, Shiver) and node.timed
    asked = node.duration if isinstance(node, Shiver) else ep.duration
    least = math.degrees(VISIBLE_SHIVER)
    why = ""
    for fa in (ep.f,) if ep.f <= LOOK_SHIVER_F else (ep.f, LOOK_SHIVER_F):
        dur = shiver_duration(asked, fa)
        bound = ep.amplitude / max(shiver_ratios(arm, ep.amplitude, fa, dur))
        if not math.isfinite(bound):
            return res
        stmt, text = st.with_value(compress(abs(st.value), bound))
        fitted = Statement(stmt, 1, 1, len(stmt) + 1, (SHIVER,))
        if not fitted.ok or abs(fitted.value) < VISIBLE_SHIVER * (1.0 - 1e-9):
            why = (f"at {fa:g} Hz the arm follows a shiver of {math.degrees(bound):.3g} deg "
                   f"at most, under the {least:g} deg a person sees; a slower one than "
                   f"{min(ep.f, LOOK_SHIVER_F):g} Hz would read as slow rolls, not a tremor")
            continue
        keys = shiver_keys(fa, asked if timed else None) if fa != ep.f else []
        for k, v, u, _ in keys:
            stmt = set_value(stmt, k, value_text(k, v, u))
        text = splice(lint.source, st.line, st.col, st.stop, stmt)
        again = lint_source(text, lint.path)
        if not again.ok:
            return res
        if b.state is not None and (again.cv is None or again.cv.state != b.state):
            found = again.cv.state.value if again.cv is not None else "nothing"
            why = (f"the {fitted.written} deg shiver the arm follows at {fa:g} Hz would make "
                   f"the file express `{found}`, not `{b.state.value}`, and a slower one "
                   f"than {min(ep.f, LOOK_SHIVER_F):g} Hz would read as slow rolls, not a "
                   "tremor")
            continue
        r = d.refusal
        records = [st.record(fitted.written, stmt, bound, r.joint, r.limit)]
        was = {"f": r.f, "for": r.duration}
        for k, v, u, desc in keys:
            w = was.get(k)
            records.append(records[0] | {
                "key": k, "declared": "" if w is None else f"{w:.3g}", "fitted": v,
                "unit": u, "bound": fa if k == "f" else float(v), "descriptor": desc})
        res.diagnostics = [offered(x, records) if x is d else x for x in res.diagnostics]
        return res
    return _refused(res, d, why)
