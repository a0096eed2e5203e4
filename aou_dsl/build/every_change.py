"""A too-fast refusal's hint with every change it needs: in a ``sequence`` several shiver
(or tilt) statements may each be too fast for the arm, and the compiler stops at the
first. Its hint (``write `f=1.4Hz``\\ ``) is applied, the file compiled again, and the
next statement's edit added (``; and `f=1.2Hz` at line 9``) until none is refused: so
applying the hint compiles in one round. A file with one statement of that kind (every
descriptor-form file) is not compiled again.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from ..core.codes import C308, C309
from ..core.diagnostics import Diagnostic, Severity
from ..lang.linter import lint_source

__all__ = ["with_every_change"]

#: Statements more than this are not followed in one refusal.
MOST = 6
_KIND = {C308: "shiver", C309: "tilt"}


def _edit(d: Diagnostic) -> str | None:
    """The edit a too-fast refusal's hint writes (None: it has none)."""
    if d.code not in _KIND or d.severity is not Severity.ERROR or d.fix is None \
            or not (d.hint or "").startswith("write `"):
        return None
    return d.fix.text


def _next(text: str, path: str, robot: str, package_dirs: tuple[str, ...], code: str
          ) -> Diagnostic | None:
    """The refusal of ``code`` compiling ``text`` on ``robot`` (None: none)."""
    from ..compiler.pipeline import CompileOptions, compile_behaviour

    lint = lint_source(text, path)
    if not lint.ok or lint.behaviour is None:
        return None
    b = lint.behaviour
    b = b.replace(settings=b.settings.replace(robot=robot))
    res = compile_behaviour(b, CompileOptions(package_dirs=package_dirs), lint.timeline)
    return next((d for d in res.diagnostics if d.code == code and _edit(d)), None)


def with_every_change(res: Any, package_dirs: tuple[str, ...]) -> Any:
    """``res`` (a build result) with its too-fast refusal's hint extended by the edits
    of the same kind the other statements need (field ``also``: line, col, edit)."""
    from ..compiler.fitting import apply_edit

    lint, b = res.lint, res.lint.behaviour
    d = next((x for x in res.diagnostics if _edit(x)), None)
    if d is None or b is None or lint.source is None or d.span.path != lint.path or len(
            {p.span for p in b.primitives if p.kind == _KIND[d.code]}) < 2:
        return res
    text, at, edit = lint.source, d.span, _edit(d)
    also: list[dict[str, Any]] = []
    for _ in range(MOST):
        assert edit is not None
        text = apply_edit(text, at, edit)
        nxt = _next(text, lint.path, b.settings.robot, package_dirs, d.code)
        if nxt is None:
            break
        at, edit = nxt.span, _edit(nxt)
        if (at.line, at.col) == (d.span.line, d.span.col) or any(
                (a["line"], a["col"]) == (at.line, at.col) for a in also):
            return res  # the same statement again: no hint is sure to end it
        also.append({"line": at.line, "col": at.col, "end_col": at.end_col, "edit": edit})
    else:
        return res
    if not also:
        return res
    more = "; ".join(f"`{a['edit']}` in the {_KIND[d.code]} at line {a['line']}"
                     for a in also)
    res.diagnostics = [replace(x, hint=f"{x.hint}; and {more}", fields={
        **x.fields, "also": also}) if x is d else x for x in res.diagnostics]
    return res
