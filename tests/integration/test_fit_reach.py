"""`--fit` of a reach: a gaze angle or a distance the arm cannot follow (C301 outside
its workspace, C302 a joint at its limit) is brought back within reach by changing that
one value, keeping the declared state and the order of a variant pair; without `--fit`
the refusal's hint gives every change the motion needs, and applying it compiles.

The oracle is the round trip: the fitted file, compiled and measured, shows the values
it declares (no C310) and the state the original declares."""

from __future__ import annotations

import re

import pytest

from aou_dsl.core.diagnostics import Span
from aou_dsl.driver.builder import build_source
from aou_dsl.fit.text_edits import apply_edit
from tests import langgen

REACH = ("C301", "C302", "C303")


def _curious(robot: str, gaze: str) -> str:
    return f"behaviour c : curious\nrobot {robot}\napproach a=0.09\npause 1.25s x3\n{gaze}\n"


def _fearful(robot: str, retreat: str) -> str:
    return (f"behaviour f : fearful\nrobot {robot}\napproach a=0.1\npause 1.25s x4\n"
            f"{retreat}\nshiver 6deg f=1.1Hz for 2.73s\n")


def _errors(res) -> list:
    return [d for d in res.diagnostics if d.severity.name == "ERROR"]


def apply_hint(text: str, d) -> str:
    """The file with a refusal's hint applied as a person would: each ``write `S` at
    line N`` replaces the statement of line N that starts like S; a ``write `k=v```
    edits the refused statement."""
    said = re.findall(r"`([^`]+)` at line (\d+)", d.hint or "")
    if not said:
        text = apply_edit(text, d.span, d.hint.split("`")[1])
        for edit, kind, n in re.findall(r"`([^`]+)` in the (\w+) at line (\d+)", d.hint):
            row = text.split("\n")[int(n) - 1]
            col = row.index(kind + " ") + 1
            end = min([len(row)] + [row.index(c, col) for c in ";#" if c in row[col:]])
            text = apply_edit(text, Span(d.span.path, int(n), col, int(n), end + 1), edit)
        return text
    lines = text.split("\n")
    for stmt, n in said:
        words = stmt.split()
        head = " ".join(words[:2] if words[0] == "gaze" else words[:1]) + " "
        row = lines[int(n) - 1]
        at = row.index(head)
        end = min([len(row)] + [row.index(c, at) for c in ";#" if c in row[at:]])
        lines[int(n) - 1] = row[:at] + stmt + (" " if end < len(row) and row[end] == "#"
                                               else "") + row[end:]
    return "\n".join(lines)


def _fitted(res) -> list:
    return [d for d in res.diagnostics if d.code == "C314"]


@pytest.mark.parametrize(("robot", "gaze", "code"), [
    ("ur3", "gaze horizontal 85deg x2", "C301"),
    ("kinova", "gaze vertical 60deg", "C301"),
    ("z1", "gaze horizontal 85deg x2", "C302"),
])
def test_a_gaze_too_wide_is_fitted_within_reach_and_stays_curious(robot, gaze, code):
    text = _curious(robot, gaze)
    plain = build_source(text, "c.aou", check=False)
    (d,) = _errors(plain)
    assert d.code == code and d.span.line == 5
    assert d.hint.startswith("write `gaze "), d.hint
    assert build_source(apply_hint(text, d), "c.aou").ok
    res = build_source(text, "c.aou", fit=True)
    assert res.ok, [(x.code, x.message) for x in res.diagnostics]
    (c,) = _fitted(res)
    assert c.span.line == 5 and c.fields["descriptor"].endswith("_gaze")
    declared = float(re.search(r"(\d+)deg", gaze).group(1))
    assert f"declared {declared:g}deg -> fitted " in c.message
    assert 0 < float(c.fields["fitted"]) < declared
    if code == "C302":  # a joint binds: it is named, with its limit
        assert c.fields["joint"] and f"{c.fields['joint']}'s position limit" in c.message
    else:
        assert "the arm's reach binds" in c.message
    # the fitted file measures as it declares, and as curious as the original
    assert not [x for x in res.diagnostics if x.code == "C310"]
    assert res.lint.cv.state.value == res.measured.cv.state.value == "curious"
    got = res.measured.descriptors[c.fields["descriptor"]]
    assert got == pytest.approx(float(c.fields["fitted"]), abs=2.0)


