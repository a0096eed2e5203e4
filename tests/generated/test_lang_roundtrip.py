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
import json
import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings

from tests import langgen
from tests.hunt import Outcome, cli, run_case

DEFAULT_N, DEFAULT_SEED = 200, 44
SLOW_N, SLOW_SEED = 1000, 12
MAX_REFUSED = 0.10


@functools.cache
def _cases(n: int, seed: int) -> tuple[langgen.Case, ...]:
    return tuple(langgen.random_cases(n, seed))


class Sweep:
    """The outcomes of a seeded sweep of generated files, each found once per run.

    A file is linted and compiled in this process's own folder (``work``); what a
    refusal-share test needs of it (status and codes) is also recorded in ``records``,
    one folder for the whole run that every pytest-xdist worker shares. The per-file
    tests spread over the workers, so the share reads the outcomes the other worker
    found instead of compiling those files again; a file nobody has compiled yet it
    compiles itself, so the share never depends on the order the tests ran in."""

    def __init__(self, work: Path, records: Path) -> None:
        self.work, self.records = work, records
        self._found: dict[tuple[int, int, int], Outcome] = {}

    def outcome(self, n: int, seed: int, i: int) -> Outcome:
        """File ``i`` of the sweep, linted, compiled and read back (and recorded)."""
        key = (n, seed, i)
        if key not in self._found:
            found = run_case(_cases(n, seed)[i], self.work / f"s{seed}")
            self._record(key, {"status": found.status,
                               "codes": found.lint_codes + found.compile_codes})
            self._found[key] = found
        return self._found[key]

    def refusal(self, n: int, seed: int, i: int) -> dict:
        """File ``i``'s status and codes, from the record any worker left, or found now."""
        path = self._path((n, seed, i))
        if path.is_file():
            return json.loads(path.read_text())
        found = self.outcome(n, seed, i)
        return {"status": found.status, "codes": found.lint_codes + found.compile_codes}

    def _path(self, key: tuple[int, int, int]) -> Path:
        return self.records / "{}-{}-{}.json".format(*key)

    def _record(self, key: tuple[int, int, int], what: dict) -> None:
        """Written whole (a temporary name, then renamed): the other worker may read it."""
        path = self._path(key)
        part = path.with_name(f"{path.name}.{os.getpid()}.part")
        part.write_text(json.dumps(what))
        os.replace(part, path)


@pytest.fixture(scope="session")
def sweep(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Sweep:
    """The sweeps' folders. Session-scoped: a module-scoped fixture would put all the
    module's tests on one worker (tests/conftest.py keeps those together). On a
    pytest-xdist worker the base temporary folder is the worker's own; its parent, the
    run's, shared by the workers, holds the records."""
    base = tmp_path_factory.getbasetemp()
    shared = base.parent if hasattr(request.config, "workerinput") else base
    records = shared / "lang-roundtrip-records"
    records.mkdir(exist_ok=True)
    return Sweep(tmp_path_factory.mktemp("lang-roundtrip"), records)


def _explain(o: Outcome) -> str:
    found = "\n".join(f"  - {d}" for d in o.certain) or "  (none)"
    return f"{o.case.stem} ({o.case.robot}):\n{o.case.text}\ndisagreements:\n{found}\n{o.crash}"


def _check_one(o: Outcome) -> None:
    assert o.status != "crash", "the tools crashed or exited 2:\n" + _explain(o)
    if o.status.endswith("refused"):
        return  # counted, with its code, by the refusal-share tests
    assert not o.certain, "the trajectory does not show what the file declares:\n" + _explain(o)


def _check_refused(sweep: Sweep, n: int, seed: int) -> None:
    outs = [sweep.refusal(n, seed, i) for i in range(n)]
    refused = [o for o in outs if o["status"].endswith("refused")]
    share = len(refused) / n
    codes = sorted({c for o in refused for c in o["codes"]})
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
def test_lint_never_crashes_on_valid_files(sweep, case):
    """Linting any generated file ends with exit 0 or 1, never a crash or a usage error."""
    path = sweep.work / "hyp" / f"{case.stem}.aou"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(case.text)
    rc, out = cli(["lint", "--format", "json", str(path)])
    assert rc in (0, 1), f"lint exit {rc} on\n{case.text}\n{out[-2000:]}"


@pytest.mark.parametrize("i", range(DEFAULT_N))
def test_compiled_file_shows_what_it_declares(sweep, i):
    """A generated file compiles without crashing, and the oracle's reading, the
    document's measured and its declared descriptors all equal the file's declaration."""
    _check_one(sweep.outcome(DEFAULT_N, DEFAULT_SEED, i))


def test_few_valid_files_are_refused(sweep):
    """Fewer than 10% of valid generated files are refused by lint or compile."""
    _check_refused(sweep, DEFAULT_N, DEFAULT_SEED)


@pytest.mark.slow
@pytest.mark.parametrize("i", range(SLOW_N))
def test_compiled_file_shows_what_it_declares_bulk(sweep, i):
    """The same round trip over 1000 seeded files."""
    _check_one(sweep.outcome(SLOW_N, SLOW_SEED, i))


@pytest.mark.slow
def test_few_valid_files_are_refused_bulk(sweep):
    """Fewer than 10% of 1000 valid generated files are refused by lint or compile."""
    _check_refused(sweep, SLOW_N, SLOW_SEED)
