"""``--fit`` and ``--write-fitted`` of ``aouc compile`` and ``aouc check``: the fitted
file written (atomically, never over an input), and ``check`` of a fitted behaviour.

``--write-fitted PATH`` obeys the output rule of ``-o``
(:func:`aou_dsl.core.files.guard_output`), checked before any work: never one of the
files the command reads (the ``.aou`` file, its robot file, the URDF, the meshes), a
link to one, a special file, nor the file ``-o`` writes."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from ..core.diagnostics import AouError, Severity
from .args import EXIT_ERRORS, EXIT_OK, EXIT_USAGE, usage_error
from .report import format_check, format_json, format_text

__all__ = ["check_fitted", "check_fitted_output", "fitted_usage", "original_text",
           "write_fitted"]


def original_text(res) -> dict[str, str]:
    """The file's own text, by path, when ``res`` (a build) was fitted: its messages
    quote the fitted text, and say where it differs from the file's."""
    from ..core.files import read_text

    if getattr(res, "fitted_source", None) is None:
        return {}
    try:
        return {res.path: read_text(res.path)}
    except AouError:
        return {}


def check_fitted_output(path: str, reads: Sequence[str], outputs: Sequence[str] = ()) -> None:
    """Refuse, before any work, a ``--write-fitted`` path that breaks the output rule
    against ``reads``, or that is (or links to) one of the command's ``outputs``.

    Raises:
        AouError: I502 naming the clash (the codes of
            :func:`aou_dsl.core.files.check_output`).
    """
    from ..core.files import apart_from, check_output

    check_output(path, reads=reads)
    apart_from(path, outputs, "the fitted text", "--write-fitted")


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
    from ..core.options import BuildOptions
    from ..driver.builder import build_file
    from ..robot.files_read import files_read

    if not args.path.endswith(".aou") or (args.write_fitted and not args.fit):
        return fitted_usage("check")
    reads = files_read([args.path], read_kw["robot"], read_kw["package_dirs"])
    if args.write_fitted:
        try:
            check_fitted_output(args.write_fitted, reads)
        except AouError as err:
            for d in err.diagnostics:
                print(format_text(d), file=sys.stderr)
            return EXIT_USAGE
    res = build_file(args.path, BuildOptions(
        robot=read_kw["robot"], package_dirs=read_kw["package_dirs"], check=False, fit=True))
    original = original_text(res).get(res.path)
    for d in res.diagnostics:
        print(format_text(d, res.lint.source if d.span.path == res.path else None,
                          original), file=sys.stderr)
    if not res.ok:
        return EXIT_ERRORS
    if args.write_fitted:
        code = write_fitted(args.write_fitted, res, reads)
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
            more, tracking = run_tracking(
                args, tr, lint, reads=[args.path],
                out=None if args.format == "json" else sys.stdout,
                written=lint_source(original, args.path) if original is not None else None,
                fitted=tuple((res.header or {}).get("fitted") or ()))
        except AouError as err:
            more = list(err.diagnostics)
        for d in more:
            print(format_text(d, lint.source if d.span.path == lint.path else None),
                  file=sys.stderr)
        bad = any(d.severity is Severity.ERROR for d in [*res.diagnostics, *more])
        if args.format == "json":  # the diagnostics too, as check without --fit gives them
            print(format_json({"path": args.path, **report.to_json(), "tracking": tracking,
                               "diagnostics": [d.to_json() for d in
                                               [*res.diagnostics, *more]]}))
        return EXIT_OK if report.ok and not bad else EXIT_ERRORS
    if args.format == "json":
        print(format_json({"path": args.path, **report.to_json()}))
    else:
        print(format_check(args.path, tr.robot, tr.t, report))
    bad = any(d.severity is Severity.ERROR for d in res.diagnostics)
    return EXIT_OK if report.ok and not bad else EXIT_ERRORS
