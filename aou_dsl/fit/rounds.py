"""``--fit``: build, and where the arm cannot give a declared value, change it by the
rule of :mod:`aou_dsl.fit.plan` and build again, until nothing is left to fit.

Each change is a C314 warning at its statement ("declared -> fitted", the joint and the
limit that bind); the fitted file's text is kept (``fitted_source``, written by
``--write-fitted``) and the document lists the changes (``fitted``). A fit that would
make the file express another state than the one it declares is not made: the build
stays refused, and a C314 says why. Nor is one that would make an episode look like
another kind than it declares (each kind's invariant,
:meth:`~aou_dsl.lang.primitives.Kind.keeps_look`: a shiver slower than a tremor, a tilt
faster than declared, a retreat too short to see): C315 says why, as it does for a
shiver no frequency and no visible amplitude fits (:mod:`~aou_dsl.fit.amplitude`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from ..core.codes import C314, C315
from ..core.diagnostics import Diagnostic, diag
from ..core.repeats import said_once
from ..lang.linter import FileResult
from ..lang.primitives import look_changed
from .guard import guarded, refusal
from .plan import FITTED, Kinds, fixed, plan
from .refusals import answer_of
from .text_edits import Change, apply

__all__ = ["MAX_ROUNDS", "fit_loop"]

#: Builds at most, the first included.
MAX_ROUNDS = 5


def _binds(c: Change) -> str:
    """What binds, in words: a joint's limit, the arm's reach or a singularity."""
    if c.limit in ("reach", "singularity"):
        return f"the arm's {c.limit}" + (f" ({c.joint})" if c.joint else "")
    return f"{c.joint}'s {c.limit or 'acceleration'} limit" if c.joint else "the arm"


def _warning(c: Change) -> Diagnostic:
    what = c.descriptor or {"f": "shiver frequency", "for": "shiver duration",
                            "a": "acceleration", "v": "tilt velocity",
                            "length": "approach distance", "angle": "angle"}[c.key]
    was = f"{c.declared}{c.unit}" if c.declared else "the default"
    binds = _binds(c)
    return diag(C314, f"{what}: declared {was} -> fitted {c.fitted}{c.unit} "
                f"(`{c.text}`): {binds} binds", c.span, key=c.key, declared=c.declared,
                fitted=c.fitted, unit=c.unit, joint=c.joint, limit=c.limit,
                descriptor=c.descriptor)


def _not_fitted(todo: list[Diagnostic], where: Any) -> list[Diagnostic]:
    """C314 for each reach refusal no change answers, with why
    (:mod:`~aou_dsl.fit.reach`)."""
    return [diag(C314, f"not fitted: {answer_of(d).not_offered}", d.span)
            for d in todo if answer_of(d).not_offered] + [
        diag(C315, f"not fitted: no shiver the arm follows keeps the look: "
             f"{answer_of(d).look}", d.span, hint="a wider or faster shiver needs a "
             "stronger wrist (a robot description's `joint_accel`, if the arm allows "
             "more); else leave the shiver out on this arm", look=answer_of(d).look)
        for d in todo if answer_of(d).look]


def _kinds(lint: FileResult) -> Kinds:
    """The kind of each statement of ``lint``, by its ``(line, col)``."""
    eps = lint.timeline.episodes if lint.timeline is not None else ()
    return {(ep.span.line, ep.span.col): ep.kind for ep in eps}


def fit_loop(lint: FileResult, build: Callable[[FileResult], Any]) -> Any:
    """``build(lint)``, then rounds of :func:`~aou_dsl.fit.plan.plan` and
    ``build`` of the changed text (at most :data:`MAX_ROUNDS` builds). A value the
    language fixes (a gaze's acceleration) is never changed: a C314 says why
    (:func:`~aou_dsl.fit.plan.fixed`)."""
    last = [lint]  # the lint of the last build
    res = _rounds(lint, build, last)
    todo = [d for d in said_once(res.diagnostics) if d.code in FITTED]
    res.diagnostics += fixed(todo, _kinds(last[-1]))
    return guarded(res)


def _rounds(lint: FileResult, build: Callable[[FileResult], Any],
            last: list[FileResult]) -> Any:
    res = build(lint)
    text, b = lint.source, lint.behaviour
    if text is None or b is None:
        return res
    state = b.state
    first: dict[tuple, float] = {}
    made: dict[tuple, Change] = {}
    for _ in range(MAX_ROUNDS - 1):
        todo = [d for d in said_once(res.diagnostics) if d.code in FITTED]
        changes = plan(todo, first, _kinds(last[-1]))
        if not changes:
            res.diagnostics += _not_fitted(todo, b.span)
            break
        new_text = apply(text, changes)
        new_lint, bad = refusal(new_text, lint.path)  # never a text the language refuses
        if bad is not None:
            res.diagnostics.append(diag(
                C314, f"not fitted: the changes ({', '.join(c.text for c in changes)}) "
                f"are values the language does not take: {bad}", b.span))
            return res
        if (state is not None and (
                new_lint.cv is None or new_lint.cv.state != state)):
            found = new_lint.cv.state.value if new_lint.cv is not None else "nothing"
            res.diagnostics.append(diag(
                C314, f"not fitted: the changes ({', '.join(c.text for c in changes)}) "
                f"would make the file express `{found}`, not "
                f"`{state.value if state else 'what it does'}`", b.span))
            return res
        why = None if lint.timeline is None or new_lint.timeline is None else \
            look_changed(lint.timeline.episodes, new_lint.timeline.episodes)
        if why is not None:
            res.diagnostics.append(diag(
                C315, f"not fitted: the changes ({', '.join(c.text for c in changes)}) "
                f"would change the kind of motion a person sees: {why}", b.span, look=why))
            return res
        for c in changes:
            key = (c.span.line, c.span.col, c.key)
            try:
                first.setdefault(key, float(c.declared))
            except ValueError:
                first.setdefault(key, math.nan)
            made[key] = replace(c, declared=made[key].declared) if key in made else c
        last.append(new_lint)
        text, res = new_text, build(new_lint)
    if made:
        res.diagnostics += [_warning(c) for c in made.values()]
        res.fitted_source = text
        if res.header is not None:
            res.header = res.header | {"fitted": [
                {"line": c.span.line, "key": c.key, "declared": c.declared,
                 "fitted": c.fitted, "unit": c.unit, "joint": c.joint, "limit": c.limit,
                 "descriptor": c.descriptor} for c in made.values()]}
    return res
