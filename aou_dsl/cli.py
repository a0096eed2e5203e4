"""``aouc``: the command line. Thin: each command calls the library and formats records.

Exit codes (LANGUAGE.md): 0 no error, 1 the input has errors (or warnings under
``--strict``), 2 usage or I/O problems. A 2 is never hidden by a flag.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from . import __version__
from .diagnostics import RULES, Diagnostic, Severity
from .report import format_github, format_json, format_text

__all__ = ["EXIT_ERRORS", "EXIT_OK", "EXIT_USAGE", "main"]

EXIT_OK = 0
EXIT_ERRORS = 1
EXIT_USAGE = 2


class _Parser(argparse.ArgumentParser):
    """argparse exits 2 on usage errors, as the contract wants; keep its message short."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        sys.stderr.write(f"aouc: error: {message}\n")
        raise SystemExit(EXIT_USAGE)


def _print_diags(diags: list[Diagnostic], fmt: str, sources: dict[str, str] | None = None,
                 stream=None) -> None:
    stream = stream or sys.stdout
    for d in diags:
        if fmt == "github":
            print(format_github(d), file=stream)
        else:
            print(format_text(d, (sources or {}).get(d.span.path)), file=stream)


# --- lint -------------------------------------------------------------------------------


def _cmd_lint(args: argparse.Namespace) -> int:
    from .lint import lint_paths, severity_counts

    results, problems = lint_paths(args.paths)
    counts = severity_counts(results)
    io_errors = bool(problems) or any(
        d.code.startswith("I") for r in results for d in r.diagnostics)
    if args.format == "json":
        print(format_json({
            "files": [r.to_json() for r in results],
            "problems": [d.to_json() for d in problems],
            "summary": {str(k): v for k, v in counts.items()},
        }))
    else:
        _print_diags(problems, args.format, stream=sys.stderr)
        for r in results:
            _print_diags(r.diagnostics, args.format, {r.path: r.source or ""})
        if args.format == "text":
            n = len(results)
            print(f"{n} file{'s' * (n != 1)} checked: {counts[Severity.ERROR]} errors, "
                  f"{counts[Severity.WARNING]} warnings, {counts[Severity.NOTE]} notes",
                  file=sys.stderr)
    if io_errors:
        return EXIT_USAGE
    if counts[Severity.ERROR] or (args.strict and counts[Severity.WARNING]):
        return EXIT_ERRORS
    return EXIT_OK


# --- rules ------------------------------------------------------------------------------


def _cmd_rules(args: argparse.Namespace) -> int:
    wanted = [c.upper() for c in args.codes]
    unknown = [c for c in wanted if c not in RULES]
    if unknown:
        print(f"aouc: unknown rule code(s): {', '.join(unknown)}; `aouc rules` lists them",
              file=sys.stderr)
        return EXIT_USAGE
    rules = [RULES[c] for c in wanted] if wanted else list(RULES.values())
    if args.format == "json":
        print(format_json([{"code": r.code, "name": r.name, "severity": str(r.severity),
                            "what": r.what, "why": r.why, "example": r.example}
                           for r in rules]))
        return EXIT_OK
    for r in rules:
        if wanted:
            print(f"{r.code} {r.name} [{r.severity}]\n  what: {r.what}\n  why: {r.why}\n"
                  f"  example:\n" + "\n".join(f"    {ln}" for ln in r.example.splitlines()))
        else:
            print(f"{r.code}  {r.name:<28} {r.severity:<8} {r.what}")
    return EXIT_OK


# --- the parser -------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="aouc", description="aou: expressive robot-arm motion from .aou files.")
    p.add_argument("--version", action="version", version=f"aouc {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    lint = sub.add_parser("lint", help="check .aou files against the language and the C-V model")
    lint.add_argument("paths", nargs="+", metavar="PATH", help=".aou files or folders")
    lint.add_argument("--format", choices=("text", "json", "github"), default="text")
    lint.add_argument("--strict", action="store_true", help="warnings fail too (exit 1)")
    lint.set_defaults(func=_cmd_lint)

    rules = sub.add_parser("rules", help="list the diagnostic codes, or explain some")
    rules.add_argument("codes", nargs="*", metavar="CODE")
    rules.add_argument("--format", choices=("text", "json"), default="text")
    rules.set_defaults(func=_cmd_rules)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    try:
        return args.func(args)
    except KeyboardInterrupt:
        print("aouc: interrupted", file=sys.stderr)
        return EXIT_USAGE
    except BrokenPipeError:
        return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
