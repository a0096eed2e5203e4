"""``--fit`` and ``--write-fitted`` of ``aouc compile`` and ``aouc check``: the fitted
file written (atomically, never over an input), and ``check`` of a fitted behaviour."""

from __future__ import annotations

import argparse
import sys

from ..core.diagnostics import AouError, Severity
from .args import EXIT_ERRORS, EXIT_OK, EXIT_USAGE, usage_error
from .report import format_check, format_json, format_text

__all__ = ["check_fitted", "fitted_usage", "write_fitted"]


def fitted_usage(command: str) -> int:
    return usage_error(command, "--write-fitted needs --fit and one .aou input")


def write_fitted(path: str, res, inputs: list[str]) -> int:
    """Write the fitted text of ``res`` at ``path`` (the file as it was when nothing was
    fitted); 2 when it cannot be written."""
    from ..core.files import write_atomic

    text = res.fitted_source if res.fitted_source is not None else res.lint.source
    if text is None:
        return EXIT_OK
    try:
        write_atomic(path, text.encode(), inputs=inputs)
    except AouError as err:
        for d in err.diagnostics:
            print(format_text(d), file=sys.stderr)
        return EXIT_USAGE
    what = "fitted" if res.fitted_source is not None else "unchanged: nothing to fit"
    print(f"{res.path} -> {path} ({what})", file=sys.stderr)
    return EXIT_OK


def check_fitted(args: argparse.Namespace, read_kw: dict) -> int:
    """``aouc check FILE.aou --fit``: the behaviour fitted to the arm, then replayed."""
    from ..api import check
    from ..build.builder import build_file
    from ..core.options import BuildOptions

    if not args.path.endswith(".aou") or (args.write_fitted and not args.fit):
        return fitted_usage("check")
    res = build_file(args.path, BuildOptions(
        robot=read_kw["robot"], package_dirs=read_kw["package_dirs"], check=False, fit=True))
    for d in res.diagnostics:
        print(format_text(d, res.lint.source), file=sys.stderr)
    if not res.ok:
        return EXIT_ERRORS
    if args.write_fitted:
        code = write_fitted(args.write_fitted, res, [args.path])
        if code != EXIT_OK:
            return code
    tr = res.trajectory.with_(path=args.path)
    report = check(tr, dynamic=not args.no_dynamic, controller=args.controller,
                   target_size=args.target_size,
                   table_height=None if args.no_table else args.table_height)
    tracking = None
    if getattr(args, "track", False):  # judged against the fitted text
        from ..lang.linter import lint_source
        from .track_cmd import run_tracking

        lint = (lint_source(res.fitted_source, args.path) if res.fitted_source is not None
                else res.lint)
        if args.format != "json":
            print(format_check(args.path, tr.robot, tr.t, report))
        try:
            more, tracking = run_tracking(args, tr, lint, reads=[args.path],
                                          out=None if args.format == "json" else sys.stdout)
        except AouError as err:
            more = list(err.diagnostics)
        for d in more:
            print(format_text(d, lint.source if d.span.path == lint.path else None),
                  file=sys.stderr)
        bad = any(d.severity is Severity.ERROR for d in [*res.diagnostics, *more])
        if args.format == "json":
            print(format_json({"path": args.path, **report.to_json(), "tracking": tracking}))
        return EXIT_OK if report.ok and not bad else EXIT_ERRORS
    if args.format == "json":
        print(format_json({"path": args.path, **report.to_json()}))
    else:
        print(format_check(args.path, tr.robot, tr.t, report))
    bad = any(d.severity is Severity.ERROR for d in res.diagnostics)
    return EXIT_OK if report.ok and not bad else EXIT_ERRORS
