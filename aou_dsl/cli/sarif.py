"""Diagnostics as a SARIF 2.1.0 log, the format code-scanning dashboards read.

One run of one tool (``aou``) whose rules are every code of the rule registry, so a
dashboard can show any result's rule, and whose results are the diagnostics, each with
its code, level, message and region. Columns count Unicode code points, as aou's spans
do (``columnKind``), and a path is written as the relative URI reference it was given
(``%SRCROOT%``: the folder the command ran in) or, when absolute, as a ``file:`` URI.

The log is deterministic: no time, no machine, no absolute path that the user did not
give; the rules in the registry's order, the results in the order of the diagnostics.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import PurePosixPath, PureWindowsPath
from urllib.parse import quote

from ..core.diagnostics import Diagnostic
from ..core.rule_model import Rule, Severity
from ..core.rules import RULES
from ..version import __version__

__all__ = ["SARIF_SCHEMA", "SARIF_VERSION", "format_sarif", "sarif_log"]

SARIF_VERSION = "2.1.0"
#: The schema's identifier, as SARIF files name it (a name, never fetched by aou).
SARIF_SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"

#: aou's severities as SARIF levels.
LEVELS = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.NOTE: "note"}


def _rule(rule: Rule) -> dict:
    """One ``reportingDescriptor``: the code, its kebab-case name, the registry's text."""
    return {
        "id": rule.code,
        "name": rule.name,
        "shortDescription": {"text": rule.what},
        "fullDescription": {"text": f"{rule.what} {rule.why}"},
        "help": {"text": f"{rule.what}\n\nWhy: {rule.why}\n\nExample:\n{rule.example}",
                 "markdown": f"{rule.what}\n\n**Why:** {rule.why}\n\n**Example:**\n\n"
                             + "\n".join(f"    {ln}" for ln in rule.example.splitlines())},
        "defaultConfiguration": {"level": LEVELS[rule.severity]},
        "properties": {"category": rule.category.name.lower()},
    }


def _uri(path: str) -> tuple[str, str | None]:
    """A path as a URI reference and the base it is relative to (None: absolute)."""
    posix = path.replace("\\", "/") if PureWindowsPath(path).drive else path
    if PurePosixPath(posix).is_absolute():
        return "file://" + quote(posix), None
    return quote(posix), "%SRCROOT%"


def _location(d: Diagnostic) -> list[dict]:
    """Where ``d`` is: its file and region; none for a diagnostic of the command line."""
    span = d.span
    if not span.path or span.path.startswith("<"):  # <command line>, <stdin>
        return []
    uri, base = _uri(span.path)
    artifact: dict = {"uri": uri}
    if base:
        artifact["uriBaseId"] = base
    physical: dict = {"artifactLocation": artifact}
    if span.line >= 1:
        region = {"startLine": span.line, "startColumn": max(1, span.col)}
        end = (span.end_line, span.end_col)
        if end > (span.line, span.col):  # an empty span is a point: no end to give
            region["endLine"] = span.end_line
            region["endColumn"] = max(1, span.end_col)
        physical["region"] = region
    return [{"physicalLocation": physical}]


def _result(d: Diagnostic, index: dict[str, int]) -> dict:
    text = d.message + (f" (hint: {d.hint})" if d.hint else "")
    out: dict = {"ruleId": d.code, "level": LEVELS[Severity(d.severity)],
                 "message": {"text": text}}
    if d.code in index:
        out["ruleIndex"] = index[d.code]
    locations = _location(d)
    if locations:
        out["locations"] = locations
    return out


def sarif_log(diagnostics: Iterable[Diagnostic], *, successful: bool = True) -> dict:
    """The SARIF log of ``diagnostics``; ``successful``: whether the command could read
    and judge every input (False when an input could not be read: exit 2)."""
    rules = list(RULES.values())
    index = {r.code: i for i, r in enumerate(rules)}
    return {
        "$schema": SARIF_SCHEMA,
        "version": SARIF_VERSION,
        "runs": [{
            "tool": {"driver": {"name": "aou", "version": __version__,
                                "semanticVersion": __version__,
                                "rules": [_rule(r) for r in rules]}},
            "columnKind": "unicodeCodePoints",
            "originalUriBaseIds": {"%SRCROOT%": {
                "description": {"text": "the folder aouc ran in"}}},
            "invocations": [{"executionSuccessful": successful}],
            "results": [_result(d, index) for d in diagnostics],
        }],
    }


def format_sarif(diagnostics: Iterable[Diagnostic], *, successful: bool = True) -> str:
    """:func:`sarif_log` as text, the same bytes for the same diagnostics."""
    return json.dumps(sarif_log(diagnostics, successful=successful), indent=2,
                      ensure_ascii=False) + "\n"
