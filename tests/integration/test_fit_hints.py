"""A refusal's hint carries every change the file needs, at once: the compiler stops at
its first refusal, but the hint of that refusal also names what the arm would refuse
next (a shiver too fast after a reach; a second shiver of a sequence), so that applying
it once compiles. Its field ``edits`` holds the same changes as text edits (the span of
each statement as written and the text to write there), which the editor applies as one
quick fix.

The oracle is the compiler itself: the edits applied once, the file is compiled again
and no refusal is left."""

from __future__ import annotations

import re

import pytest

from aou_dsl.driver.builder import build_source
from aou_dsl.lang.linter import lint_source
from tests import langgen
from tests.integration.test_fit_reach import apply_hint

#: The arms of the generated sets: small ones (the Z1, the UR3, the Kinova) refuse
#: reaches, the UR5's slow wrist refuses shivers.
ROBOTS = ("z1", "ur3", "kinova", "ur5")


def apply_edits(text: str, edits: list[dict]) -> str:
    """``text`` with each edit's span replaced by its text (from the last edit to the
    first, so the earlier spans stay valid)."""
    lines = text.split("\n")
    for e in sorted(edits, key=lambda e: (e["line"], e["col"]), reverse=True):
        assert e["line"] == e["end_line"], e
        row = lines[e["line"] - 1]
        assert row[e["col"] - 1:e["end_col"] - 1] == e["was"], (row, e)
        lines[e["line"] - 1] = row[:e["col"] - 1] + e["text"] + row[e["end_col"] - 1:]
    return "\n".join(lines)


def _errors(res) -> list:
    return [d for d in res.diagnostics if d.severity.name == "ERROR"]


def _says_what_to_write(d) -> bool:
    """A refusal whose hint is a change of the file: a value to write, or the `start`
    at which every pose is within reach."""
    return (d.hint or "").startswith("write `") or bool(re.search(r"`start \d+cm`",
                                                                  d.hint or ""))


def _one_round(text: str, robot: str, seen: dict[str, int]) -> None:
    """Every refusal of ``text`` on ``robot`` whose hint says what to write: its edits,
    applied once, compile with no refusal; the hint names each edit."""
    res = build_source(text, "gen.aou", robot=robot, check=False)
    for d in _errors(res):
        if not _says_what_to_write(d):
            continue
        seen[d.code] = seen.get(d.code, 0) + 1
        edits = d.fields.get("edits")
        assert edits, (text, robot, d.code, d.hint)
        for e in edits:  # the words say what the fields do
            keyed = " ".join(k for k in re.findall(r"\w+=\S+|for\s+\S+", e["text"])
                             if k not in e["was"])
            added = e["text"].removeprefix(e["was"]).lstrip("; ")  # a setting written
            assert f"`{e['text']}`" in d.hint or (keyed and f"`{keyed}`" in d.hint) or (
                added and f"`{added}`" in d.hint), (d.hint, e)
        if len(edits) > 1:
            seen["several"] = seen.get("several", 0) + 1
        if len({e["text"].split()[0] for e in edits}) > 1:  # e.g. a gaze and a tilt
            seen["kinds"] = seen.get("kinds", 0) + 1
        fixed = apply_edits(text, edits)
        if d.hint.startswith("write `"):  # as a person applies it, from the words
            assert apply_hint(text, d).split() == fixed.split(), (text, d.hint)
        again = build_source(fixed, "gen.aou", robot=robot, check=False)
        if not d.fields["edits_complete"]:  # said so: what is then refused, and why
            seen["said not answered"] = seen.get("said not answered", 0) + 1
            assert "; not every refusal is answered: then " in d.hint, d.hint
            (left, *_) = _errors(again)
            assert f"then {left.code} at line {left.span.line}" in d.hint, d.hint
            fit = build_source(text, "gen.aou", robot=robot, check=False, fit=True)
            assert _errors(fit), (text, d.hint)  # --fit finds no answer either
            continue
        assert not _errors(again), (text, robot, d.hint,
                                    [(x.code, x.message) for x in _errors(again)])


