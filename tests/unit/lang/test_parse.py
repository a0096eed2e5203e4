"""Stage 1: the grammar and the syntax tree."""

import pytest

from aou_dsl.core.diagnostics import AouError
from aou_dsl.lang.parse import (
    KeyVal,
    Quantity,
    SequenceBlock,
    Statement,
    Vector,
    Word,
    build_parser,
    parse,
)


def test_grammar_has_no_conflicts_in_strict_mode():
    """Lark's strict mode rejects shift/reduce conflicts and terminal collisions."""
    build_parser(strict=True)


def test_semicolons_and_newlines_both_end_statements():
    """`a; b` and `a\\nb` give the same statements."""
    one = parse("approach a=0.05; pause 1.67s x5; retreat 0.06m a=0.12 x3")
    many = parse("approach a=0.05\npause 1.67s x5\n\n retreat 0.06m a=0.12 x3\n")
    assert [s.keyword for s in one.items] == ["approach", "pause", "retreat"]
    assert [s.keyword for s in many.items] == ["approach", "pause", "retreat"]


def test_comments_run_to_end_of_line():
    tree = parse("# header comment\npause 1s # trailing\n# only a comment")
    assert len(tree.items) == 1
    assert [a.text for a in tree.items[0].args] == ["1s"]


def test_empty_file_parses():
    assert parse("").items == ()
    assert parse("\n# nothing\n;;\n").items == ()


@pytest.mark.parametrize("text,value,unit", [
    ("0.06m", 0.06, "m"), ("1e-2m", 0.01, "m"), ("-20deg", -20.0, "deg"),
    ("0.12m/s^2", 0.12, "m/s^2"), ("4Hz", 4.0, "Hz"), ("+.5s", 0.5, "s"), ("3", 3.0, ""),
])
def test_quantities_split_into_number_and_unit(text, value, unit):
    (st,) = parse(f"start {text}").items
    (q,) = st.args
    assert isinstance(q, Quantity)
    assert q.value == pytest.approx(value) and q.unit == unit


def test_every_node_knows_its_span():
    """Spans are 1-based line:col of the token, end exclusive."""
    tree = parse("pause 1s\n  retreat 6cm a=0.12 x3", "f.aou")
    st = tree.items[1]
    assert isinstance(st, Statement)
    assert (st.keyword_span.line, st.keyword_span.col) == (2, 3)
    q, kv, rep = st.args
    assert (q.span.line, q.span.col, q.span.end_col) == (2, 11, 14)
    assert isinstance(kv, KeyVal) and kv.key == "a" and kv.span.col == 15
    assert isinstance(rep, Word) and rep.text == "x3"


def test_sequence_block_and_vector():
    tree = parse("goal (0.5, 0, 0.3m)\nsequence {\n approach 0.08m\n pause 1s\n}")
    goal, seq = tree.items
    assert isinstance(goal.args[0], Vector)
    assert [q.value for q in goal.args[0].items] == [0.5, 0.0, 0.3]
    assert isinstance(seq, SequenceBlock)
    assert [s.keyword for s in seq.statements] == ["approach", "pause"]
    assert seq.span.line == 2 and seq.span.end_line == 5


def _error(text: str):
    with pytest.raises(AouError) as info:
        parse(text, "x.aou")
    (d,) = info.value.diagnostics
    return d


def test_unexpected_token_names_what_was_found():
    d = _error("pause 1.67s x5 )")
    assert d.code == "S001" and (d.span.line, d.span.col) == (1, 16)
    assert "`)`" in d.message


def test_end_of_file_error_points_at_last_character():
    """Lark reports EOF at line -1; aou maps it to the last character of the file."""
    d = _error("sequence {\n  approach a=0.09")
    assert d.code == "S002"
    assert (d.span.line, d.span.col) == (2, 17)
    assert "}" in d.hint


def test_unknown_character():
    d = _error("pause @5")
    assert d.code == "S003" and d.span.col == 7 and "@" in d.message
