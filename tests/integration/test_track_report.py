"""What `aouc check --track` tells a user: how much of each descriptor at risk the arm
shows under each servo mode and which modes keep it, for a behaviour fitted to the arm
too (the file's values beside the fitted ones); where the arm refuses the file, the
command that tracks the fitted motion; the same report from the same plan."""

import json
import re

import numpy as np
import pytest

pytest.importorskip("mujoco")

from aou_dsl.cli.commands import EXIT_OK, main  # noqa: E402
from tests.conftest import BEHAVIOURS, ROOT  # noqa: E402

FEARFUL = str(BEHAVIOURS / "fearful.aou")
#: Hesitant with a small fast tremor: the Kinova's wrist gives it only narrower and
#: slower, still a tremor (2.5 Hz) and still hesitant, so ``--fit`` fits it. (Fearful's
#: 6 deg shiver it cannot give at a tremor's rate wide enough to stay fearful.)
TREMBLE = """behaviour tremble : hesitant
robot panda
start 0.30m
standoff 0.10m

approach a=0.05
pause 1.67s x5
retreat 0.06m a=0.12 x3
shiver 2deg f=5Hz for 1s
"""


@pytest.fixture(scope="module")
def tremble(tmp_path_factory) -> str:
    path = tmp_path_factory.mktemp("track") / "tremble.aou"
    path.write_text(TREMBLE)
    return str(path)


def fitted(path: str) -> list[str]:
    """The fitted check, as the refusal's pointer names it (the replay's slow parts off)."""
    return ["check", path, "--robot", "kinova", "--fit", "--track", "--no-dynamic",
            "--no-collision-check"]


@pytest.fixture(scope="module")
def fitted_doc(tremble):
    """One fitted compile of the tremor on the Kinova for the module."""
    import contextlib
    import io

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([*fitted(tremble), "--format", "json"])
    assert code == EXIT_OK, err.getvalue()
    return json.loads(out.getvalue())


def _written(key: str, statement: str) -> float:
    """A value as the test's file writes it (``a=0.12`` of its ``retreat`` line)."""
    line = next(ln for ln in TREMBLE.splitlines() if ln.startswith(statement))
    return float(re.search(rf"\b{key}=([0-9.]+)", line).group(1))


def test_the_fitted_report_says_what_each_mode_shows_of_each_descriptor_at_risk(fitted_doc):
    """Every descriptor some mode loses is listed with its share per mode, computed from
    that mode's own row; the modes that keep it are exactly the rows within tolerance;
    the shiver is listed; a fitted descriptor carries the file's value beside it."""
    t = fitted_doc["tracking"]
    rows = {m["mode"]: {d["descriptor"]: d for d in m["descriptors"]} for m in t["modes"]}
    risk = {a["descriptor"]: a for a in t["at_risk"]}
    assert "shiver_amplitude" in risk
    for name, a in risk.items():
        assert a["keeps"] == [m for m in rows if rows[m][name]["ok"]]
        for mode, got in a["modes"].items():
            row = rows[mode][name]
            assert got["ok"] == row["ok"] and got["measured"] == row["measured"]
            assert got["share"] == pytest.approx(row["measured"] / row["declared"], rel=1e-5)
    lost = {name for m in rows for name, d in rows[m].items() if not d["ok"]}
    assert lost <= set(risk)
    shiver = risk["shiver_amplitude"]
    assert shiver["modes"]["position"]["share"] < 0.95 and not shiver["modes"]["position"]["ok"]
    assert "feedforward" in shiver["keeps"]
    assert t["fitted"]  # the Kinova refuses the tremor as written (the test below)
    for change in t["fitted"]:  # each fitted descriptor: the file's value and the fit's
        if change["descriptor"] is None:
            continue
        a = risk[change["descriptor"]]
        assert a["declared"] == pytest.approx(float(change["fitted"]))
        assert a["written"] == pytest.approx(float(change["declared"])) != a["declared"]
    if any(c["descriptor"] == "retreat_acceleration" for c in t["fitted"]):
        assert risk["retreat_acceleration"]["written"] == _written("a", "retreat")


def test_the_fitted_text_report_names_the_slower_shiver_and_the_modes_keeping_it(
        fitted_doc, tremble, capsys):
    assert main(fitted(tremble)) == EXIT_OK
    out = capsys.readouterr().out
    for f in (c for c in fitted_doc["tracking"]["fitted"] if c["key"] == "f"):
        assert f"fitted from {f['declared']} Hz to {f['fitted']} Hz" in out
    assert "fitted to the arm before tracking" in out
    table = out[out.index("what the arm shows of each descriptor at risk"):]
    line = next(ln for ln in table.splitlines() if ln.strip().startswith("shiver_amplitude"))
    keeps = next(a["keeps"] for a in fitted_doc["tracking"]["at_risk"]
                 if a["descriptor"] == "shiver_amplitude")
    assert line.endswith(", ".join(keeps))
    for c in fitted_doc["tracking"]["fitted"]:
        if c["descriptor"] is not None:
            row = next(ln for ln in table.splitlines()
                       if ln.strip().startswith(c["descriptor"]))
            assert f"(written {float(c['declared']):.4g})" in row


def test_a_refusal_points_to_the_command_that_tracks_the_fitted_motion(tremble, capsys):
    """The tremor as written is refused on the Kinova (C308): the pointer is the exact
    command, which the tests above run and which works."""
    assert main(["check", tremble, "--robot", "kinova", "--track"]) == 1
    err = capsys.readouterr().err
    assert " C308 " in err
    assert f"aouc check {tremble} --robot kinova --fit --track" in err
    assert "line 9" in err


