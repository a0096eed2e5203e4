"""``aouc lint``: the files' diagnostics as text, JSON, GitHub annotations or SARIF."""

from __future__ import annotations

import argparse
import sys

from ..core.diagnostics import Severity
from ..core.rules import category
from .args import EXIT_ERRORS, EXIT_OK, EXIT_USAGE
from .report import format_json, format_suppressed
from .report import print_diagnostics as _print_diags

__all__ = ["cmd_lint", "count"]


def count(n: int, noun: str) -> str:
    """``1 error``, ``2 errors``."""
    return f"{n} {noun}{'s' * (n != 1)}"


def cmd_lint(args: argparse.Namespace) -> int:
    from ..lang.linter import lint_paths, severity_counts

    results, problems = lint_paths(args.paths)
    counts = severity_counts(results)
    io_errors = bool(problems) or any(category(d.code).is_usage
                                      for r in results for d in r.diagnostics)
    if args.format == "json":
        print(format_json({"files": [r.to_json() for r in results],
                           "problems": [d.to_json() for d in problems],
                           "summary": {str(k): v for k, v in counts.items()}}))
    elif args.format == "sarif":
        from .sarif import format_sarif

        sys.stdout.write(format_sarif([*problems, *(d for r in results for d in r.diagnostics)],
                                      successful=not io_errors))
    else:
        _print_diags(problems, args.format)
        for r in results:
            _print_diags(r.diagnostics, args.format, {r.path: r.source or ""}, sys.stdout)
            note = format_suppressed(r.path, r.suppressed)
            if note:
                print(note)
        if args.format == "text":
            print(f"{count(len(results), 'file')} checked: "
                  f"{count(counts[Severity.ERROR], 'error')}, "
                  f"{count(counts[Severity.WARNING], 'warning')}, "
                  f"{count(counts[Severity.NOTE], 'note')}", file=sys.stderr)
    if io_errors:
        return EXIT_USAGE
    if counts[Severity.ERROR] or (args.strict and counts[Severity.WARNING]):
        return EXIT_ERRORS
    return EXIT_OK
