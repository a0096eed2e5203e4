"""A fuzz of what aou reads: `.aou` numbers at the float limits, malformed and oversized
recordings (CSV, JSON, NPZ), special files, robot files (URDF trees and sizes, TOML depth
and types). The generators (tests/inputgen.py) are written from the promises.

Every command run must: exit 1 or 2 with a diagnostic code printed, print no traceback
and no "internal error", use at most 30 s of processor time and end within 90 s of wall
time (the machine may be shared), stay within 2 GB of address space, change no input and
leave no temporary file. In-process runs must raise nothing but AouError.

The default run is bounded (a seeded sample); the slow run takes every case and many
more generated files.
"""

import os
import random
import re
from pathlib import Path

import pytest

from aou_dsl.core.diagnostics import RULES, AouError
from tests import inputgen as gen

SEED = 27
CODE = re.compile(r"\b([SVMCRI]\d{3})\b")


def _all_cases() -> list[gen.Case]:
    return (gen.special_cases() + gen.recording_cases() + gen.robot_cases()
            + gen.clock_cases())


#: Cases of the default run: the special files (where a hang would be), and a seeded
#: sample of the others.
def _default_cases() -> list[gen.Case]:
    rng = random.Random(SEED)
    special = [c for c in gen.special_cases() if c.name in (
        "fifo.csv-measure", "fifo.aou-compile", "zero.json-measure", "urandom.npz-measure",
        "zero.urdf-robot", "fifo-robot")]
    others = rng.sample(gen.recording_cases(), 5) + rng.sample(gen.robot_cases(), 3)
    return special + others


def _valid_exit(case: gen.Case) -> set[int]:
    """Commands on a file aou reads but need not refuse (a huge episode list is left
    out; a clock that does not start at 0 is checked) may succeed."""
    return {0, 1, 2} if case.name.startswith(("json-episodes", "json-plot", "check-t-")) \
        else {1, 2}


def _run(case: gen.Case, tmp_path: Path) -> None:
    folder = tmp_path / "in"
    folder.mkdir()
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    argv = gen.materialise(case, str(folder))
    before = gen.snapshot(str(folder))
    rc, out = gen.run_cli(argv, {**case.env, "TMPDIR": str(tmp)})
    assert rc is not None, f"{case.name}: no answer within 90 s"
    assert "Traceback" not in out and "internal error" not in out, (case.name, out[-2000:])
    assert rc in _valid_exit(case), (case.name, rc, out[-1000:])
    if rc:
        codes = set(CODE.findall(out))
        assert codes and codes <= set(RULES), (case.name, out[-1000:])
        assert re.search(r":\d+:\d+: [SVMCRI]\d{3} ", out), (case.name, out[-1000:])
    after = gen.snapshot(str(folder))
    assert {p: v for p, v in after.items() if p in before} == before, case.name
    assert os.listdir(tmp) == [], (case.name, os.listdir(tmp))


@pytest.mark.parametrize("case", _default_cases(), ids=lambda c: c.name)
def test_a_sample_of_hostile_inputs_fails_cleanly(case, tmp_path):
    _run(case, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("case", _all_cases(), ids=lambda c: c.name)
def test_every_hostile_input_fails_cleanly(case, tmp_path):
    _run(case, tmp_path)


def _lint_then_compile(texts: list[str], compiles: int, tmp_path: Path) -> None:
    """Lint never raises; a diagnostic always has a registered code and a span on its
    file; the first ``compiles`` files that lint clean compile without raising."""
    from aou_dsl.driver.builder import build_source
    from aou_dsl.lang.linter import lint_source

    left = compiles
    for k, text in enumerate(texts):
        result = lint_source(text, "f.aou")
        assert all(d.code in RULES and d.span.line >= 1 for d in result.diagnostics), text
        clean = not any(d.severity == "error" for d in result.diagnostics)
        if clean and left > 0:
            left -= 1
            res = build_source(text, str(tmp_path / f"f{k}.aou"))
            assert all(d.code in RULES for d in res.diagnostics), text


def test_aou_numbers_at_the_float_limits(tmp_path):
    """400 files of numbers at and around the float limits (and look-alike digits)."""
    texts = gen.aou_numbers(random.Random(SEED), 400)
    assert any("1e308" in t for t in texts) and any("1e-155" in t for t in texts)
    _lint_then_compile(texts, 2, tmp_path)


@pytest.mark.slow
def test_many_aou_numbers_at_the_float_limits(tmp_path):
    _lint_then_compile(gen.aou_numbers(random.Random(SEED + 1), 3000), 25, tmp_path)


def _bases() -> dict[str, bytes]:
    import json

    t, q = gen.motion()
    return {"csv": gen.csv_bytes(t, q), "json": json.dumps(gen.json_doc(t, q)).encode(),
            "npz": gen.npz_of(t, q)}


def _read_mutants(count: int, seed: int, tmp_path: Path) -> int:
    """Read ``count`` mutated recordings; each reads or is an AouError with registered
    codes. Returns how many were refused."""
    import io
    import zipfile

    from aou_dsl.measuring.recording import read_recording

    rng = random.Random(seed)
    bases = _bases()
    refused = 0
    for k in range(count):
        fmt = rng.choice(sorted(bases))
        if fmt == "npz":  # mutate one member, keep the zip readable
            with zipfile.ZipFile(io.BytesIO(bases["npz"])) as zf:
                members = {n: zf.read(n) for n in zf.namelist()}
            name = rng.choice(sorted(members))
            members[name] = gen.mutate_recording(rng, members[name])
            data = gen.npz_bytes(members)
        else:
            data = gen.mutate_recording(rng, bases[fmt])
        path = tmp_path / f"m{k}.{fmt}"
        path.write_bytes(data)
        try:
            read_recording(str(path), robot="panda")
        except AouError as err:
            assert err.diagnostics and all(d.code in RULES for d in err.diagnostics)
            refused += 1
        path.unlink()
    return refused


@pytest.mark.filterwarnings("error::RuntimeWarning")  # numpy's warnings are no diagnostic
def test_mutated_recordings_read_or_are_refused(tmp_path):
    assert _read_mutants(150, SEED, tmp_path) > 0


@pytest.mark.slow
@pytest.mark.filterwarnings("error::RuntimeWarning")
def test_many_mutated_recordings_read_or_are_refused(tmp_path):
    assert _read_mutants(1500, SEED + 1, tmp_path) > 0
