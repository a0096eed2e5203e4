"""Linting again after an edit (:class:`~aou_dsl.lang.relint.Relinter`, the warm
session's lint) gives exactly what a fresh full lint of the same text gives: the same
diagnostics (codes, messages, spans, hints, fixes, fields), behaviour, timeline and C-V
point, whatever the edits before it; and it parses only the statements an edit changed.

The files are the shipped and fixture behaviours, long files as an editor holds them and
files generated from the language contract (tests/langgen.py); each is edited many times
in a row, into valid and invalid texts alike: characters typed or deleted, lines moved,
joined, doubled or dropped, numbers half typed, junk, braces, quotes and comments.
"""

from __future__ import annotations

import random
import re

import pytest

from aou_dsl.driver.session import Session
from aou_dsl.lang.linter import FileResult, lint_source
from aou_dsl.lang.parse import parse
from aou_dsl.lang.pieces import Pieces
from aou_dsl.lang.relint import Relinter
from tests import langgen
from tests.conftest import BEHAVIOURS, INVALID, ROOT, VALID

#: Characters an edit types: the language's own, and the slips a file may hold.
TYPED = list("abcdefgsxz0123456789.-+=:;,(){}#\"' \t\n") + [
    "\r", "°", "\u00a0", "\ufeff", "\x0b", "é", "１"]
JUNK = ["sequence", "sequence {", "}", "{", "??", "x3", "x", "1e", "-", ".", "0.", "1.5",
        '"', '"a;b#c"', "# note; {", "behaviour b : curious", "robot panda", "pause 1s",
        "approach a=", "gaze (1, 2, 3)", "( 0.5, 0, 0.3 )", "effort W=", ";;", "\n\n"]


def outcome(r: FileResult) -> tuple[str, ...]:
    """Everything a lint says, exactly (reprs: floats to the last bit, NaN equal to
    itself)."""
    return (r.path, repr(r.source), repr(r.diagnostics), repr(r.suppressed),
            repr(r.behaviour), repr(r.timeline), repr(r.cv))


def long_sequence(lines: int = 200) -> str:
    """A long sequence of every kind, as an editor holds it."""
    body = []
    for i in range(lines):
        body.append(["  approach 0.01m a=0.1", f"  pause {0.5 + i % 3 / 10:g}s  # hold {i}",
                     "  retreat 0.01m a=0.1", f"  gaze horizontal {10 if i % 2 else -10}deg",
                     "  tilt 5deg v=20; pause 0.3s", "  shiver 2deg f=2Hz for 1s"][i % 6])
    return "behaviour long : hesitant\nrobot panda\nstart 0.6m\nsequence {\n" + \
        "\n".join(body) + "\n}\n"


def seeds() -> list[str]:
    files = sorted(BEHAVIOURS.glob("*.aou")) + sorted(VALID.glob("*.aou")) + \
        sorted(INVALID.glob("*.aou")) + sorted((ROOT / "examples").rglob("*.aou"))
    texts = [p.read_text(encoding="utf-8") for p in files]
    texts += [c.text for c in langgen.random_cases(40, seed=11)]
    texts += [long_sequence(60), "approach\npause 1.25s x2\nretreat 0.06m a=0.12\n", ""]
    return texts


def _numbers(text: str) -> list[re.Match]:
    return list(re.finditer(r"\d+(\.\d+)?", text))


def edit(rng: random.Random, text: str, donors: list[str]) -> str:
    """One random edit of ``text``, as typing or pasting makes it."""
    lines = text.split("\n")
    at = rng.randint(0, len(text))
    pick = rng.randrange(12)
    if pick == 0:
        return text[:at] + rng.choice(TYPED) + text[at:]
    if pick == 1:
        return text[:at] + text[at + rng.randint(1, 6):]
    if pick == 2 and _numbers(text):  # a number half typed, or retyped
        m = rng.choice(_numbers(text))
        new = rng.choice(["", "1", "1.", ".", "-", "1e", "0.4", "12.75", "3e-2", "0x"])
        return text[:m.start()] + new + text[m.end():]
    if pick == 3:
        return text[:at] + rng.choice(JUNK) + text[at:]
    i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
    if pick == 4:  # a line doubled
        lines.insert(j, lines[i])
    elif pick == 5 and len(lines) > 1:  # a line dropped
        del lines[i]
    elif pick == 6:  # a line moved
        lines.insert(j, lines.pop(i))
    elif pick == 7 and i + 1 < len(lines):  # two lines joined by a `;`
        lines[i:i + 2] = [lines[i] + rng.choice(["; ", ";", " ; "]) + lines[i + 1].lstrip()]
    elif pick == 8:  # a blank or comment line above everything that follows
        lines.insert(i, rng.choice(["", "# note", "   ", ";"]))
    elif pick == 9:  # a line of another file
        donor = rng.choice(donors).split("\n")
        lines.insert(i, rng.choice(donor))
    elif pick == 10:  # indentation changed
        lines[i] = rng.choice(["", "  ", "\t", "    "]) + lines[i].lstrip()
    else:  # many lines doubled: past the diagnostics' cap, or a long file
        lines[i:i + 1] = [lines[i]] * rng.randint(2, 40)
    return "\n".join(lines)


