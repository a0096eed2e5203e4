"""`aouc compile` as a user meets it: the trajectory file's contract, byte-
identical output, atomic writes, inputs never overwritten, batches, exit codes."""

import json
import shutil

import numpy as np
import pytest

from aou_dsl.cli.commands import EXIT_ERRORS, EXIT_OK, EXIT_USAGE, main
from tests.conftest import BEHAVIOURS

REQUIRED = ("format", "behaviour", "state", "robot", "ee_frame", "joint_names", "goal", "t",
            "q", "qd", "qdd", "descriptors", "cv")


@pytest.fixture(scope="module")
def hesitant_json(tmp_path_factory):
    out = tmp_path_factory.mktemp("out") / "hesitant.json"
    assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "-o", str(out)]) == EXIT_OK
    return out


def test_json_has_the_contract_keys(hesitant_json):
    doc = json.loads(hesitant_json.read_text())
    assert all(k in doc for k in REQUIRED)
    assert doc["format"] == "aou-trajectory/1"
    assert doc["behaviour"] == "hesitant" and doc["state"] == "hesitant"
    assert doc["robot"] == "panda" and doc["ee_frame"] == "panda_hand_tcp"
    assert doc["joint_names"] == [f"panda_joint{i}" for i in range(1, 8)]
    t = np.array(doc["t"])
    assert t[0] == 0.0 and np.all(np.diff(t) > 0)
    for key in ("q", "qd", "qdd"):
        assert np.array(doc[key]).shape == (len(t), 7)
    assert set(doc["cv"]) == {"C", "V", "state"} and doc["cv"]["state"] == "hesitant"
    assert doc["descriptors"]["declared"]["retreat_count"] == 3
    assert doc["descriptors"]["measured"]["retreat_count"] == 3


def test_positions_keep_at_least_nine_significant_digits(hesitant_json):
    """Accelerations are measured from q: rounding it would swamp a 0.05 m/s^2 peak."""
    text = hesitant_json.read_text()
    doc = json.loads(text)
    moving = [v for row in doc["q"][100:200] for v in row]
    digits = [len(repr(v).replace("-", "").replace(".", "").lstrip("0")) for v in moving]
    assert min(digits) >= 9


def test_output_is_byte_identical(tmp_path, hesitant_json):
    again = tmp_path / "again.json"
    assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "-o", str(again)]) == EXIT_OK
    assert again.read_bytes() == hesitant_json.read_bytes()


@pytest.mark.parametrize("fmt", ["csv", "npz"])
def test_other_formats_are_deterministic_and_carry_the_same_data(tmp_path, fmt, hesitant_json):
    doc = json.loads(hesitant_json.read_text())
    a, b = tmp_path / f"a.{fmt}", tmp_path / f"b.{fmt}"
    for out in (a, b):
        assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "-o", str(out)]) == EXIT_OK
    assert a.read_bytes() == b.read_bytes()
    if fmt == "npz":
        z = np.load(a)
        assert np.array_equal(z["q"], np.array(doc["q"]))
        assert np.array_equal(z["t"], np.array(doc["t"]))
    else:
        rows = [r for r in a.read_text().splitlines() if not r.startswith("#")]
        assert rows[0] == "t," + ",".join(doc["joint_names"])
        assert len(rows) == len(doc["t"]) + 1


def test_csv_output_measures_like_the_json(tmp_path, capsys):
    out = tmp_path / "h.csv"
    assert main(["compile", str(BEHAVIOURS / "fearful.aou"), "-o", str(out)]) == EXIT_OK
    assert main(["measure", str(out), "--robot", "panda", "--format", "json"]) == EXIT_OK
    m = json.loads(capsys.readouterr().out)["descriptors"]
    assert m["retreat_count"] == 1 and m["pause_count"] == 4
    assert abs(m["shiver_amplitude"] - 6.0) <= 0.5


def test_rate_option_sets_the_clock(tmp_path):
    out = tmp_path / "c.json"
    assert main(["compile", str(BEHAVIOURS / "confident.aou"), "-o", str(out),
                 "--rate", "100"]) == EXIT_OK
    doc = json.loads(out.read_text())
    assert doc["rate"] == 100.0
    assert np.allclose(np.diff(doc["t"])[:-1], 0.01)


def test_failure_writes_nothing_and_keeps_an_existing_file(tmp_path):
    bad = tmp_path / "far.aou"
    bad.write_text("goal (2.0, 0, 0.3)\napproach\npause 1s\n")
    out = tmp_path / "far.json"
    out.write_text("previous content")
    assert main(["compile", str(bad), "-o", str(out)]) == EXIT_ERRORS
    assert out.read_text() == "previous content"
    # No temporary file is left behind either.
    assert sorted(p.name for p in tmp_path.iterdir()) == ["far.aou", "far.json"]


def test_unreachable_goal_is_a_located_diagnostic(tmp_path, capsys):
    bad = tmp_path / "far.aou"
    bad.write_text("goal (2.0, 0, 0.3)\napproach\npause 1s\n")
    main(["compile", str(bad), "-o", str(tmp_path / "x.json")])
    err = capsys.readouterr().err
    assert "far.aou:1:1: C301" in err and "start pose" in err
    assert not (tmp_path / "x.json").exists()


