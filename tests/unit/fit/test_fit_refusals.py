"""The compiler's refusals are typed: each refusal the fit and the hints read carries its
record (``Diagnostic.refusal``), and the diagnostic's JSON ``fields`` are that record's
values, in its order, so a script reading the JSON reads what it read before."""

from __future__ import annotations

import dataclasses

import pytest

from aou_dsl.driver.builder import build_source
from aou_dsl.fit.refusals import (
    AccelerationShort,
    ShiverTooFast,
    StartUnreachable,
    TiltTooFast,
    Unreachable,
)

CASES = [
    # a wrist too slow for a 12 Hz shiver
    ("behaviour s\nrobot panda\npause 1s\nshiver 6deg f=12Hz for 1s\n", "C308",
     ShiverTooFast, ["joint", "limit", "max_frequency", "duration", "f"]),
    # a tilt faster than the wrist turns
    ("behaviour t\nrobot z1\npause 1s\ntilt 40deg v=2000deg/s\n", "C309", TiltTooFast,
     ["joint", "limit", "max_velocity", "declared_velocity"]),
    # an approach the joints cannot accelerate so hard
    ("behaviour a\nrobot panda\napproach a=30\npause 1s\n", "C304", AccelerationShort,
     ["joint", "achieved", "declared", "descriptor"]),
    # a gaze beyond the small arm's reach
    ("behaviour c : curious\nrobot z1\napproach a=0.09\npause 1.25s x3\n"
     "gaze vertical 60deg\n", "C30", Unreachable, ["reason", "time", "joint"]),
    # a start pose beyond reach
    ("behaviour f\nrobot z1\nstart 1m\npause 1s\n", "C30", StartUnreachable,
     ["reason", "time", "joint", "start"]),
]


@pytest.mark.parametrize(("text", "code", "kind", "keys"), CASES)
def test_a_refusal_carries_its_record_and_its_fields_are_the_records(text, code, kind,
                                                                    keys):
    res = build_source(text, "r.aou", check=False)
    d = next(x for x in res.diagnostics if x.code.startswith(code))
    assert type(d.refusal) is kind, (d.code, d.message, d.refusal)
    assert list(d.to_json()["fields"])[:len(keys)] == keys
    assert {k: d.fields[k] for k in keys} == dataclasses.asdict(d.refusal)


def test_what_the_fit_found_is_typed_and_is_its_fields():
    """The reach fit's changes and the hint's edits (a retreat too far for the small
    arm) are the refusal's typed answer; the JSON fields say the same, after the
    refusal's."""
    from aou_dsl.fit.refusals import Answer

    text = ("behaviour f : fearful\nrobot z1\napproach a=0.1\npause 1.25s x4\n"
            "retreat 0.3m a=2\nshiver 6deg f=1.1Hz for 2.73s\n")
    res = build_source(text, "r.aou", check=False)
    d = next(x for x in res.diagnostics if isinstance(x.refusal, Unreachable))
    assert type(d.answer) is Answer and d.answer.offered and d.answer.edits, d.answer
    assert list(d.fields)[:3] == ["reason", "time", "joint"]
    assert list(d.fields)[-3:] == ["reach", "edits", "edits_complete"]
    assert d.fields["reach"] == list(d.answer.offered)
    assert d.fields["edits"] == list(d.answer.edits)
    assert d.fields["edits_complete"] is d.answer.edits_complete