def check_edits(text: str, rng: random.Random, donors: list[str], steps: int,
                linter: Relinter, path: str = "edited.aou") -> None:
    history = [text]
    for _ in range(steps):
        got = outcome(linter.lint(text, path))
        assert got == outcome(lint_source(text, path)), history
        if rng.random() < 0.15 and len(history) > 1:
            text = rng.choice(history)  # undo: back to a text seen before
        else:
            text = edit(rng, text, donors)
        history.append(text)


@pytest.mark.parametrize("chunk", range(8))
def test_relint_after_edits_is_the_full_lint(chunk):
    """Many files, each edited 25 times in a row: after every edit, the lint from the
    kept statements is the full lint of the text."""
    texts = seeds()
    rng = random.Random(1000 + chunk)
    for k, text in enumerate(texts):
        if k % 8 != chunk:
            continue
        check_edits(text, rng, texts, 25, Relinter())


def test_line_endings_and_byte_order_mark_are_linted_as_a_full_lint_does():
    rng = random.Random(5)
    texts = seeds()
    for text in texts[:20]:
        for variant in (text.replace("\n", "\r\n"), "\ufeff" + text, text.replace("\n", "\r")):
            check_edits(variant, rng, texts, 6, Relinter())


def test_the_kept_tree_is_the_parsed_tree():
    """Where the pieces give a tree, it is the parser's tree of the whole text; where they
    give none, the text is one the cutting cannot be sure of (here: a syntax error)."""
    rng = random.Random(9)
    texts = seeds()
    for text in texts:
        pieces = Pieces("t.aou")
        for _ in range(15):
            tree = pieces.tree(text)
            try:
                full = parse(text, "t.aou")
            except Exception:  # noqa: BLE001 - an AouError: a syntax error
                full = None
            if tree is not None:
                assert repr(tree) == repr(full), text
            text = edit(rng, text, texts)


def test_a_one_line_edit_parses_one_statement():
    linter = Relinter()
    text = long_sequence(200)
    linter.lint(text, "long.aou")
    pieces = linter.pieces("long.aou")
    before = pieces.parsed
    edited = text.replace("pause 0.6s", "pause 0.65s", 1)
    assert outcome(linter.lint(edited, "long.aou")) == outcome(lint_source(edited, "long.aou"))
    assert pieces.parsed == before + 1


def test_lines_inserted_above_move_the_statements_without_parsing_them():
    """A line added at the top moves every statement down: none is parsed again, each
    keeps what was read from it, and the spans are those of the new lines."""
    linter = Relinter()
    text = long_sequence(100)
    linter.lint(text, "long.aou")
    pieces = linter.pieces("long.aou")
    before = pieces.parsed
    moved = "# a note\n\n" + text
    got = linter.lint(moved, "long.aou")
    assert pieces.parsed == before
    assert outcome(got) == outcome(lint_source(moved, "long.aou"))
    assert got.behaviour is not None and got.behaviour.primitives[0].span.line == 7


def test_a_syntax_error_is_the_full_parse_s_and_the_file_is_kept_through_it():
    """A syntax error mid-file is reported as the full parse reports it; once mended,
    the statements after it are still kept (not parsed again)."""
    linter = Relinter()
    text = long_sequence(100)
    linter.lint(text, "long.aou")
    pieces = linter.pieces("long.aou")
    broken = text.replace("  pause 0.6s", "  pause (0.6s", 1)
    got = linter.lint(broken, "long.aou")
    assert got.diagnostics[0].code.startswith("S")
    assert outcome(got) == outcome(lint_source(broken, "long.aou"))
    before = pieces.parsed
    assert outcome(linter.lint(text, "long.aou")) == outcome(lint_source(text, "long.aou"))
    assert pieces.parsed <= before + 1  # only the mended line, if no other line is as it