def _faster(text: str) -> str:
    """``text`` with its shivers three times as fast and its gazes and retreats wider,
    where the language allows it: files an arm refuses for more than one reason."""
    def shiver(m: re.Match) -> str:
        return f"f={min(float(m[1]) * 3, 8):.3g}Hz"

    def wider(m: re.Match) -> str:
        return f"{m[1]}{min(abs(float(m[2])) * 1.6, 85):.4g}deg"

    out = []
    for row in text.split("\n"):
        if "shiver" in row:
            row = re.sub(r"f=([0-9.]+)Hz", shiver, row)
        row = re.sub(r"(gaze \w+ -?)([0-9.]+)deg", wider, row)
        row = re.sub(r"(retreat )([0-9.]+)m\b", lambda m: f"{m[1]}"
                     f"{min(float(m[2]) * 2, 0.4):.3g}m", row)
        out.append(row)
    faster = "\n".join(out)
    return faster if lint_source(faster, "gen.aou").ok else text


def test_a_reach_and_a_shiver_too_fast_are_answered_by_one_hint():
    """On the UR3 a 0.4 m retreat is out of reach and a 4 Hz shiver too fast for the
    wrist: the compiler refuses the retreat; its hint also gives the slower shiver (still
    a tremor, 2.5 Hz at least), and applied once the file compiles."""
    text = ("behaviour f\nrobot ur3\napproach a=0.1\npause 1.25s x4\n"
            "retreat 0.4m a=0.5\nshiver 2deg f=4Hz for 3s\n")
    (d,) = _errors(build_source(text, "two.aou", check=False))
    assert d.code in ("C301", "C302", "C303") and d.span.line == 5
    assert [e["line"] for e in d.fields["edits"]] == [5, 6], d.hint
    f = re.search(r"`shiver 2deg f=([0-9.]+)Hz[^`]*` at line 6", d.hint)
    assert f and 2.5 <= float(f[1]) < 4, d.hint
    fixed = apply_edits(text, d.fields["edits"])
    again = build_source(fixed, "two.aou")
    assert again.ok, (fixed, [(x.code, x.message) for x in again.diagnostics])


def test_a_start_out_of_reach_and_a_shiver_too_fast_are_answered_by_one_hint():
    """The start pose beyond the Z1's reach: the hint's `start` and the slower shiver
    the Z1's wrist then needs are one quick fix."""
    text = "robot z1\nstart 0.9m\napproach a=0.1\npause 1s\nshiver 5deg f=6Hz\n"
    (d,) = _errors(build_source(text, "s.aou", check=False))
    assert d.span.line == 2 and "`start " in d.hint, d.hint
    lines = [e["line"] for e in d.fields["edits"]]
    assert lines == [2, 5], d.hint
    again = build_source(apply_edits(text, d.fields["edits"]), "s.aou", check=False)
    assert not _errors(again), [(x.code, x.message) for x in again.diagnostics]


def test_a_file_without_start_gets_the_start_that_fits_as_an_edit():
    """The Kinova reaches no start pose 0.3 m from that goal (the default: the file has
    no `start`): the hint's `start` is written after the `goal` it points at, with the
    slower shiver the wrist then needs, and the file compiles."""
    text = "robot kinova\ngoal (0.3, 0.0, 0.6)\napproach a=0.1\npause 1s\nshiver 5deg f=6Hz\n"
    (d,) = _errors(build_source(text, "s.aou", check=False))
    assert d.span.line == 2 and re.search(r"; start \d+cm` at line 2", d.hint), d.hint
    first, second = d.fields["edits"]
    assert re.fullmatch(r"goal \(0\.3, 0\.0, 0\.6\); start \d+cm", first["text"]), first
    assert second["line"] == 5 and "f=6Hz" not in second["text"]
    fixed = apply_edits(text, d.fields["edits"])
    assert apply_hint(text, d).split() == fixed.split(), d.hint
    again = build_source(fixed, "s.aou", check=False)
    assert not _errors(again), [(x.code, x.message) for x in again.diagnostics]


