"""Every numeric option of every command, fed what scripts and typos feed it.

A number that is not finite, or out of the option's range, is a usage error (exit 2)
before any work: never a traceback, a hang, or a check that passes because its input
was not a number. The options are found by walking the parser, so a new option is
covered the day it is added.
"""

from __future__ import annotations

import argparse
import math

import pytest

from aou_dsl.cli.args import build_parser
from aou_dsl.cli.commands import main

BAD = ("0", "-1", "nan", "NaN", "inf", "-inf", "1e308", "-1e308", "99999999999999999999",
       "20000x20000", "", "1,2", "x")

#: The least each command needs besides the option under test.
BASE = {
    "lint": ["x.aou"], "explain": ["x.aou"], "compile": ["x.aou"], "check": ["x.json"],
    "plot": ["x.json", "-o", "x.png"], "render": ["x.aou", "-o", "x.gif"],
    "variants": ["x.aou", "--vary", "pause_duration=1,2"], "measure": ["x.json"],
    "rules": [], "robot": ["panda"], "synth": ["--state", "curious"],
    "studio": ["x.aou"], "dmp": ["roll", "x.dmp"],
}


def _numeric_options() -> list[tuple[str, str]]:
    _, commands = build_parser()
    out = []
    for name, sub in commands.items():
        for action in sub._actions:
            if not action.option_strings or action.type in (None, str):
                continue
            if isinstance(action, argparse._StoreAction):
                out.append((name, action.option_strings[-1]))
    return out


OPTIONS = _numeric_options()


def test_the_walk_finds_the_numeric_options():
    found = set(OPTIONS)
    assert {("compile", "--rate"), ("render", "--fps"), ("render", "--size"),
            ("check", "--target-size"), ("check", "--table-height"),
            ("synth", "--intensity"), ("measure", "--goal")} <= found
    assert set(BASE) >= {name for name, _ in OPTIONS}


def _finite(value) -> bool:
    if isinstance(value, tuple):
        return all(_finite(v) for v in value)
    return not isinstance(value, float) or math.isfinite(value)


@pytest.mark.parametrize("command, option", OPTIONS)
@pytest.mark.parametrize("value", BAD)
def test_a_bad_number_is_a_usage_error_or_a_finite_value(command, option, value):
    parser, _ = build_parser()
    argv = [command, *BASE[command], f"{option}={value}"]
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:
        assert exc.code == 2
        return
    dest = next(a.dest for a in parser._subparsers._group_actions[0].choices[command]._actions
                if option in a.option_strings)
    parsed = getattr(args, dest)
    assert _finite(parsed), (argv, parsed)
    assert value.lower().lstrip("-") not in ("nan", "inf"), f"{argv} was accepted"


@pytest.mark.parametrize("argv", [
    ["compile", "behaviours/confident.aou", "--rate", "nan", "-o", "/nonexistent/x.json"],
    ["check", "behaviours/confident.aou", "--target-size", "nan"],
    ["check", "behaviours/confident.aou", "--table-height", "inf"],
    ["render", "behaviours/confident.aou", "-o", "x.gif", "--size", "20000x20000"],
    ["synth", "--C", "nan", "--V", "0"],
])
def test_the_command_line_exits_two_and_does_no_work(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "error" in err and "Traceback" not in err