def test_a_retreat_too_far_for_a_small_arm_is_shortened_and_stays_fearful():
    text = _fearful("z1", "retreat 0.3m a=2")
    (d,) = _errors(build_source(text, "f.aou", check=False))
    assert d.code == "C302" and d.fields["joint"] and d.span.line == 5
    res = build_source(text, "f.aou", fit=True)
    assert res.ok, [(x.code, x.message) for x in res.diagnostics]
    (c,) = [x for x in _fitted(res) if x.fields["descriptor"] == "retreat_distance"]
    assert c.fields["declared"] == "0.3" and 0 < float(c.fields["fitted"]) < 0.3
    assert f"{d.fields['joint']}'s position limit binds" in c.message
    assert not [x for x in res.diagnostics if x.code == "C310"]
    assert res.measured.cv.state.value == "fearful"
    assert res.measured.descriptors["retreat_distance"] == pytest.approx(
        float(c.fields["fitted"]), abs=0.01)
    assert {f["key"] for f in res.header["fitted"]} >= {"length"}
    assert f"retreat {c.fields['fitted']}m a=" in res.fitted_source


@pytest.mark.parametrize(("make", "robot", "values"), [
    (lambda r, x: _curious(r, f"gaze horizontal {x}deg x2"), "ur3", (70, 80, 85)),
    (lambda r, x: _fearful(r, f"retreat {x}m a=2"), "z1", (0.25, 0.3)),
])
def test_a_variant_pair_keeps_its_order_when_its_reach_is_fitted(make, robot, values):
    """Values the arm cannot reach, differing in that one value, are fitted to values
    in the same order (one increasing map under one bound), each below the bound."""
    fitted, bounds = [], set()
    for x in values:
        res = build_source(make(robot, x), "pair.aou", fit=True, check=False)
        assert res.ok, [(d.code, d.message) for d in res.diagnostics]
        (c,) = [d for d in _fitted(res) if d.fields["key"] in ("angle", "length")]
        fitted.append(float(c.fields["fitted"]))
        plain = build_source(make(robot, x), "pair.aou", check=False)
        bounds.add(round(_errors(plain)[0].fields["reach"][0]["bound"], 9))
    assert all(a < b for a, b in zip(fitted, fitted[1:], strict=False)), fitted
    (bound,) = bounds  # the bound does not depend on the value declared
    assert all(f < bound for f in fitted)


def test_a_fit_that_would_change_the_state_is_refused_with_why():
    """On the Z1 a vertical gaze small enough to reach no longer reads as curious."""
    text = _curious("z1", "gaze vertical 60deg")
    (d,) = _errors(build_source(text, "c.aou", check=False))
    assert "would express `hesitant`, not `curious`" in d.hint
    res = build_source(text, "c.aou", fit=True, check=False)
    assert not res.ok and res.fitted_source is None
    (c,) = _fitted(res)
    assert c.message.startswith("not fitted") and "`hesitant`, not `curious`" in c.message


def test_a_direction_in_a_sequence_keeps_its_sign():
    text = ("robot ur3\nsequence {\n  approach 0.1m\n  pause 1s\n  gaze horizontal -85deg\n"
            "  pause 1s\n}\n")
    res = build_source(text, "s.aou", fit=True, check=False)
    assert res.ok, [(d.code, d.message) for d in res.diagnostics]
    (c,) = _fitted(res)
    assert c.fields["declared"] == "-85" and -85 < float(c.fields["fitted"]) < 0
    assert f"gaze horizontal {c.fields['fitted']}deg" in res.fitted_source


def test_the_hint_gives_every_reach_change_at_once():
    """A gaze and a retreat both beyond the UR3's reach: one refusal (the compiler stops
    at the first), whose hint names both statements; applied, the file compiles."""
    text = ("behaviour f : fearful\nrobot ur3\napproach a=0.1\npause 1.25s x4\n"
            "retreat 0.4m a=0.5\ngaze vertical 70deg\nshiver 6deg f=1Hz for 3s\n")
    (d,) = _errors(build_source(text, "two.aou", check=False))
    assert d.code in REACH
    lines = sorted(int(n) for n in re.findall(r"` at line (\d+)", d.hint))
    assert lines == [5, 6], d.hint
    fixed = apply_hint(text, d)
    again = build_source(fixed, "two.aou")
    assert again.ok, (fixed, [(x.code, x.message) for x in again.diagnostics])
    fit = build_source(text, "two.aou", fit=True, check=False)
    assert {c.span.line for c in _fitted(fit)} == {5, 6}


def test_a_too_fast_refusal_s_hint_names_every_statement_too_fast():
    """Two shivers of a sequence too fast for the Z1's wrist: the compiler stops at the
    first, and its hint adds the second's edit (each narrower at its own frequency:
    slower, they would read as slow rolls); applied, the file compiles."""
    text = ("robot z1\nsequence {\n  approach 0.1m\n  pause 1s\n  shiver 5deg f=2.5Hz\n"
            "  pause 1s\n  shiver 4deg f=2.2Hz for 2s\n}\n")
    (d,) = _errors(build_source(text, "s.aou", check=False))
    assert d.code == "C308" and d.span.line == 5
    assert re.search(r"`shiver [0-9.]+deg f=2.5Hz` at line 5; `shiver [0-9.]+deg f=2.2Hz "
                     r"for 2s` at line 7", d.hint), d.hint
    fixed = apply_hint(text, d)
    again = build_source(fixed, "s.aou")
    assert again.ok, (fixed, [(x.code, x.message) for x in again.diagnostics])


