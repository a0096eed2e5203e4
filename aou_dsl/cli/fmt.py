"""``aouc fmt``: the formatter (:mod:`aou_dsl.lang.formatter`) over files and folders."""

from __future__ import annotations

import argparse
import sys

from ..core.diagnostics import AouError
from ..core.rules import category
from ..lang.formatter import diff, format_file, write_in_place

__all__ = ["cmd_fmt"]


def cmd_fmt(args: argparse.Namespace) -> int:
    """``aouc fmt PATH... [--check] [--diff]``: 0 nothing to do or all formatted, 1 a file
    has syntax errors or (with ``--check``/``--diff``) would change, 2 I/O problems."""
    from ..lang.linter import collect_files
    from .report import print_diagnostics as _print_diags

    files, problems = collect_files(args.paths)
    _print_diags(problems)
    results = [format_file(f) for f in files]
    changed = [r for r in results if r.changed]
    failed = [r for r in results if r.diagnostics]
    for r in failed:
        _print_diags(r.diagnostics, sources={r.path: r.source or ""})
    io_error = bool(problems) or any(category(d.code).is_usage for r in failed
                                     for d in r.diagnostics)
    dry = args.check or args.diff
    for r in changed:
        if args.diff:
            sys.stdout.write(diff(r))
        elif args.check:
            print(f"would reformat {r.path}")
        else:
            try:
                write_in_place(r.path, r.formatted or "")
            except AouError as err:
                _print_diags(err.diagnostics)
                io_error = True
    verb = "would be reformatted" if dry else "reformatted"
    print(f"{len(changed)} file{'s' * (len(changed) != 1)} {verb}, "
          f"{len(results) - len(changed) - len(failed)} unchanged"
          + (f", {len(failed)} not formatted (errors)" if failed else ""), file=sys.stderr)
    if io_error:
        return 2
    return 1 if failed or (dry and changed) else 0
