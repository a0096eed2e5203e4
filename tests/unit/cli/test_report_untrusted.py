"""``aouc measure``'s text marks a value R411 says not to trust on its own line, and the
C-V point read from it: the warning goes to standard error, and a table copied without
it must not pass a guess off as a measurement."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from aou_dsl import api
from aou_dsl.cli.report import format_measured
from aou_dsl.measuring.measured import measure

HESITANT = Path(__file__).resolve().parents[3] / "behaviours" / "hesitant.aou"
MARK = "not to be trusted"


@pytest.fixture(scope="module")
def measured():
    return measure(api.compile(str(HESITANT)).trajectory)


def _line(text: str, name: str) -> str:
    return next(ln for ln in text.splitlines() if ln.split()[:1] == [name])


def test_a_trusted_measurement_carries_no_mark(measured):
    text = format_measured("h.json", "panda", measured)
    assert all(s.stable for s in measured.uncertainty.values())
    assert MARK not in text


def test_an_untrusted_value_is_marked_and_so_is_the_point_read_from_it(measured):
    name = "approach_acceleration"
    assert measured.descriptors[name] is not None
    spreads = dict(measured.uncertainty)
    spreads[name] = replace(spreads[name], stable=False)
    text = format_measured("h.json", "panda", replace(measured, uncertainty=spreads))
    assert _line(text, name).endswith(MARK)
    others = [k for k, v in measured.descriptors.items() if k != name]
    assert not any(_line(text, k).endswith(MARK) for k in others)
    point = next(ln for ln in text.splitlines() if "C-V:" in ln)
    assert point.endswith(f"read from values {MARK} ({name})")


def test_an_absent_value_is_not_marked_though_its_presence_is_unstable(measured):
    name = next(k for k, v in measured.descriptors.items() if v is None)
    spreads = dict(measured.uncertainty)
    spreads[name] = replace(spreads[name], stable=False)
    text = format_measured("h.json", "panda", replace(measured, uncertainty=spreads))
    assert MARK not in _line(text, name) and MARK not in text
