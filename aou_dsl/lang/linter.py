"""``aouc lint`` as a library: source -> records of diagnostics, with the C-V judgement.

Nothing here imports a heavy dependency: linting a folder in CI starts fast.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..core.codes import I501, I503, M201, M202, M203, M204
from ..core.diagnostics import AouError, Diagnostic, Severity, Span, diag, has_errors
from ..core.inputs import read_input_text
from ..core.rules import Category, category
from .cv import CANONICAL, DEFAULT_WEIGHTS, CVPoint, CVWeights, composition, effort_to_cv, infer
from .descriptors import descriptor_problems, every_descriptor
from .ir import Behaviour
from .layout import episode_values, nominal_values
from .parse import SequenceBlock, parse
from .primitives import plugin_problems
from .timeline import Timeline
from .validate import Validated, validate_tree

__all__ = ["MAX_DIAGNOSTICS", "FileResult", "collect_files", "collect_inputs", "judge",
           "lint_file", "lint_paths", "lint_source", "load", "read_source", "severity_counts"]


#: At most this many diagnostics are kept per file (the most severe, earliest first);
#: the others are only counted (:attr:`FileResult.suppressed`).
MAX_DIAGNOSTICS = 100

_RANK = {Severity.ERROR: 0, Severity.WARNING: 1, Severity.NOTE: 2}


@dataclass
class FileResult:
    """What lint found in one file. ``behaviour`` and ``cv`` are None when it has errors.

    ``suppressed`` counts, per severity, the diagnostics beyond :data:`MAX_DIAGNOSTICS`
    that were found but not kept."""

    path: str
    diagnostics: list[Diagnostic] = field(default_factory=list)
    behaviour: Behaviour | None = None
    cv: CVPoint | None = None
    source: str | None = None
    timeline: Timeline | None = None
    suppressed: dict[Severity, int] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return not has_errors(self.diagnostics) and not self.suppressed.get(Severity.ERROR)

    def to_json(self) -> dict:
        b = self.behaviour
        out = {
            "path": self.path,
            "behaviour": b.name if b else None,
            "state": b.state.value if b and b.state else None,
            "cv": self.cv.to_json() if self.cv else None,
            "diagnostics": [d.to_json() for d in self.diagnostics],
        }
        if any(self.suppressed.values()):  # only a file past the cap says so
            out["suppressed"] = {str(k): v for k, v in self.suppressed.items() if v}
        return out


def _cap(result: FileResult) -> None:
    """Keep the :data:`MAX_DIAGNOSTICS` most severe diagnostics (earliest first among
    equals), in file order; count the rest by severity."""
    diags = result.diagnostics
    if len(diags) > MAX_DIAGNOSTICS:
        ranked = sorted(diags, key=lambda d: (_RANK[d.severity], d.span.line, d.span.col,
                                              d.code))
        for d in ranked[MAX_DIAGNOSTICS:]:
            result.suppressed[d.severity] = result.suppressed.get(d.severity, 0) + 1
        diags = ranked[:MAX_DIAGNOSTICS]
    result.diagnostics = sorted(diags, key=lambda d: (d.span.line, d.span.col, d.code))


def behaviour_cv(b: Behaviour, timeline: Timeline | None) -> tuple[CVPoint, list]:
    """The C-V point a behaviour expresses, from what its episodes do (a sequence's
    negative approach is a retreat), and each evidence channel's pull."""
    values = episode_values(timeline.episodes) if b.form == "sequence" and timeline \
        else nominal_values(b)
    return infer(composition(values))


def _model_checks(b: Behaviour, timeline: Timeline | None, weights: CVWeights
                  ) -> tuple[CVPoint, list[Diagnostic]]:
    out: list[Diagnostic] = []
    point, contributions = behaviour_cv(b, timeline)
    inferred = point.state
    where = b.header_span or (b.primitives[0].span if b.primitives else b.span)
    if b.state is None:
        out.append(diag(M204, f"no state declared; the primitives express `{inferred}` "
                        f"(C={point.C:+.2f}, V={point.V:+.2f})", where,
                        inferred=inferred.value, C=point.C, V=point.V))
    elif inferred is not b.state:
        pulls = sorted(contributions, key=lambda c: -(abs(c.dC) + abs(c.dV)))
        pull_text = ", ".join(
            f"{c.primitive} ({'C' if c.dC else 'V'} {c.dC or c.dV:+.2f})" for c in pulls
        ) or "no primitives (C and V at their floor)"
        c0, v0 = CANONICAL[b.state]
        out.append(diag(
            M201,
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
                M202,
                f"the effort vector maps to C={ep.C:+.2f}, V={ep.V:+.2f}, nearest to "
                f"`{ep.state}`, not the declared `{b.state}`",
                effort.span, declared=b.state.value, effort_state=ep.state.value,
                C=ep.C, V=ep.V,
            ))
    state = b.state or inferred
    kinds = {p.kind for p in b.primitives if p.count}
    for name, d in every_descriptor().items():
        if state in d.no_effect and d.kind in kinds:
            p = next(p for p in b.primitives if p.kind == d.kind)
            out.append(diag(M203, f"the study found no clear perceived effect of {name} on "
                            f"how {state} a motion looks", p.span, descriptor=name,
                            state=state.value))
    return point, out


