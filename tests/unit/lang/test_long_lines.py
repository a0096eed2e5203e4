"""A long line lints in time linear in its length: checked on the work done, not on a
clock (the figures are the benchmark's).

- Parsing again after an edit parses each statement of a line alone; the text handed
  to the parser adds up to no more than the line (it was padded with the whole line
  before each statement, so a line of n statements cost n^2).
- A statement of many arguments is read with a number of Python calls that grows as
  the arguments do (each left-over one was searched for among all)."""

from __future__ import annotations

import sys

from aou_dsl.lang import pieces
from aou_dsl.lang.linter import lint_source
from aou_dsl.lang.relint import Relinter


def test_the_parser_is_handed_each_statement_once_without_padding(monkeypatch):
    handed: list[int] = []
    parse = pieces.parse_statement

    def counted(text: str, path: str):
        handed.append(len(text))
        return parse(text, path)

    monkeypatch.setattr(pieces, "parse_statement", counted)
    text = "pause 1s x0; tilt 20deg x0; " * 400 + "pause 3m\n"
    res = Relinter().lint(text, "x.aou")
    assert len(handed) >= 800 and sum(handed) <= len(text)
    # and the spans are where the whole file's parse puts them
    assert [(d.code, d.span) for d in res.diagnostics] == \
        [(d.code, d.span) for d in lint_source(text, "x.aou").diagnostics]


def _calls(text: str) -> int:
    n = 0

    def count(frame, event, arg):
        nonlocal n
        if event == "call":
            n += 1

    sys.setprofile(count)
    try:
        lint_source(text, "x.aou")
    finally:
        sys.setprofile(None)
    return n


def test_a_statement_of_many_arguments_reads_in_linear_work():
    for statement in (lambda k: "shiver 6deg f=3Hz " + "1 " * k,
                      lambda k: "pause 1s " + "x 3 " * k):
        small, large = _calls(statement(300)), _calls(statement(1200))
        assert large < 6 * small, (statement(2), small, large)  # 4x the arguments
