"""``aouc measure REC --against FILE.aou``: a recording judged against the behaviour it
should show (:mod:`aou_dsl.measuring.verdict`), as a table, JSON or GitHub annotations;
exit 1 when a descriptor is outside its tolerance, 3 when none is but the recording's noise
leaves one undecided (inconclusive), 0 when all pass."""

from __future__ import annotations

import argparse
import sys

from ..core.diagnostics import Diagnostic, Severity
from .args import EXIT_ERRORS, EXIT_INCONCLUSIVE, EXIT_OK, EXIT_USAGE, exit_for
from .report import about, cv_text, format_github, format_json, format_text

__all__ = ["cmd_measure_against", "format_verdict"]


def _v(v: float | int | None) -> str:
    return "absent" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v))


def _pm(r) -> str:
    """The measured value's 95 % interval about it, as ``aouc measure`` prints it
    (:func:`.report.about`; a count's as lo..hi)."""
    if r.measured is None or r.low is None or r.high is None:
        return "" if r.high is None else f"or {_v(r.high)}"  # copies that found it
    if isinstance(r.measured, int) and not isinstance(r.measured, bool):
        return "" if r.low == r.high else f"{r.low}..{r.high}"
    return about(r.measured, r.low, r.high)


_SHOWN = {"pass": "pass", "fail": "FAIL", "inconclusive": "INCONCLUSIVE"}


def format_verdict(verdict) -> str:
    """The table: each descriptor declared and measured with its 95 % interval, its
    tolerance, pass, FAIL or INCONCLUSIVE; the C-V point of each; how many pass."""
    lines = [f"{verdict.path} against {verdict.against} (robot {verdict.robot})"]
    if verdict.goal_from_file:
        lines.append("  (the recording has no goal: measured at the behaviour's)")
    lines.append(f"  {'descriptor':24s} {'declared':>10s} {'measured':>10s} {'95 %':>17s} "
                 f"{'tolerance':>11s}  {'unit':6s} result")
    for r in verdict.rows:
        tol = "-" if r.tolerance is None else (
            "exact" if r.tolerance == 0 else f"+-{r.tolerance:.3g}")
        lines.append(f"  {r.name:24s} {_v(r.declared):>10s} {_v(r.measured):>10s} "
                     f"{_pm(r):>17s} {tol:>11s}  {r.unit:6s} {_SHOWN[r.result]}")
    cv = verdict.declared_cv
    lines.append(f"  C-V declared: C={cv.C:+.2f} V={cv.V:+.2f} -> {cv.state.value}")
    lines.append(f"  C-V measured: {cv_text(verdict.measured)}")
    n = sum(r.ok for r in verdict.rows)
    undecided = len(verdict.inconclusive)
    lines.append(f"  {n} of {len(verdict.rows)} descriptors within tolerance"
                 + (f", {undecided} inconclusive" if undecided else ""))
    return "\n".join(lines)


def cmd_measure_against(args: argparse.Namespace, read) -> int:
    """Run ``aouc measure PATH --against FILE.aou`` (``read(path, args, **kw)`` reads
    PATH). A recording that names no robot (a bare CSV without ``--robot``) is read
    with the behaviour's."""
    from ..core.codes import I501
    from ..core.diagnostics import AouError
    from ..lang.linter import lint_file
    from ..measuring.verdict import judge

    lint = lint_file(args.against)
    if lint.behaviour is None:  # the behaviour is what the recording is judged by
        errors = [d for d in lint.diagnostics if d.severity == Severity.ERROR]
        _unread(args, errors or lint.diagnostics, {lint.path: lint.source or ""})
        # 2 when it could not be read at all, 1 for a file with errors (as `aouc lint`)
        return exit_for(errors)
    try:
        try:
            rec = read(args.path, args)
        except AouError as e:
            if args.robot or not any(d.code == I501 and "without its robot" in d.message
                                     for d in e.diagnostics):
                raise
            rec = read(args.path, args, robot=lint.behaviour.settings.robot)
        verdict = judge(rec, lint)  # its columns may not be the robot's joints (R402)
    except AouError as e:  # not a verdict: exit 2, as for a file that cannot be read
        return _unread(args, e.diagnostics, {})
    outside: list[Diagnostic] = verdict.outside() + verdict.undecided() \
        + verdict.undeclared()
    sources = {lint.path: lint.source or ""}
    if args.format == "json":
        print(format_json(verdict.to_json() | {
            "diagnostics": [d.to_json() for d in verdict.diagnostics + outside]}))
    elif args.format == "github":
        for d in verdict.diagnostics + outside:
            print(format_github(d))
    else:
        print(format_verdict(verdict))
        for d in verdict.diagnostics + outside:
            print(format_text(d, sources.get(d.span.path)), file=sys.stderr)
    if verdict.failed:
        return EXIT_ERRORS
    return EXIT_INCONCLUSIVE if verdict.inconclusive else EXIT_OK


def _unread(args: argparse.Namespace, diags: list[Diagnostic], sources: dict) -> int:
    """The diagnostics of a recording or behaviour that could not be read, in the
    requested format (a JSON document with no verdict, GitHub annotations, or text);
    exit 2, which no verdict gives."""
    if args.format == "json":
        print(format_json({"path": args.path, "against": args.against, "result": None,
                           "diagnostics": [d.to_json() for d in diags]}))
    elif args.format == "github":
        for d in diags:
            print(format_github(d))
    else:
        for d in diags:
            print(format_text(d, sources.get(d.span.path)), file=sys.stderr)
    return EXIT_USAGE