def test_the_session_lints_edits_as_a_fresh_lint():
    """The warm session's lint of an edited text is the full lint's, for each file it
    keeps apart."""
    session = Session()
    rng = random.Random(3)
    texts = seeds()
    for k in range(12):
        path = f"f{k % 3}.aou"
        text = texts[k]
        for _ in range(6):
            assert outcome(session.lint(text, path)) == outcome(lint_source(text, path))
            text = edit(rng, text, texts)


def test_a_layout_kept_from_the_last_lint_tells_minus_zero_from_zero():
    """The episodes after a gaze back to `-0deg` start from a plane angle of -0.0, after
    one to `0deg` from 0.0: equal numbers, but not the same timeline, and the relint
    gives each its own."""
    linter = Relinter()
    text = "sequence {\n  gaze horizontal 10deg\n  pause 1s\n  gaze horizontal {}deg\n" \
        "  pause 1s\n  approach 2cm\n}\n"
    for angle in ("0", "-0", "0", "-0.0", "+0"):
        t = text.replace("{}", angle)
        assert outcome(linter.lint(t, "z.aou")) == outcome(lint_source(t, "z.aou")), angle


def test_a_statement_laid_out_from_another_pose_is_laid_out_again():
    """A sequence statement whose start changes (an edit before it) is laid out anew;
    those after an edit that leaves every pose as it was keep their episodes."""
    linter = Relinter()
    text = long_sequence(60)
    for old, new in (("approach 0.01m", "approach 0.02m"), ("pause 0.6s", "pause 0.7s"),
                     ("start 0.6m", "start 0.7m"),
                     ("gaze horizontal 10deg", "gaze horizontal 12deg")):
        text = text.replace(old, new, 1)
        assert outcome(linter.lint(text, "s.aou")) == outcome(lint_source(text, "s.aou"))


def test_typing_in_one_line_at_a_time_is_the_full_lint():
    """Typing as in an editor: characters typed or deleted in one line at a time (the
    path where only that line's statement is new), numbers half typed, the line made
    junk, blank or a comment and back."""
    rng = random.Random(21)
    texts = seeds()
    for text in [long_sequence(80), *texts[:12]]:
        linter = Relinter()
        history = [text]
        original = text.split("\n")
        for _ in range(60):
            got = outcome(linter.lint(text, "typed.aou"))
            assert got == outcome(lint_source(text, "typed.aou")), history[-3:]
            lines = text.split("\n")
            k = rng.randrange(len(lines))
            line = lines[k]
            at = rng.randint(0, len(line))
            pick = rng.randrange(5)
            if pick == 0:
                typed = TYPED if rng.random() < 0.2 else list("0123456789.-=sxaegm ")
                line = line[:at] + rng.choice([*typed, "1.", "e", "deg", " x2"]) + line[at:]
            elif pick == 1:
                line = line[:at] + line[at + rng.randint(1, 3):]
            elif pick == 2 and _numbers(line):
                m = rng.choice(_numbers(line))
                line = line[:m.start()] + rng.choice(["", "1", "0.", "2.5", "-3"]) + \
                    line[m.end():]
            elif pick == 3:
                line = rng.choice(["", "  # gone", "  ??", line, "  pause 1s", "  approach"])
            elif len(lines) == len(original):  # a line typed back as it was
                k = rng.choice([i for i, (a, b) in enumerate(zip(lines, original, strict=True))
                                if a != b] or [k])
                line = original[k]
            lines[k] = line
            text = "\n".join(lines)
            history.append(text)


def test_the_relinter_s_tree_is_the_parse_and_none_on_a_syntax_error():
    """What the language server's outline reads: the parser's tree of the text, from
    the kept statements, the same text twice included; None where the parse fails."""
    rng = random.Random(33)
    texts = seeds()
    linter = Relinter()
    for text in texts[:25]:
        for _ in range(8):
            for variant in (text, text, "\ufeff" + text):
                try:
                    full = repr(parse(variant.removeprefix("\ufeff"), "o.aou"))
                except Exception:  # noqa: BLE001 - an AouError: a syntax error
                    full = None
                tree = linter.tree(variant, "o.aou")
                assert (repr(tree) if tree is not None else None) == full, variant
            text = edit(rng, text, texts)
