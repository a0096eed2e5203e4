"""Round trip over the whole language, checked against what the compiler did not make.

The default run takes 200 generated files, the slow run 1000 (``-m slow``); ``python
tests/hunt.py`` reports the same over any number of files, with the refusals by code.

Files come from ``langgen`` (written from the language contract and the model's
definitions), trajectories are read back by ``oracle`` (forward kinematics of its own,
no compiler code). The promise under test: every file the linter accepts compiles to a
trajectory whose measured descriptors equal the declared ones.
"""

from __future__ import annotations

import functools
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings

from . import langgen
from .hunt import Outcome, cli, run_case

DEFAULT_N, DEFAULT_SEED = 200, 44
SLOW_N, SLOW_SEED = 1000, 12
MAX_REFUSED = 0.10

_WORK = Path(tempfile.mkdtemp(prefix="aou-roundtrip-"))

#: The per-file tests of a sweep and its refusal share run on one worker (pytest-xdist),
#: where the share reads the outcomes the per-file tests left in ``_outcome``'s cache.
DEFAULT_SWEEP = pytest.mark.xdist_group("lang_roundtrip-default")
SLOW_SWEEP = pytest.mark.xdist_group("lang_roundtrip-slow")


@functools.cache
def _cases(n: int, seed: int) -> tuple[langgen.Case, ...]:
    return tuple(langgen.random_cases(n, seed))


@functools.cache
def _outcome(n: int, seed: int, i: int) -> Outcome:
    return run_case(_cases(n, seed)[i], _WORK / f"s{seed}")


def _explain(o: Outcome) -> str:
    found = "\n".join(f"  - {d}" for d in o.certain) or "  (none)"
    return f"{o.case.stem} ({o.case.robot}):\n{o.case.text}\ndisagreements:\n{found}\n{o.crash}"


def _check_one(o: Outcome) -> None:
    assert o.status != "crash", "the tools crashed or exited 2:\n" + _explain(o)
    if o.status.endswith("refused"):
        return  # counted, with its code, by the refusal-share tests
    assert not o.certain, "the trajectory does not show what the file declares:\n" + _explain(o)


def _check_refused(n: int, seed: int) -> None:
    outs = [_outcome(n, seed, i) for i in range(n)]
    refused = [o for o in outs if o.status.endswith("refused")]
    share = len(refused) / n
    codes = sorted({c for o in refused for c in o.lint_codes + o.compile_codes})
    assert share < MAX_REFUSED, f"{share:.0%} of valid files refused (codes {codes})"


# --------------------------------------------------------------------------------------


def test_generator_covers_the_grammar():
    """A sample of 500 files uses both forms, every primitive, signed values, x0 and xN,
    every setting, a header with and without state, comments, `;`, bare keyword values
    and every unit."""
    seen: set[str] = set()
    for case in langgen.random_cases(500, seed=3):
        seen |= case.features
    required = {
        "form:descriptor", "form:sequence",
        "prim:approach", "prim:pause", "prim:retreat", "prim:gaze-h", "prim:gaze-v",
        "prim:tilt", "prim:shiver", "no-approach", "approach:rest-of-way",
        "sign:negative-approach", "sign:negative-retreat", "sign:negative-gaze",
        "sign:negative-tilt", "sign:plus",
        "count:x0", "count:x1", "count:xN", "cap:v",
        "setting:robot-panda", "setting:robot-ur5", "setting:robot-default", "setting:goal",
        "setting:from", "setting:start", "setting:standoff", "setting:effort",
        "header:state", "header:nostate", "header:none", "comment", "semicolon",
        "bare:accel", "bare:speed", "bare:angspeed", "bare:freq", "unit:exponent",
    }
    required |= {f"unit:{u}" for units in langgen.UNITS.values() for u in units}
    missing = required - seen
    assert not missing, f"never generated: {sorted(missing)}"


def test_generated_expectations_are_complete():
    """Every expectation names the eleven descriptors, and only those are marked open."""
    for case in langgen.random_cases(200, seed=4):
        exp = case.expectation
        assert set(exp.values) == set(langgen.DESCRIPTORS)
        assert set(exp.uncertain) <= set(langgen.DESCRIPTORS)
        assert exp.values["pause_count"] is not None


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(langgen.aou_cases())
def test_lint_never_crashes_on_valid_files(case):
    """Linting any generated file ends with exit 0 or 1, never a crash or a usage error."""
    path = _WORK / "hyp" / f"{case.stem}.aou"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(case.text)
    rc, out = cli(["lint", "--format", "json", str(path)])
    assert rc in (0, 1), f"lint exit {rc} on\n{case.text}\n{out[-2000:]}"


@DEFAULT_SWEEP
@pytest.mark.parametrize("i", range(DEFAULT_N))
def test_compiled_file_shows_what_it_declares(i):
    """A generated file compiles without crashing, and the oracle's reading, the
    document's measured and its declared descriptors all equal the file's declaration."""
    _check_one(_outcome(DEFAULT_N, DEFAULT_SEED, i))


@DEFAULT_SWEEP
def test_few_valid_files_are_refused():
    """Fewer than 10% of valid generated files are refused by lint or compile."""
    _check_refused(DEFAULT_N, DEFAULT_SEED)


@pytest.mark.slow
@SLOW_SWEEP
@pytest.mark.parametrize("i", range(SLOW_N))
def test_compiled_file_shows_what_it_declares_bulk(i):
    """The same round trip over 1000 seeded files."""
    _check_one(_outcome(SLOW_N, SLOW_SEED, i))


@pytest.mark.slow
@SLOW_SWEEP
def test_few_valid_files_are_refused_bulk():
    """Fewer than 10% of 1000 valid generated files are refused by lint or compile."""
    _check_refused(SLOW_N, SLOW_SEED)