def test_a_hint_that_cannot_answer_everything_says_so():
    """Two shivers too fast for the UR3's wrist in an inactive sequence. Slower than
    declared they would read as slow rolls; narrower, the file would read curious: no
    change keeps both, so the hint has no edit and says why, and ``--fit`` refuses."""
    text = ("behaviour b : inactive\nsequence {\n  pause 1350ms\n  approach\n"
            "  gaze horizontal 18.7deg\n  pause 0.516s\n  retreat 0.0425m a=0.107\n"
            "  gaze horizontal 24.4deg\n  pause 553ms\n  shiver 7.56deg f=2.04Hz for 1.53s x2\n"
            "  pause 1.3s; gaze horizontal 15.8deg\n  shiver 4.79deg f=2.32Hz\n"
            "  pause 0.352s\n  retreat 0.0433m a=0.0512 x2\n  pause 1.15s\n}\n"
            "from (-0.65, -0.1, 0.75); start 30.4cm\n")
    (d,) = _errors(build_source(text, "s.aou", robot="ur3", check=False))
    assert d.code == "C308" and d.span.line == 10
    assert not d.fields.get("edits") and "`" not in d.hint.split(":")[0], d.hint
    assert "would make the file express `curious`, not `inactive`" in d.hint, d.hint
    assert "slow rolls" in d.hint, d.hint
    fit = build_source(text, "s.aou", robot="ur3", check=False, fit=True)
    assert _errors(fit)  # --fit gives no answer either
    assert [x.span.line for x in fit.diagnostics if x.code == "C315"] == [10]


def test_applying_any_refusals_hint_once_compiles_over_a_generated_set():
    """Generated files on small arms, and the same files with faster shivers and wider
    gazes and retreats (refused for two reasons at once): every refusal whose hint says
    what to write compiles once its edits are applied, in one round."""
    seen: dict[str, int] = {}
    for i, case in enumerate(langgen.random_cases(24, seed=23)):
        robot = ROBOTS[i % len(ROBOTS)]
        _one_round(case.text, robot, seen)
        _one_round(_faster(case.text), robot, seen)
    assert seen.get("C308") and any(seen.get(c) for c in ("C301", "C302", "C303")), seen
    assert seen.get("several"), seen  # hints that change more than one statement
    assert seen.get("kinds"), seen  # ... of more than one kind


@pytest.mark.slow
@pytest.mark.large
def test_applying_any_refusals_hint_once_compiles_over_a_bigger_generated_set():
    seen: dict[str, int] = {}
    for i, case in enumerate(langgen.random_cases(160, seed=11)):
        robot = ROBOTS[i % len(ROBOTS)]
        _one_round(case.text, robot, seen)
        _one_round(_faster(case.text), robot, seen)
    assert seen.get("C308") and seen.get("C309") and seen.get("several"), seen


def test_aouc_compile_prints_the_hint_with_every_change(tmp_path, capsys):
    """`aouc compile` refuses the file, writes nothing, and its hint line names both
    statements to change, as words a person applies."""
    from aou_dsl.cli.commands import main

    src = tmp_path / "two.aou"
    src.write_text("behaviour f\nrobot ur3\napproach a=0.1\npause 1.25s x4\n"
                   "retreat 0.4m a=0.5\nshiver 2deg f=4Hz for 3s\n")
    assert main(["compile", str(src), "-o", str(tmp_path / "out"), "--no-check"]) != 0
    err = capsys.readouterr().err
    said = err.split("[error]", 1)[1]  # the refusal, then its source line and hint
    hint = next(ln for ln in said.splitlines() if ln.strip().startswith("= hint:"))
    assert re.search(r"`retreat [0-9.]+m a=0\.5` at line 5; `shiver 2deg f=[0-9.]+Hz"
                     r"[^`]*` at line 6", hint), hint
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
