"""What a newcomer measuring recordings and using `aouc robot` should see: a C-V point read
without the gazes says so, a unit that contradicts the robot's limits is refused, unit
problems point at their row, a plot without a goal warns, and `aouc robot`'s file reads
back to the same robot."""

import json
import math
import re
import tomllib

import numpy as np
import pytest

from aou_dsl.cli.commands import EXIT_ERRORS, EXIT_OK, main
from aou_dsl.measuring.measured import measure
from aou_dsl.measuring.recording import read_recording
from aou_dsl.robot.load import load_arm
from tests.conftest import fails_with
from tests.synth import Synth

DEG = math.pi / 180
GAZES = ["horizontal_gaze", "vertical_gaze"]  # the descriptors that are goal bearings


@pytest.fixture(scope="module")
def curious():
    """Two gaze arcs (20 deg either side of the start direction) between approaches."""
    s = Synth()
    s.line(-0.08, 0.09).arc(20 * DEG, 45 * DEG).hold(1.25).line(-0.05, 0.09)
    s.arc(-40 * DEG, 45 * DEG).hold(1.25).line(-0.05, 0.09).hold(1.25)
    return s.recording()


def _json(tmp_path, rec, goal: bool, name="r.json") -> str:
    doc = {"format": "aou-trajectory/1", "robot": rec.robot, "ee_frame": None,
           "joint_names": list(rec.joint_names), "t": rec.t.tolist(), "q": rec.q.tolist()}
    if goal:
        doc["goal"] = {"position": list(rec.goal)}
    path = tmp_path / name
    path.write_text(json.dumps(doc))
    return str(path)


# --- 1. a C-V point read without the gazes -----------------------------------------------

def test_a_cv_point_without_a_goal_says_which_descriptors_it_could_not_use(
        tmp_path, curious, capsys):
    blind = _json(tmp_path, curious, goal=False)
    assert main(["measure", blind]) == EXIT_OK
    out = capsys.readouterr().out
    (line,) = [ln for ln in out.splitlines() if "C-V" in ln]
    assert "without" in line and all(g in line for g in GAZES), line
    assert main(["measure", blind, "--format", "json"]) == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc["cv"]["missing_descriptors"] == GAZES
    # ... and it really lacks them: the two gazes the motion makes would raise V.
    seen = json.loads(_measure_json(_json(tmp_path, curious, goal=True, name="g.json"),
                                    capsys))
    assert doc["cv"]["V"] < seen["cv"]["V"]


def _measure_json(path, capsys) -> str:
    assert main(["measure", path, "--format", "json"]) == EXIT_OK
    return capsys.readouterr().out


def test_a_complete_measurement_is_unmarked_and_unchanged(tmp_path, curious, capsys):
    path = _json(tmp_path, curious, goal=True)
    doc = json.loads(_measure_json(path, capsys))
    assert doc["cv"]["missing_descriptors"] == []
    point = measure(read_recording(path)).cv
    assert (doc["cv"]["C"], doc["cv"]["V"]) == (round(point.C, 4), round(point.V, 4))
    assert doc["cv"]["state"] == point.state.value
    assert main(["measure", path]) == EXIT_OK
    (line,) = [ln for ln in capsys.readouterr().out.splitlines() if "C-V" in ln]
    assert "without" not in line and not any(g in line for g in GAZES)


# --- 2. and 3. units: an override against the limits, and where R404 points -------------

def _csv(tmp_path, rec, name, scale_q=1.0, scale_t=1.0, header=("# robot: panda",)) -> str:
    lines = [*header, "t," + ",".join(rec.joint_names)]
    lines += [",".join(repr(float(v)) for v in [t * scale_t, *(row * scale_q)])
              for t, row in zip(rec.t, rec.q, strict=True)]
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return str(path)


@pytest.fixture(scope="module")
def short():
    s = Synth()
    s.line(-0.05, 0.1).hold(0.6)
    return s.recording()


def test_an_angle_unit_that_puts_a_joint_outside_its_limits_throughout_is_refused(
        tmp_path, short, capsys):
    """Degrees read as radians (the user said rad): a joint at about -126 deg sits at
    -126 rad, nowhere near its limits, at every sample."""
    path = _csv(tmp_path, short, "deg.csv", scale_q=1 / DEG)
    d = fails_with("R404", read_recording, path, goal=short.goal, angle_unit="rad")
    arm = load_arm("panda")
    j = arm.joint_names.index(d.fields["joint"])
    col = short.q[:, j] / DEG
    assert ((col < arm.lower[j]) | (col > arm.upper[j])).all()  # truly out throughout
    assert f"`{d.fields['joint']}`" in d.message and "--angle-unit rad" in d.message
    assert "limits" in d.message and re.search(r"\b(row|sample) \d+", d.message)
    assert "--angle-unit deg" in (d.hint or "")
    assert main(["measure", path, "--angle-unit", "rad"]) == EXIT_ERRORS
    assert "R404" in capsys.readouterr().err
    # The right unit is still obeyed, for either file.
    assert read_recording(path, goal=short.goal, angle_unit="deg").q == pytest.approx(
        short.q)
    plain = _csv(tmp_path, short, "rad.csv")
    assert read_recording(plain, goal=short.goal, angle_unit="rad").q == pytest.approx(
        short.q)


