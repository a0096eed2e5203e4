"""The shape of the code: small functions and modules, one definition of each
descriptor, a package that imports fast, and a rule registry whose examples are true."""

import re
import shlex
import subprocess
import sys

import pytest

from aou_dsl.core.diagnostics import RULES
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.lang.linter import lint_source
from tests.conftest import ROOT

PACKAGE = ROOT / "aou_dsl"
MAX_MODULE_LINES = 420


def test_no_function_is_more_complex_than_twenty():
    """ruff's McCabe check (C901) at 20 finds nothing in the package."""
    out = subprocess.run([sys.executable, "-m", "ruff", "check", "--select", "C901",
                          "--config", "lint.mccabe.max-complexity=20", "--no-cache",
                          str(PACKAGE)], capture_output=True, text=True)
    assert out.returncode == 0, out.stdout


def test_ruff_finds_nothing():
    """The project's ruff rules (pyproject.toml) hold over the package, tests and benchmarks."""
    out = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", str(PACKAGE),
                          str(ROOT / "tests"), str(ROOT / "benchmarks")],
                         capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stdout


@pytest.mark.slow
def test_mypy_finds_nothing():
    """The package type-checks under the project's mypy settings (pyproject.toml)."""
    out = subprocess.run([sys.executable, "-m", "mypy", str(PACKAGE)], capture_output=True,
                         text=True, cwd=ROOT)
    assert out.returncode == 0, out.stdout


@pytest.mark.parametrize("path", sorted(PACKAGE.rglob("*.py")), ids=lambda p: p.name)
def test_modules_stay_small(path):
    """No module of the package is over ~400 lines."""
    n = len(path.read_text().splitlines())
    assert n <= MAX_MODULE_LINES, f"{path.relative_to(ROOT)} has {n} lines"


@pytest.mark.parametrize("name", list(REGISTRY))
def test_each_descriptor_is_named_in_at_most_two_modules(name):
    """A descriptor is defined once (the registry); at most one other module names it."""
    where = [p for p in PACKAGE.rglob("*.py") if re.search(rf"\b{name}\b", p.read_text())]
    assert len(where) <= 2, [str(p.relative_to(ROOT)) for p in where]


def _lint_codes(text: str) -> set[str]:
    return {d.code for d in lint_source(text, "example.aou").diagnostics}


FRONT_END = [c for c in RULES if c[0] in "SVM" and not RULES[c].example.startswith("aouc ")]


@pytest.mark.parametrize("code", FRONT_END)
def test_each_front_end_rule_example_triggers_its_own_code(code):
    """`aouc rules CODE` shows an example; linting it reports that very code."""
    assert code in _lint_codes(RULES[code].example), RULES[code].example


#: Compiler codes no file has been found to reach: the IK's damping and limits report
#: C301/C302 first, and TOPP-RA has not failed on a path the front end lets through.
#: C311 is the controller's check of a trajectory file (``aouc check``); a compiled one
#: keeps within the jerk limits by construction (tests/integration/test_jerk.py has both sides).
UNREACHED = {"C303", "C305", "C311"}
#: Codes said only when a build fits the behaviour to the arm (``--fit``).
FIT_CODES = {"C314", "C315"}
#: Codes said only by ``aouc check`` (inverse dynamics, the physics replay, --track):
#: tests/integration/test_torque.py and tests/integration/test_track.py reach each.
CHECK_CODES = {"C320", "C321", "C322", "C323"}


@pytest.mark.slow
@pytest.mark.parametrize("code", [pytest.param(c, marks=pytest.mark.xfail(
    strict=True, reason="no input known to reach it")) if c in UNREACHED else c
    for c in RULES if c[0] == "C" and c not in CHECK_CODES])
def test_each_compiler_rule_example_triggers_its_own_code(code, tmp_path, monkeypatch):
    """A C-rule's example lints clean of errors and then fails (or warns) in compile
    with that very code. An example naming a robot file gets one: the Panda's URDF
    with its collision shapes removed."""
    import re

    from aou_dsl.driver.builder import build_source
    from aou_dsl.robot.load import scene_urdf

    example = RULES[code].example
    for name in re.findall(r'robot "([^"]+)"', example):
        text = open(scene_urdf("panda")).read()
        (tmp_path / name).write_text(re.sub(r"<collision>.*?</collision>", "", text,
                                            flags=re.S))
    monkeypatch.chdir(tmp_path)
    res = build_source(example, str(tmp_path / "example.aou"), fit=code in FIT_CODES)
    assert code in {d.code for d in res.diagnostics}, (example, [
        (d.code, d.message) for d in res.diagnostics])


def _fixtures(folder) -> None:
    """The files the command examples name, made as their comments describe them."""
    import numpy as np

    from tests.inputgen import json_doc, motion, npy_claiming, npz_of, panda_urdf

    (folder / "empty").mkdir()
    (folder / "a.aou").write_text("pause 1s\n")
    (folder / "huge.aou").write_text("pause 1s\n" + "# padding\n" * 210_000)  # 2.1 MB
    escape = re.sub(r'filename="package://[^"]*"',
                    'filename="package://arm/../../../etc/passwd"', panda_urdf(), count=1)
    (folder / "escape.urdf").write_text(escape)
    t, q = motion()
    assert json_doc(t, q)["robot"] == "panda"
    (folder / "huge.npz").write_bytes(npz_of(t, q, q_npy=npy_claiming((10**9, 7))))
    assert np.isfinite(q).all()


@pytest.mark.parametrize("code", [c for c in RULES if c[0] in "RI" or c[0] == "V"
                                  and RULES[c].example.startswith("aouc ")])
def test_each_reading_and_usage_rule_example_triggers_its_own_code(code, tmp_path, capsys,
                                                                    monkeypatch):
    """R and I examples (and V examples that are commands on robot files or large files)
    are inputs or commands; running them reports that very code."""
    from aou_dsl.cli.commands import main

    example = RULES[code].example
    if example.startswith("aouc "):
        _fixtures(tmp_path)
        argv = shlex.split(example, comments=True)[1:]
    elif example.startswith("{"):
        (tmp_path / "x.json").write_text(example)
        argv = ["measure", str(tmp_path / "x.json")]
    elif example.startswith("t,"):
        rows = example.strip().splitlines()[1:]
        more = "" if len(rows) >= 3 else "\n0,0\n0.1,0\n0.2,0"  # samples enough to measure
        (tmp_path / "x.csv").write_text(example + more + "\n")
        argv = ["measure", str(tmp_path / "x.csv"), "--robot", "panda", "--goal", "0.5,0,0.3"]
    else:
        pytest.skip(f"{code}'s example is measured in test_measure.py")
    monkeypatch.chdir(tmp_path)
    main(argv)
    out = capsys.readouterr()
    err = out.err + out.out  # lint reports on stdout, the other commands on stderr
    assert f" {code} " in err or f"{code} [" in err, err
