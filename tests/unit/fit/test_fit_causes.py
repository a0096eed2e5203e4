"""A fit's refusal names its real cause: a fitted text the language refuses is said to
be refused by the language (its code and message), not to express another state, and a
reach value squeezed under the least the language takes is not said to be "not
followed" by the arm."""

from __future__ import annotations

from types import SimpleNamespace

from aou_dsl.core.codes import C301, C308
from aou_dsl.core.diagnostics import Severity, refused
from aou_dsl.fit import reach
from aou_dsl.fit.refusals import ShiverTooFast, Unreachable
from aou_dsl.fit.rounds import fit_loop
from aou_dsl.lang.linter import lint_source

SHIVER = "behaviour s : fearful\nrobot panda\napproach a=0.1\npause 1.25s x4\n" \
    "retreat 0.2m\nshiver 6deg f=2.5Hz\n"


def test_a_fitted_text_the_language_refuses_is_named_as_such():
    """A refusal whose fitted value the language does not take (a shiver made slower
    than the slowest shiver the language allows): the fit says which rule of the
    language, at which line, and never that the file would express `errors`."""
    lint = lint_source(SHIVER, "s.aou")
    assert lint.ok and lint.behaviour is not None
    node = next(p for p in lint.behaviour.primitives if p.kind == "shiver")
    too_fast = refused(C308, "too fast", node.span,
                       ShiverTooFast("j7", "acceleration", 0.5, None, 2.5))
    res = fit_loop(lint, lambda _: SimpleNamespace(diagnostics=[too_fast], header=None))
    said = [d.message for d in res.diagnostics if d.message.startswith("not fitted")]
    fitted = lint_source(SHIVER.replace("f=2.5Hz", "f=0.5Hz"), "s.aou")
    bad = next(d for d in fitted.diagnostics if d.severity is Severity.ERROR)
    assert said and "`errors`" not in said[0], said
    assert bad.code in said[0] and f"line {bad.span.line}" in said[0], said


RETREAT = "behaviour r\nrobot panda\napproach a=0.1\npause 1s x2\nretreat 6mm\n"


def test_a_reach_squeezed_under_the_least_retreat_is_named_as_such(monkeypatch):
    """The arm follows a retreat of 5.03 mm but not of 6 mm: the least change keeps
    90 % of the bound and more, 4.9 mm, under the 5 mm a retreat must move. The fit
    says the language refuses that value (V123), not that the arm does not follow it.
    (The bound's grid is narrowed to 10.04 mm, so that it has a point at 5.02 mm: on
    the default grid the bound of a length nearest the least is 7.8 mm.)"""
    fail = SimpleNamespace(joint="j4", status=SimpleNamespace(name="UNREACHABLE"))

    def reaches(tl):
        for i, ep in enumerate(tl.episodes):
            if ep.kind == "retreat" and ep.end.d - ep.start.d > 0.00503:
                return i, fail
        return None

    monkeypatch.setattr(reach, "_reach", lambda *_: reaches)
    monkeypatch.setitem(reach.SPAN, "length", 0.01004)
    lint = lint_source(RETREAT, "r.aou")
    assert lint.ok and lint.timeline is not None
    ep = next(e for e in lint.timeline.episodes if e.kind == "retreat")
    why = reach._fits(lint, refused(C301, "", ep.span, Unreachable("unreachable", 1.0, "j4")),
                      "panda", ())
    assert isinstance(why, str), why
    assert "V123" in why and "not followed" not in why, why