def test_zero_standoff_fails_with_a_diagnostic(tmp_path, capsys):
    bad = tmp_path / "zero.aou"
    bad.write_text("standoff 0m\napproach\n")
    assert main(["compile", str(bad), "-o", str(tmp_path / "z.json")]) == EXIT_ERRORS
    assert "V105" in capsys.readouterr().err
    assert not (tmp_path / "z.json").exists()


def test_input_is_never_overwritten(tmp_path):
    src = tmp_path / "h.aou"
    shutil.copy(BEHAVIOURS / "hesitant.aou", src)
    before = src.read_bytes()
    assert main(["compile", str(src), "-o", str(src), "--format", "json"]) == EXIT_USAGE
    assert src.read_bytes() == before


def test_batch_to_a_folder_with_progress(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["compile", str(BEHAVIOURS), "-o", str(out)]) == EXIT_OK
    assert sorted(p.name for p in out.iterdir()) == sorted(
        f"{n}.json" for n in ("confident", "curious", "hesitant", "fearful", "inactive"))
    err = capsys.readouterr().err
    assert "[1/5]" in err and "[5/5]" in err


def test_batch_continues_past_a_failing_file(tmp_path, capsys):
    src = tmp_path / "src"
    src.mkdir()
    shutil.copy(BEHAVIOURS / "confident.aou", src)
    (src / "bad.aou").write_text("pause 3m\n")
    out = tmp_path / "out"
    assert main(["compile", str(src), "-o", str(out)]) == EXIT_ERRORS
    assert [p.name for p in out.iterdir()] == ["confident.json"]


def test_no_check_is_recorded(tmp_path):
    out = tmp_path / "c.json"
    assert main(["compile", str(BEHAVIOURS / "confident.aou"), "-o", str(out),
                 "--no-check"]) == EXIT_OK
    assert "skipped" in json.loads(out.read_text())["checks"]["kinematic"]


def test_explain_prints_the_timeline(capsys):
    assert main(["explain", str(BEHAVIOURS / "hesitant.aou")]) == EXIT_OK
    out = capsys.readouterr().out
    assert out.count(" retreat ") == 3 and out.count(" pause ") == 5
    assert "C-V point: C=+0.00" in out


@pytest.mark.parametrize("argv", [
    ["check", "x.json", "--goal", "1,2"],
    ["measure", "x.json", "--goal", "a,b,c"],
    ["render", "x.aou", "-o", "x.mp4", "--size", "big"],
    ["render", "x.aou", "-o", "x.mp4", "--camera-target", "1"],
    ["compile", "x.aou", "--rate", "fast"],
])
def test_bad_option_values_are_usage_errors_not_tracebacks(argv, capsys):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == EXIT_USAGE
    assert "aouc: error: argument" in capsys.readouterr().err


def test_check_reads_a_csv_recording_with_its_robot(tmp_path, hesitant_json, capsys):
    doc = json.loads(hesitant_json.read_text())
    csv = tmp_path / "rec.csv"
    csv.write_text("t," + ",".join(doc["joint_names"]) + "\n" + "\n".join(
        ",".join(repr(v) for v in [t, *row]) for t, row in zip(doc["t"], doc["q"],
                                                               strict=True)))
    assert main(["check", str(csv), "--no-dynamic"]) == EXIT_USAGE  # which robot?
    assert "--robot" in capsys.readouterr().err
    assert main(["check", str(csv), "--robot", "panda", "--no-dynamic"]) == EXIT_OK
    out = capsys.readouterr().out  # the CSV names no goal: no cube, nothing to pass
    assert "pass  self-collision" in out and "n/a   target-contact" in out
    assert "pass  target-contact" not in out


def test_robot_command_lists_and_describes_arms(capsys):
    assert main(["robot", "--list"]) == EXIT_OK
    names = [line.split()[0] for line in capsys.readouterr().out.splitlines()]
    assert {"panda", "ur5", "xarm7", "kinova", "z1"} <= set(names)
    assert main(["robot", "xarm7", "--format", "json"]) == EXIT_OK
    doc = json.loads(capsys.readouterr().out)
    assert doc["ee_frame"] == "link_eef" and len(doc["joints"]) == 7
    assert doc["sources"]["joint_accel"]  # every limit says where it comes from


def test_robot_command_on_an_unknown_robot_is_v109(capsys):
    assert main(["robot", "kuka_lbr"]) == 1
    assert "V109" in capsys.readouterr().err


def test_compile_to_a_ros2_bag_holds_the_trajectory(tmp_path, hesitant_json):
    from aou_dsl.compiler.ros import read_bag

    doc = json.loads(hesitant_json.read_text())
    out = tmp_path / "h.mcap"
    assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "-o", str(out),
                 "--controller", "franka"]) == EXIT_OK
    topic, msgtype, msg = read_bag(str(tmp_path / "h"))
    assert msgtype == "trajectory_msgs/msg/JointTrajectory"
    assert msg["joint_names"] == doc["joint_names"]
    assert len(msg["points"]) == len(doc["t"])
    assert np.allclose(msg["points"][-1]["positions"], doc["q"][-1])
    assert not np.any(msg["points"][-1]["velocities"])  # the last point is at rest