def test_radians_read_as_degrees_are_refused_where_a_joint_s_range_excludes_zero(
        tmp_path, short):
    """--angle-unit deg on a file in radians shrinks every angle toward zero; the Panda's
    fourth joint cannot reach zero (its range ends at -4 deg), so it sits beyond its
    limit at every sample."""
    arm = load_arm("panda")
    j = arm.joint_names.index("panda_joint4")
    assert arm.upper[j] < -math.radians(3) and (short.q[:, j] * DEG > arm.upper[j]).all()
    path = _csv(tmp_path, short, "rad.csv")
    d = fails_with("R404", read_recording, path, goal=short.goal, angle_unit="deg")
    assert d.fields["joint"] == "panda_joint4" and "--angle-unit deg" in d.message
    assert "--angle-unit rad" in (d.hint or "")


def _degrees_csv(tmp_path) -> tuple[str, int]:
    """panda_joint1 in degrees climbing past its limit (2.9 rad read as radians) at the
    fifth sample; the other joints read sensibly either way. Returns the path and the
    line of that fifth sample in the file."""
    rows = []
    for i, a in enumerate([0, 1, 2, 3, 10, 20, 30, 40, 50, 60]):
        rows.append(f"{i * 0.01:.2f},{a},0,0,-2,0,1,0")
    text = ("# robot: panda\n# recorded by a newcomer\n\n"
            "t,panda_joint1,panda_joint2,panda_joint3,panda_joint4,panda_joint5,"
            "panda_joint6,panda_joint7\n" + "\n".join(rows) + "\n")
    path = tmp_path / "climb.csv"
    path.write_text(text)
    line = text.splitlines().index(rows[4]) + 1
    return str(path), line


def test_implausible_degrees_point_at_the_row_where_they_are_seen(tmp_path):
    path, line = _degrees_csv(tmp_path)
    d = fails_with("R404", read_recording, path)
    assert d.span.path == path and d.span.line == line
    assert f"row {line}" in d.message and "panda_joint1" in d.message


def test_implausible_milliseconds_point_at_a_row_of_the_file(tmp_path, short):
    path = _csv(tmp_path, short, "ms.csv", scale_t=1000.0,
                header=("# robot: panda", "# goal: 0.55,0,0.25"))
    d = fails_with("R404", read_recording, path)
    lines = open(path).read().splitlines()
    assert "milliseconds" in d.message and d.span.line > 3  # past the comments, header
    row = lines[d.span.line - 1].split(",")
    t = float(row[0])
    assert f"row {d.span.line}" in d.message and f"t={t:g}" in d.message


# --- 4. a plot without a goal -------------------------------------------------------------

def test_plot_without_a_goal_warns_and_leaves_the_goal_distance_out(tmp_path, short,
                                                                      capsys):
    pytest.importorskip("matplotlib")
    from aou_dsl.media.plot import profile_data, profile_figure

    blind = profile_data(read_recording(_json(tmp_path, short, goal=False)))
    assert [d.code for d in blind.diagnostics] == ["R405"]
    labels = [ax.get_ylabel() for ax in profile_figure(blind).axes]
    assert not any("goal" in label for label in labels) and "speed [m/s]" in labels
    seen = profile_data(read_recording(_json(tmp_path, short, goal=True, name="g.json")))
    assert seen.diagnostics == ()
    assert "goal distance [m]" in [ax.get_ylabel() for ax in profile_figure(seen).axes]
    png = tmp_path / "p.png"
    assert main(["plot", _json(tmp_path, short, goal=False), "-o", str(png)]) == EXIT_OK
    assert "R405" in capsys.readouterr().err and png.stat().st_size > 0


# --- 5. `aouc robot`'s file reads back to the same robot ----------------------------------

def _printed(capsys, robot: str, tmp_path, name: str) -> str:
    assert main(["robot", robot, "--format", "toml"]) == EXIT_OK
    path = tmp_path / name
    path.write_text(capsys.readouterr().out)
    return str(path)


def _same_limits(a, b):
    for key in ("lower", "upper", "vmax", "amax", "jmax"):
        assert np.array_equal(getattr(a, key), getattr(b, key)), key


