"""``aouc lint`` as a library: source -> records of diagnostics, with the C-V judgement.

Nothing here imports a heavy dependency: linting a folder in CI starts fast.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from .cv import CANONICAL, DEFAULT_WEIGHTS, CVPoint, CVWeights, composition_of, effort_to_cv, infer
from .diagnostics import AouError, Diagnostic, Severity, Span, diag, has_errors
from .ir import Behaviour, State
from .parse import parse
from .validate import validate

__all__ = ["FileResult", "collect_files", "lint_file", "lint_paths", "lint_source", "load"]

#: MODEL.md s7: descriptors with no clear perceived effect, per state, and the statement
#: (primitive kind) that sets each.
NO_EFFECT: dict[State, tuple[tuple[str, str], ...]] = {
    State.CURIOUS: (("pause_duration", "pause"), ("tilt_velocity", "tilt")),
    State.HESITANT: (("tilt_angle", "tilt"), ("retreat_acceleration", "retreat")),
    State.FEARFUL: (("shiver_amplitude", "shiver"), ("retreat_acceleration", "retreat")),
}


@dataclass
class FileResult:
    """What lint found in one file. ``behaviour`` and ``cv`` are None when it has errors."""

    path: str
    diagnostics: list[Diagnostic] = field(default_factory=list)
    behaviour: Behaviour | None = None
    cv: CVPoint | None = None
    source: str | None = None

    @property
    def ok(self) -> bool:
        return not has_errors(self.diagnostics)

    def to_json(self) -> dict:
        b = self.behaviour
        return {
            "path": self.path,
            "behaviour": b.name if b else None,
            "state": b.state.value if b and b.state else None,
            "cv": self.cv.to_json() if self.cv else None,
            "diagnostics": [d.to_json() for d in self.diagnostics],
        }


def _model_checks(b: Behaviour, weights: CVWeights) -> tuple[CVPoint, list[Diagnostic]]:
    out: list[Diagnostic] = []
    point, contributions = infer(composition_of(b))
    inferred = point.state
    where = b.header_span or (b.primitives[0].span if b.primitives else b.span)
    if b.state is None:
        out.append(diag("M204", f"no state declared; the primitives express `{inferred}` "
                        f"(C={point.C:+.2f}, V={point.V:+.2f})", where,
                        inferred=inferred.value, C=point.C, V=point.V))
    elif inferred is not b.state:
        pulls = sorted(contributions, key=lambda c: -(abs(c.dC) + abs(c.dV)))
        pull_text = ", ".join(
            f"{c.primitive} ({'C' if c.dC else 'V'} {c.dC or c.dV:+.2f})" for c in pulls
        ) or "no primitives (C and V at their floor)"
        c0, v0 = CANONICAL[b.state]
        out.append(diag(
            "M201",
            f"declared `{b.state}` but the primitives express `{inferred}`: inferred "
            f"C={point.C:+.2f}, V={point.V:+.2f}; `{b.state}` sits at C={c0:+.0f}, V={v0:+.0f}",
            where,
            hint=f"pulling the point: {pull_text}; see `aouc rules M201` and docs/cv-model.md",
            declared=b.state.value, inferred=inferred.value, C=point.C, V=point.V,
        ))
    effort = b.settings.effort
    if effort is not None:
        ep = effort_to_cv(effort, weights)
        if b.state is not None and ep.state is not b.state:
            out.append(diag(
                "M202",
                f"the effort vector maps to C={ep.C:+.2f}, V={ep.V:+.2f}, nearest to "
                f"`{ep.state}`, not the declared `{b.state}`",
                effort.span, declared=b.state.value, effort_state=ep.state.value,
                C=ep.C, V=ep.V,
            ))
    state = b.state or inferred
    for descriptor, kind in NO_EFFECT.get(state, ()):
        for p in b.primitives:
            if p.kind == kind:
                out.append(diag(
                    "M203", f"the study found no clear perceived effect of {descriptor} on "
                    f"how {state} a motion looks (MODEL.md s7)", p.span,
                    descriptor=descriptor, state=state.value))
                break
    return point, out


def _realisable(b: Behaviour) -> list[Diagnostic]:
    """A descriptor-form file whose layout cannot show what it declares (V121): a gaze is
    measured at the pause that ends it, a retreat between two pauses, and two pauses
    with nothing moving between them are one pause."""
    from .compiler.layout import layout
    from .declared import declared_descriptors, timeline_descriptors

    if b.form != "descriptor":
        return []
    want = declared_descriptors(b)
    got = timeline_descriptors(layout(b).episodes)
    out = []
    for key, kind in (("pause_count", "pause"), ("retreat_count", "retreat")):
        if want[key] != got[key]:
            prim = b.first(kind)
            out.append(diag("V121", f"{want[key]} {kind}s are declared but the layout can "
                            f"only show {got[key]}", prim.span if prim else b.span,
                            hint="pauses need motion between them (an approach, a retreat, "
                            "a gaze...); each retreat and each gaze needs a pause after it",
                            declared=want[key], realised=got[key]))
    for plane in ("horizontal", "vertical"):
        key = f"{plane}_gaze"
        if want[key] is not None and got[key] is None:
            g = b.first("gaze", plane)
            out.append(diag("V121", f"the {plane} gaze is measured at the pause that ends it, "
                            "and no pause is left for it", g.span if g else b.span,
                            hint="add a pause per gaze episode (beyond those the retreats "
                            "need)"))
    return out


def load(text: str, path: str = "<string>") -> tuple[Behaviour | None, list[Diagnostic]]:
    """Parse and validate; the first two stages, without the model's judgement."""
    try:
        tree = parse(text, path)
    except AouError as err:
        return None, err.diagnostics
    return validate(tree)