def test_a_refusal_the_fit_refuses_too_gets_the_fits_reason_not_a_command(capsys):
    """Fearful on the Kinova: the arm refuses its shiver (C308), and the fit cannot keep
    it a fearful tremor (C315). The note gives the fit's reason, not a command that
    would be refused."""
    assert main(["check", FEARFUL, "--robot", "kinova", "--track"]) == 1
    err = capsys.readouterr().err
    note = next(ln for ln in err.splitlines() if ln.startswith("aouc check --track"))
    assert "C315" in note and "--fit --track" not in note


def test_a_file_with_errors_of_its_own_is_not_pointed_to_fit(capsys):
    """--fit fits values to the arm; it cannot mend a file that does not lint, so a
    refusal of that kind gets no pointer to it."""
    path = ROOT / "tests" / "invalid" / "invalid_missing_unit.aou"
    assert main(["check", str(path), "--track"]) != EXIT_OK
    err = capsys.readouterr().err
    assert "--fit" not in err and "nothing to track" not in err


def test_the_same_plan_gives_the_same_report(capsys):
    """No timing in the report: two trackings of one plan print the same text and JSON."""
    from aou_dsl.cli.track_cmd import format_tracking
    from aou_dsl.core.trajectory import Trajectory
    from aou_dsl.robot.load import load_arm
    from aou_dsl.safety.track_report import track_modes

    arm = load_arm("panda")
    t = np.arange(251) / 250.0
    q = np.tile(np.array(arm.spec.posture), (len(t), 1))
    q[:, 5] += np.radians(2.0) * np.sin(2 * np.pi * t) ** 2
    tr = Trajectory(t, q, arm.joint_names, "panda", None, (0.5, 0.0, 0.3))
    a, b = track_modes(tr), track_modes(tr)
    assert format_tracking(a) == format_tracking(b)
    assert json.dumps(a.to_json()) == json.dumps(b.to_json())


def test_compile_fit_track_reports_the_files_values_beside_the_fitted_ones(
        fitted_doc, tremble, tmp_path, capsys):
    """compile --fit --track prints the same report on standard error: what the fit
    changed, and the file's value beside a fitted one."""
    out = tmp_path / "f.json"
    assert main(["compile", tremble, "--robot", "kinova", "--fit", "--track", "--no-check",
                 "-o", str(out)]) == EXIT_OK
    err = capsys.readouterr().err
    assert "fitted to the arm before tracking" in err
    (c, *_) = [c for c in fitted_doc["tracking"]["fitted"] if c["descriptor"] is not None]
    line = next(ln for ln in err.splitlines() if ln.strip().startswith(c["descriptor"])
                and "%" in ln)
    assert f"(written {float(c['declared']):.4g})" in line


def test_a_servo_without_velocity_gain_says_feedforward_changes_nothing():
    """The UR5e's published servos have no kv: the report says why its feedforward
    column equals its position column, and says nothing of the kind for the Panda."""
    from dataclasses import replace

    from aou_dsl.cli.track_cmd import format_tracking
    from aou_dsl.core.servo_specs import PANDA
    from aou_dsl.core.trajectory import Trajectory
    from aou_dsl.robot.load import load_arm
    from aou_dsl.safety.track_report import track_modes

    arm = load_arm("panda")
    t = np.arange(126) / 250.0
    q = np.tile(np.array(arm.spec.posture), (len(t), 1))
    q[:, 6] += np.radians(1.0) * np.sin(np.pi * t / t[-1]) ** 2
    tr = Trajectory(t, q, arm.joint_names, "panda", None, (0.5, 0.0, 0.3))
    no_kv = replace(PANDA, kv=(0.0,) * 7)
    report = track_modes(tr, servo=no_kv)
    pos, ff = (report.result(m).tracked for m in ("position", "feedforward"))
    assert np.array_equal(pos.trajectory.q, ff.trajectory.q)
    assert "no velocity gain" in format_tracking(report)
    assert "no velocity gain" not in format_tracking(track_modes(tr, servo=PANDA))


def test_the_fitted_json_carries_the_fit_and_the_tracking_diagnostics(fitted_doc):
    """As check without --fit gives them: the fit's C314 changes, and a C322 for the
    shiver the chosen mode (plain set-points) loses, naming the modes that keep it."""
    diags = fitted_doc["diagnostics"]
    assert {d["code"] for d in diags} >= {"C314", "C322", "C323"}
    (lost,) = [d for d in diags if d["code"] == "C322"
               and d["fields"]["descriptor"] == "shiver_amplitude"]
    keeps = next(a["keeps"] for a in fitted_doc["tracking"]["at_risk"]
                 if a["descriptor"] == "shiver_amplitude")
    assert lost["fields"]["keeps"] == keeps and lost["fields"]["mode"] == "position"


def test_a_refusal_the_fit_cannot_change_gets_no_fit_command(tremble):
    """A refusal of a kind --fit does not change (a failed check, C306) beside one it
    does: the note names it and gives no command, which would fail too."""
    import argparse

    from aou_dsl.cli.track_cmd import _refusal_note
    from aou_dsl.core.diagnostics import Span, diag

    span = Span.whole_file(tremble)
    args = argparse.Namespace(path=tremble, robot="kinova", servo="position", track=True)
    fit_only = [diag("C308", "a shiver too fast", span)]
    assert "--fit --track" in _refusal_note(args, fit_only)
    both = [*fit_only, diag("C306", "table-contact check failed", span)]
    note = _refusal_note(args, both)
    assert "C306" in note and "--fit --track" not in note and "mend that first" in note