@pytest.mark.parametrize("robot", ["panda", "ur5"])
def test_the_printed_robot_file_loads_the_same_limits_jerk_included(robot, tmp_path,
                                                                     capsys):
    from aou_dsl.robot import robot_diagnostics

    path = _printed(capsys, robot, tmp_path, f"{robot}.toml")
    text = open(path).read()
    named, again = load_arm(robot), load_arm(path)
    _same_limits(named, again)
    for key in ("arm_joints", "ee_frame", "goal", "start_direction", "posture",
                "shiver_joint", "velocity_scale", "accel_scale", "limit_margin"):
        assert getattr(again.spec, key) == getattr(named.spec, key), key
    # The jerk limit aou plans with is in the file, pinned or as a commented default.
    top = text.split("[sources]")[0].splitlines()  # the values, before their sources
    (jerk,) = [ln for ln in top if re.match(r"#?\s*joint_jerk\s*=", ln)]
    values = tomllib.loads(jerk.lstrip("# ").split("  #")[0])["joint_jerk"]
    assert values == list(named.jmax)
    # Its keys are the robot file's own, and a default stays flagged as one.
    assert set(tomllib.loads(text)) <= _reader_keys()
    assert [(d.code, d.fields.get("defaults")) for d in robot_diagnostics(path)] == [
        (d.code, d.fields.get("defaults")) for d in robot_diagnostics(robot)]


def _reader_keys() -> set[str]:
    from aou_dsl.robot.description import KEYS

    return set(KEYS)


def test_a_description_prints_back_to_itself(tmp_path, capsys):
    """What a robot description pins beyond the built-in arm it extends (the planning
    margins, a jerk limit and its source) survives printing and reading back."""
    mine = tmp_path / "mine.toml"
    mine.write_text('robot = "panda"\nlimit_margin = 0.1\nvelocity_scale = 0.5\n'
                    'joint_jerk = 2000\n[sources]\njoint_jerk = "my controller"\n')
    (tmp_path / "out").mkdir()
    path = _printed(capsys, str(mine), tmp_path / "out", "again.toml")
    a, b = load_arm(str(mine)), load_arm(path)
    _same_limits(a, b)
    assert list(b.jmax) == [2000.0] * 7
    for key in ("limit_margin", "velocity_scale", "accel_scale", "goal", "posture"):
        assert getattr(b.spec, key) == getattr(a.spec, key), key
    assert b.spec.source("joint_jerk") == "my controller"


def test_a_urdf_s_printed_file_keeps_its_unsourced_limits_flagged(tmp_path, capsys):
    from aou_dsl.robot import robot_diagnostics
    from tests.integration.test_robots import small_arm

    urdf = tmp_path / "small.urdf"
    urdf.write_text(small_arm())
    path = _printed(capsys, str(urdf), tmp_path, "small.toml")
    _same_limits(load_arm(str(urdf)), load_arm(path))
    before = [d.fields.get("defaults") for d in robot_diagnostics(str(urdf))]
    assert before == [["joint_accel", "joint_jerk"]]
    assert [d.fields.get("defaults") for d in robot_diagnostics(path)] == before


def test_the_spec_names_aouc_robot_shows_are_pointed_to_the_file_s_names(tmp_path):
    from aou_dsl.robot.description import read_description

    bad = tmp_path / "b.toml"
    bad.write_text('robot = "panda"\nstart_direction = [-0.6, 0.0, 0.8]\n')
    d = fails_with("V109", read_description, str(bad))
    assert "`from`" in (d.hint or "") and d.span.line == 2


# --- an aou CSV edited into degrees -------------------------------------------------------

@pytest.fixture(scope="module")
def aou_csv(tmp_path_factory):
    """A CSV written by `aouc compile` (comment lines say aou wrote it), and the same
    file with its joint columns turned into degrees, as a spreadsheet edit would."""
    from aou_dsl.compiler.output import encode
    from aou_dsl.driver.builder import build_source

    res = build_source("approach a=0.1\npause 1s x2\nretreat 0.05m a=0.1\n", "b.aou",
                       check=False)
    text = encode(res.document, "csv").decode()
    edited = []
    for line in text.splitlines():
        if line.startswith("#") or line.startswith("t,"):
            edited.append(line)
        else:
            t, *q = line.split(",")
            edited.append(",".join([t, *(repr(float(v) / DEG) for v in q)]))
    d = tmp_path_factory.mktemp("aou_csv")
    (d / "rad.csv").write_text(text)
    (d / "deg.csv").write_text("\n".join(edited) + "\n")
    return str(d / "rad.csv"), str(d / "deg.csv")


def test_an_aou_csv_edited_into_degrees_is_refused_then_read_with_the_unit(aou_csv):
    rad, deg = aou_csv
    d = fails_with("R404", read_recording, deg)
    assert "degrees" in d.message and "--angle-unit deg" in (d.hint or "")
    want = measure(read_recording(rad)).descriptors
    got = measure(read_recording(deg, angle_unit="deg")).descriptors
    for key in ("approach_acceleration", "pause_count", "retreat_distance"):
        assert got[key] == pytest.approx(want[key], rel=1e-6), key


def test_a_unit_on_an_unedited_aou_csv_is_still_refused(aou_csv):
    rad, _ = aou_csv
    d = fails_with("R404", read_recording, rad, angle_unit="deg")
    assert "aou wrote this file" in d.message
