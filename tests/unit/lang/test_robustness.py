"""Bad input never crashes aou: whatever the text, lint returns diagnostics with codes
and locations, never an exception."""

from hypothesis import given, settings
from hypothesis import strategies as st

from aou_dsl.core.diagnostics import RULES
from aou_dsl.lang.linter import lint_source

TOKENS = ["behaviour", "b", ":", "hesitant", "robot", "panda", "ur5", "goal", "from",
          "(", ")", ",", "0.5", "-1", "start", "standoff", "effort", "W=1", "T=-1",
          "S=0.5", "F=2", "approach", "pause", "retreat", "gaze", "horizontal", "vertical",
          "tilt", "shiver", "for", "sequence", "{", "}", "x3", "x0", "x2.5", "a=0.05",
          "v=3deg/s", "f=4Hz", "1.67s", "6cm", "20deg", "-20deg", "0m", "1e-2m", "3m/s^2",
          "12in", ";", "\n", "#", "@", "=", "\t", "1e999s", "nan", "-0s"]


def _assert_diagnosed(text: str) -> None:
    result = lint_source(text, "fuzz.aou")
    for d in result.diagnostics:
        assert d.code in RULES
        assert d.span.line >= 1 and d.span.col >= 1
    assert (result.behaviour is None) == (not result.ok)


@settings(max_examples=400, deadline=None)
@given(st.lists(st.sampled_from(TOKENS), max_size=30).map(" ".join))
def test_token_soup_is_diagnosed_not_crashed(text):
    _assert_diagnosed(text)


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=200))
def test_arbitrary_text_is_diagnosed_not_crashed(text):
    _assert_diagnosed(text)