def _family(code: str) -> tuple[str, ...]:
    return REACH if code in REACH else (code,)


def test_applying_any_refusals_hint_over_a_generated_set_compiles_in_one_round():
    """Generated files on small arms: every refusal whose hint says what to write is
    gone in one round once the hint is applied (no refusal of its kind is left at the
    statements it names; a reach hint names every statement the motion needs changed);
    applying the hints in turn, the file compiles."""
    robots = ("z1", "ur3", "kinova", "ur5")
    seen: dict[str, int] = {}
    for i, case in enumerate(langgen.random_cases(40, seed=11)):
        robot = robots[i % len(robots)]
        text = case.text
        for _ in range(4):
            res = build_source(text, "gen.aou", robot=robot, check=False)
            errors = _errors(res)
            if not errors or not all((d.hint or "").startswith("write `") for d in errors):
                break
            (d,) = errors
            seen[d.code] = seen.get(d.code, 0) + 1
            fixed = apply_hint(text, d)
            assert fixed != text, d.hint
            again = build_source(fixed, "gen.aou", robot=robot, check=False)
            named = {int(n) for n in re.findall(r"at line (\d+)", d.hint)} | {d.span.line}
            left = [x for x in _errors(again) if x.code in _family(d.code)
                    and x.span.line in named]
            assert not left, (text, d.hint, [(x.code, x.message) for x in left])
            text = fixed
        else:
            raise AssertionError(f"hints never end: {text}")
        if text != case.text:
            assert not _errors(res), (text, [(x.code, x.message) for x in _errors(res)])
    assert seen.get("C308") and seen.get("C309") and any(seen.get(c) for c in REACH), seen


def test_every_arm_gives_every_shipped_behaviour_as_declared_or_as_fitted():
    """The robots page's report (kept equal to a fresh run by the slow test of
    test_robots.py): on every built-in arm each shipped behaviour compiles, passes the
    checks and measures as declared, or does so with --fit (measured as its fitted file
    declares, in its declared state), and each fitted change is stated; or --fit refuses
    it with C315, the reason stated, where no change keeps what a person sees."""
    from aou_dsl.core.robot_specs import ROBOTS
    from tests.conftest import BEHAVIOURS, ROOT

    page = (ROOT / "docs" / "robots.md").read_text()
    report = page[page.index("<!-- report:start"):page.index("<!-- report:end")]
    n = len(list(BEHAVIOURS.glob("*.aou")))
    refused = report.count("| refused (C315) |")
    assert f"{len(ROBOTS) - refused} of {len(ROBOTS)} do with --fit" in report
    for robot in ROBOTS:
        section = report[report.index(f"\n### {robot}\n"):]
        section = section[:section.index("\n### ", 5)] if "\n### " in section[5:] \
            else section
        rows = [r for r in section.split("\n") if r.startswith("| ")
                and not r.startswith("| behaviour")]
        assert len(rows) == n, robot
        for row in rows:
            cells = [c.strip() for c in row.strip("|").split("|")]
            declared_ok = cells[1:4] == ["yes", "yes", "yes"]
            assert declared_ok or cells[-1] in ("yes", "refused (C315)"), (robot, row)
            if cells[-1] == "refused (C315)":
                assert f"- {cells[0]} with --fit: refused, C315 " in section, (robot, row)
            elif not declared_ok:
                note = f"- {cells[0]} with --fit: "
                assert note in section and " -> fitted " in section.split(note)[1] \
                    .split("\n")[0], (robot, cells[0])


def test_a_shiver_no_frequency_fits_is_fitted_by_its_amplitude_in_order():
    """60 deg would need a shiver slower than the language allows: the amplitude is
    fitted instead, at its frequency; applying the hint compiles, the fitted file
    measures the amplitude it declares, and two amplitudes keep their order."""
    got = []
    for amp in (50, 60):
        text = f"shiver {amp}deg f=2.5Hz\n"
        (d,) = _errors(build_source(text, "s.aou", check=False))
        assert d.code == "C308" and not d.fields["max_frequency"]
        assert d.hint.startswith("write `shiver "), d.hint
        assert build_source(apply_hint(text, d), "s.aou").ok
        res = build_source(text, "s.aou", fit=True)
        assert res.ok, [(x.code, x.message) for x in res.diagnostics]
        (c,) = _fitted(res)
        assert c.fields["descriptor"] == "shiver_amplitude" and c.fields["joint"]
        fitted = float(c.fields["fitted"])
        assert not [x for x in res.diagnostics if x.code == "C310"]
        assert res.measured.descriptors["shiver_amplitude"] == pytest.approx(fitted, abs=0.5)
        got.append(fitted)
    assert got[0] < got[1]
