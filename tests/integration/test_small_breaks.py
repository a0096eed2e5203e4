"""Smaller breaks a user met, each as it was met: a missing extra said as one, a figure of
a document whose strings are not text, messages that quote the file's line."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from aou_dsl.cli.commands import main
from tests.conftest import BEHAVIOURS
from tests.generated.test_fuzz_outputs import _workspace


def test_cluster_without_its_extra_names_the_extra(tmp_path, monkeypatch, capsys):
    """--cluster where Dask distributed is not installed: the message every other
    missing extra gets (exit 2), not an internal error."""
    monkeypatch.setitem(sys.modules, "distributed", None)  # `import distributed` fails
    out = tmp_path / "c.json"
    code = main(["compile", str(BEHAVIOURS / "inactive.aou"), "--no-check", "--cluster",
                 "tcp://127.0.0.1:1", "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "internal error" not in err, err
    assert "needs the cluster extra" in err and "pip install '.[cluster]'" in err, err
    assert not out.exists()


@pytest.mark.parametrize("field", ["behaviour", "episodes"])
def test_plot_of_strings_that_are_not_text_is_r401(tmp_path, monkeypatch, capsys, field):
    monkeypatch.chdir(tmp_path)
    _workspace(tmp_path)
    doc = json.loads(Path("t.json").read_text())
    if field == "behaviour":
        doc["behaviour"] = "a\ud800b"
    else:
        doc["episodes"] = [{"kind": "pause\udfff", "t_start": 0.0, "t_end": 0.5}]
    Path("s.json").write_text(json.dumps(doc))  # json writes "\ud800" as an escape
    code = main(["plot", "s.json", "-o", "s.png"])
    err = capsys.readouterr().err
    assert "internal error" not in err and "Traceback" not in err, err
    assert code == 1 and " R401 [error]" in err and "lone surrogate" in err, err
    assert not Path("s.png").exists()


def test_fit_messages_say_the_quoted_line_is_the_fitted_text(tmp_path, capsys):
    """A --fit build quotes the fitted text under its messages; where it differs from
    the file's line it says so, with the file's own line. (Fearful with a 4 Hz shiver, on
    a UR5 whose wrist follows it at 2.8 Hz, still a tremor.)"""
    src = tmp_path / "fearful.aou"
    src.write_text((BEHAVIOURS / "fearful.aou").read_text().replace(
        "shiver 6deg for 1.25s", "shiver 6deg f=4Hz for 0.8s"))
    arm = tmp_path / "ur5.toml"
    arm.write_text('robot = "ur5"\njoint_accel = [5, 5, 5, 5, 5, 18]\n')
    assert main(["compile", str(src), "--robot", str(arm), "--fit", "--no-check", "-o",
                 str(tmp_path / "f.json")]) == 0
    err = capsys.readouterr().err
    lines = err.splitlines()
    quoted = [i for i, x in enumerate(lines) if x.startswith("   7 | ")]
    assert quoted and all("a=1.437" in lines[i] for i in quoted), err
    for i in quoted:  # each quote of the fitted line says what the file's line is
        assert lines[i + 2] == ("     = the line as fitted, above; the file's line 7 says "
                                "`retreat 0.06m a=2`"), err
    assert main(["check", str(src), "--robot", str(arm), "--fit", "--no-dynamic"]) in (0, 1)
    err = capsys.readouterr().err
    assert "the file's line 8 says `shiver 6deg f=4Hz for 0.8s`" in err, err


def test_against_places_declared_absent_failures_at_the_header(tmp_path, capsys):
    """A descriptor the file declares absent is said at its header (the file's first
    lines are comments), or without one at its first statement: never 1:1."""
    traj = tmp_path / "h.json"
    assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "--no-check", "-o",
                 str(traj)]) == 0
    text = (BEHAVIOURS / "hesitant.aou").read_text()
    no_retreat = "".join(x for x in text.splitlines(True) if not x.startswith("retreat"))
    (tmp_path / "nr.aou").write_text(no_retreat)
    (tmp_path / "nh.aou").write_text("".join(
        x for x in no_retreat.splitlines(True) if not x.startswith("behaviour")))
    header = no_retreat.splitlines().index("behaviour hesitant : hesitant") + 1
    first = [x.split()[0] if x.strip() else "" for x in
             (tmp_path / "nh.aou").read_text().splitlines()].index("approach") + 1
    for name, line in (("nr.aou", header), ("nh.aou", first)):
        capsys.readouterr()
        assert main(["measure", str(traj), "--against", str(tmp_path / name), "--format",
                     "json"]) == 1
        doc = json.loads(capsys.readouterr().out)
        absent = [d for d in doc["diagnostics"] if d["code"] == "R408"
                  and d["fields"]["descriptor"].startswith("retreat")]
        assert len(absent) == 3, doc["diagnostics"]
        assert {d["line"] for d in absent} == {line}, absent


def _setup_blocks() -> list[str]:
    from tests.conftest import ROOT

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Set-up: two commands", 1)[1].split("\n## ", 1)[0]
    return [b.strip() for b in section.split("```")[1::2]]


def test_the_readme_set_up_makes_a_virtual_environment_first():
    """Debian's Python refuses `pip install .` outside a virtual environment (PEP 668):
    the set-up makes and activates one before its two commands, which stay as they
    were."""
    venv, install, tests = _setup_blocks()
    assert venv == "python3 -m venv .venv && . .venv/bin/activate"
    assert install == ("pip install . && aouc compile behaviours/hesitant.aou -o "
                       "hesitant.json && aouc measure hesitant.json")
    assert tests == 'pip install ".[test]" && python -m pytest -q'


@pytest.mark.slow
def test_the_readme_virtual_environment_command_works(tmp_path):
    """The command, run as written by a shell: the environment's Python is the one
    that runs afterwards, with its own pip."""
    import subprocess

    venv = _setup_blocks()[0]
    done = subprocess.run(["bash", "-c", f"{venv} && python -c 'import sys; "
                           "print(sys.prefix)' && pip --version"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    prefix, pip = done.stdout.splitlines()[:2]
    assert prefix == str(tmp_path / ".venv") and str(tmp_path / ".venv") in pip