def lint_source(text: str, path: str = "<string>", *,
                weights: CVWeights = DEFAULT_WEIGHTS) -> FileResult:
    """Lint ``.aou`` source text."""
    behaviour, diags = load(text, path)
    result = FileResult(path, list(diags), source=text)
    if behaviour is not None:
        result.diagnostics.extend(_realisable(behaviour))
    if behaviour is not None and not has_errors(result.diagnostics):
        point, model_diags = _model_checks(behaviour, weights)
        result.behaviour, result.cv = behaviour, point
        result.diagnostics.extend(model_diags)
    result.diagnostics.sort(key=lambda d: (d.span.line, d.span.col, d.code))
    return result


def read_source(path: str) -> str:
    """Read a source file as UTF-8, or raise an :class:`AouError` with an I501."""
    try:
        with open(path, encoding="utf-8") as fh:
            return fh.read()
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise AouError(diag("I501", f"cannot read `{path}`: {reason}",
                            Span.whole_file(path))) from None


def lint_file(path: str, *, weights: CVWeights = DEFAULT_WEIGHTS) -> FileResult:
    try:
        text = read_source(path)
    except AouError as err:
        return FileResult(path, err.diagnostics)
    return lint_source(text, path, weights=weights)


def collect_files(paths: list[str]) -> tuple[list[str], list[Diagnostic]]:
    """Expand folders recursively into their ``.aou`` files, sorted; report bad paths."""
    files: list[str] = []
    problems: list[Diagnostic] = []
    for p in paths:
        if os.path.isdir(p):
            found = sorted(str(f) for f in Path(p).rglob("*.aou") if f.is_file())
            if not found:
                problems.append(diag("I503", f"no `.aou` files in folder `{p}`",
                                     Span.whole_file(p)))
            files.extend(found)
        elif os.path.exists(p):
            files.append(p)
        else:
            problems.append(diag("I501", f"cannot read `{p}`: no such file or folder",
                                 Span.whole_file(p)))
    return files, problems


def lint_paths(paths: list[str], *, weights: CVWeights = DEFAULT_WEIGHTS
               ) -> tuple[list[FileResult], list[Diagnostic]]:
    """Lint files and folders. Returns per-file results and path problems (I5xx)."""
    files, problems = collect_files(paths)
    return [lint_file(f, weights=weights) for f in files], problems


def severity_counts(results: list[FileResult]) -> dict[Severity, int]:
    counts = dict.fromkeys(Severity, 0)
    for r in results:
        for d in r.diagnostics:
            counts[d.severity] += 1
    return counts