def load_validated(text: str, path: str = "<string>") -> Validated:
    """Parse and validate: the front end, without the model's judgement."""
    try:
        tree = parse(text, path)
    except AouError as err:
        return Validated(None, None, err.diagnostics)
    return validate_tree(tree)


def load(text: str, path: str = "<string>") -> tuple[Behaviour | None, list[Diagnostic]]:
    """Parse and validate; the behaviour (None on errors) and the diagnostics."""
    v = load_validated(text, path)
    return v.behaviour, v.diagnostics


def lint_source(text: str, path: str = "<string>", *,
                weights: CVWeights = DEFAULT_WEIGHTS) -> FileResult:
    """Lint ``.aou`` source text (a leading byte-order mark is not part of it)."""
    text = text.removeprefix("\ufeff")
    return judge(text, path, load_validated(text, path), weights)


def judge(text: str, path: str, v: Validated, weights: CVWeights = DEFAULT_WEIGHTS
          ) -> FileResult:
    """The lint of ``text`` (no byte-order mark) from its validation ``v``: the model's
    judgement added, the diagnostics capped and in file order."""
    result = FileResult(path, list(v.diagnostics), source=text)
    result.diagnostics += plugin_warnings(text, path)
    b = v.behaviour
    if b is not None and not has_errors(result.diagnostics):
        point, model_diags = _model_checks(b, v.timeline, weights)
        result.behaviour, result.cv, result.timeline = b, point, v.timeline
        result.diagnostics.extend(model_diags)
    _cap(result)
    return result


def plugin_warnings(text: str, path: str) -> list[Diagnostic]:
    """K801 and K803 for the plugins that cannot be used as they are (one did not load,
    gives something malformed, or takes a name already taken), each said once at the
    first statement of ``text`` that uses the plugin's keyword: a file that does not
    use it is not told about it."""
    problems = (*plugin_problems(), *descriptor_problems())
    if not problems:
        return []
    try:
        tree = parse(text, path)
    except AouError:  # the syntax error is said already
        return []
    first: dict[str, Span] = {}
    for item in tree.items:
        for st in item.statements if isinstance(item, SequenceBlock) else (item,):
            first.setdefault(st.keyword, st.keyword_span)
    out, said = [], set()
    for p in problems:
        if p.name in first and (p.code, p.name, p.why) not in said:
            said.add((p.code, p.name, p.why))
            out.append(diag(p.code, p.message(), first[p.name], plugin=p.name,
                            source=p.source))
    return out


def read_source(path: str) -> str:
    """Read a source file as UTF-8 (a leading byte-order mark dropped), or raise an
    :class:`AouError` with an I501."""
    return read_input_text(path, "behaviour")


#: Extensions of the trajectories aou writes and reads: given where a behaviour is
#: expected, the file is almost surely one of them.
TRAJECTORY_EXTENSIONS = (".json", ".csv", ".npz", ".yaml", ".mcap")


def lint_file(path: str, *, weights: CVWeights = DEFAULT_WEIGHTS) -> FileResult:
    try:
        text = read_source(path)
    except AouError as err:
        result = FileResult(path, err.diagnostics)
    else:
        result = lint_source(text, path, weights=weights)
    first = result.diagnostics[0] if result.diagnostics else None
    unread = first is not None and category(first.code) in (Category.SYNTAX, Category.USAGE)
    if first and unread and path.lower().endswith(TRAJECTORY_EXTENSIONS):
        result.diagnostics[0] = replace(first, hint=(
            "this looks like a trajectory, not a behaviour: `aouc measure`, `check` and "
            "`plot` read trajectories; `lint` and `compile` read `.aou` files"))
    return result


def collect_inputs(paths: list[str]) -> tuple[list[tuple[str, str | None]], list[Diagnostic]]:
    """Expand folders recursively into their ``.aou`` files, sorted; report bad paths.
    Each file comes with the folder it was found in (None when named directly)."""
    files: list[tuple[str, str | None]] = []
    problems: list[Diagnostic] = []
    for p in paths:
        if os.path.isdir(p):
            found = sorted(str(f) for f in Path(p).rglob("*.aou") if f.is_file())
            if not found:
                problems.append(diag(I503, f"no `.aou` files in folder `{p}`",
                                     Span.whole_file(p)))
            files.extend((f, p) for f in found)
        elif os.path.exists(p):
            files.append((p, None))
        else:
            problems.append(diag(I501, f"cannot read `{p}`: no such file or folder",
                                 Span.whole_file(p)))
    return files, problems


def collect_files(paths: list[str]) -> tuple[list[str], list[Diagnostic]]:
    """:func:`collect_inputs` without the folders."""
    files, problems = collect_inputs(paths)
    return [f for f, _ in files], problems


def lint_paths(paths: list[str], *, weights: CVWeights = DEFAULT_WEIGHTS
               ) -> tuple[list[FileResult], list[Diagnostic]]:
    """Lint files and folders. Returns per-file results and path problems (I5xx)."""
    files, problems = collect_files(paths)
    return [lint_file(f, weights=weights) for f in files], problems


def severity_counts(results: list[FileResult]) -> dict[Severity, int]:
    """Diagnostics per severity over all files, those not kept included."""
    counts = dict.fromkeys(Severity, 0)
    for r in results:
        for d in r.diagnostics:
            counts[d.severity] += 1
        for sev, n in r.suppressed.items():
            counts[sev] += n
    return counts
