"""The studio's Save: new descriptor values written into a .aou text, nothing else touched."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from aou_dsl.core.diagnostics import AouError
from aou_dsl.lang.declared import written
from aou_dsl.lang.linter import lint_source
from aou_dsl.studio.edits import Origin, apply, settable, synth_origin

HESITANT = """\
# a comment that stays
behaviour hesitant : hesitant
robot panda
start 0.30m   # aligned comment
standoff 0.10m

approach   a=0.05
pause 1670ms x5    # written in milliseconds
retreat 0.06m a=0.12 x3
"""


def _values(text: str) -> dict:
    r = lint_source(text, "t.aou")
    assert r.ok and r.behaviour is not None, r.diagnostics
    return dict(written(r.behaviour))


def test_only_the_changed_token_is_rewritten():
    new = apply(HESITANT, {"approach_acceleration": 0.08})
    assert new == HESITANT.replace("a=0.05", "a=0.08")
    assert _values(new)["approach_acceleration"] == pytest.approx(0.08)


def test_a_value_in_another_unit_is_written_in_the_descriptors():
    new = apply(HESITANT, {"pause_duration": 2.25})
    assert new == HESITANT.replace("1670ms", "2.25s")
    assert "# written in milliseconds" in new


def test_counts_change_their_xN_and_keep_the_rest():
    new = apply(HESITANT, {"pause_count": 3, "retreat_count": 1})
    assert new == HESITANT.replace("x5", "x3").replace("a=0.12 x3", "a=0.12 x1")
    v = _values(new)
    assert (v["pause_count"], v["retreat_count"]) == (3, 1)


def test_a_value_left_to_its_default_is_added_to_its_statement():
    text = "behaviour b : hesitant\napproach\npause 1.5s x3  # note\nretreat 0.05m x2\n"
    new = apply(text, {"approach_acceleration": 0.07, "retreat_acceleration": 0.2})
    assert new == text.replace("approach\n", "approach a=0.07\n").replace(
        "retreat 0.05m x2", "retreat 0.05m a=0.2 x2")
    text1 = "behaviour b : hesitant\napproach a=0.05\npause 1.5s # one\n"
    assert apply(text1, {"pause_count": 4}) == text1.replace("1.5s", "1.5s x4")


def test_angles_are_written_in_degrees():
    text = "behaviour c : curious\napproach a=0.09\npause 1.25s x3\ngaze horizontal 20deg x2\n"
    new = apply(text, {"horizontal_gaze": 27.5})
    assert new == text.replace("20deg", "27.5deg")


def test_unchanged_values_leave_the_text_as_it_was():
    assert apply(HESITANT, {"pause_count": 5, "approach_acceleration": 0.05}) == HESITANT
    assert apply(HESITANT, {}) == HESITANT


def test_what_cannot_be_changed_is_refused_with_a_code():
    seq = "behaviour s : hesitant\nsequence {\n  approach 0.1m\n  pause 1s\n}\n"
    lint = lint_source(seq, "s.aou")
    assert "pause_count" not in settable(lint.behaviour, lint.timeline)
    with pytest.raises(AouError) as err:  # a sequence's counts are its statements' order
        apply(seq, {"pause_count": 2})
    assert err.value.diagnostics[0].code == "I504"
    with pytest.raises(AouError) as err:
        apply(HESITANT, {"shiver_amplitude": 3.0})  # the file has no shiver
    assert err.value.diagnostics[0].code == "I504"
    with pytest.raises(AouError) as err:  # shorter than a pause that can be seen
        apply(HESITANT, {"pause_duration": 0.05})
    assert err.value.diagnostics[0].code.startswith("V")


def test_settable_lists_what_the_file_sets_in_the_descriptors_units():
    text = "behaviour c : curious\napproach a=0.09\npause 1.25s x3\ngaze horizontal 20deg x2\n"
    got = settable(lint_source(text, "c.aou").behaviour)
    assert got == {"approach_acceleration": 0.09, "pause_count": 3, "pause_duration": 1.25,
                   "horizontal_gaze": pytest.approx(20.0)}


@settings(max_examples=60, deadline=None)
@given(pd=st.floats(0.2, 5.0), pc=st.integers(0, 8), rd=st.floats(0.005, 0.09),
       ra=st.floats(0.01, 1.5), aa=st.floats(0.01, 1.0))
def test_the_new_text_declares_the_new_values_and_keeps_the_others(pd, pc, rd, ra, aa):
    changes = {"pause_duration": pd, "pause_count": pc, "retreat_distance": rd,
               "retreat_acceleration": ra, "approach_acceleration": aa}
    try:
        new = apply(HESITANT, changes)
    except AouError as err:  # a combination the language refuses says why, with a code
        assert all(d.code[0] in "VC" for d in err.diagnostics)
        return
    got = _values(new)
    for name, value in changes.items():
        assert got[name] == pytest.approx(value, rel=1e-5)
    assert got["retreat_count"] == 3
    for line_old, line_new in zip(HESITANT.splitlines(), new.splitlines(), strict=True):
        if not line_old.startswith(("approach", "pause", "retreat")):
            assert line_new == line_old  # settings, comments and blank lines stay
        elif "#" in line_old:
            assert line_new.endswith(line_old[line_old.index("#") - 4:])


def test_a_file_synth_wrote_for_a_state_says_its_intensity():
    from aou_dsl.synth.synthesis import synthesize

    text = synthesize("hesitant", intensity=0.7, verify=False)
    assert synth_origin(text) == Origin("hesitant", 0.7)
    assert synth_origin(HESITANT) is None
    blend = synthesize(C=-0.5, V=0.2, intensity=0.8, verify=False)  # a C-V point
    assert synth_origin(blend) == Origin("hesitant", 0.8, (-0.5, 0.2))


#: Characters Python's ``str.splitlines`` ends a line at, that the language does not.
LINE_LIKE = ["\f", "\v", "\x1c", "\x1d", "\x1e", "\x85", "\u2028", "\u2029"]
PEEK_SEQUENCE = """\
# a sequence
behaviour peek : curious
sequence {
  approach 0.08m a=0.09
  pause 1.25s   # first
  gaze horizontal 20deg
  pause 1.25s
  approach a=0.09
}
"""


@pytest.mark.parametrize("mark", LINE_LIKE)
@pytest.mark.parametrize("text, changes", [
    (HESITANT, {"retreat_acceleration": 0.2, "pause_count": 4}),
    (PEEK_SEQUENCE, {"horizontal_gaze": 26.0}),
])
def test_line_like_characters_in_comments_move_no_edit(mark, text, changes):
    """A character that is not a line end in the language, in comments before the
    statements edited, leaves each edit on its own statement: the edit is the one made
    without it, the character kept where it was."""
    plain = apply(text, changes)
    marked = text.replace("# a", f"# a{mark}", 1).replace("# first", f"# fi{mark}rst")
    assert marked != text
    want = plain.replace("# a", f"# a{mark}", 1).replace("# first", f"# fi{mark}rst")
    assert apply(marked, changes) == want
