"""What aou reads, when what it reads is hostile: every case here once crashed, hung or
was accepted silently. Each must now be a diagnostic with a code, at once."""

import json
import os
import re

import numpy as np
import pytest

from aou_dsl.lang.linter import lint_source
from aou_dsl.measuring.recording import read_recording
from aou_dsl.robot.description import read_description
from aou_dsl.robot.urdf import read_urdf, resolve_uri
from tests.conftest import fails_with
from tests.inputgen import (
    GOAL,
    chain,
    csv_bytes,
    json_doc,
    motion,
    npy,
    npy_claiming,
    npz_bytes,
    npz_of,
    panda_urdf,
    panda_with,
    urdf,
)


def _codes(text: str) -> list[str]:
    return [d.code for d in lint_source(text, "t.aou").diagnostics if d.severity == "error"]


# --- .aou numbers at the float limits ----------------------------------------------------

@pytest.mark.parametrize("text", ["tilt 1e160deg", "tilt 20deg v=1e-155",
                                  "tilt 20deg v=1e308", "approach v=1e160\npause 1s",
                                  "shiver 5deg f=1e308", "pause 4000s", "retreat 1e308m",
                                  "approach a=1e308\npause 1s", "gaze horizontal 1e200deg"])
def test_numbers_at_the_float_limits_are_out_of_range(text):
    """A value no behaviour can use is V130 at its statement, naming the range."""
    result = lint_source(text, "t.aou")
    (d,) = [d for d in result.diagnostics if d.severity == "error"]
    assert d.code == "V130" and d.span.line == 1
    assert "from" in d.message or "up to" in d.message
    assert d.hint and d.hint.startswith("write a value")


def test_the_range_admits_its_own_bounds():
    """A tilt of one turn and a shiver at 100 Hz are in range (other rules may speak)."""
    assert "V130" not in _codes("tilt 360deg")
    assert "V130" in _codes("tilt 361deg")
    assert "V130" not in _codes("shiver 5deg f=100Hz")
    assert "V130" in _codes("shiver 5deg f=101Hz")


def test_a_slow_rate_in_range_is_still_the_time_bound():
    """A rate inside the range but too slow to finish is V110, the time bound, as before."""
    assert _codes("tilt 20deg v=1e-4") == ["V110"]


def test_a_repeat_count_of_5000_digits_is_the_episode_bound():
    assert _codes("pause 1s x" + "9" * 5000) == ["V110"]


@pytest.mark.parametrize("text,meant", [("pause １０s", "10s"), ("start 0.٣m\napproach", "0.3m"),
                                        ("pause 1s x٣", "x3")])
def test_lookalike_digits_are_refused_with_the_ascii_number(text, meant):
    """Digits that only look like 0-9 do not lint clean: S003 says what to write."""
    (d,) = lint_source(text, "t.aou").diagnostics
    assert d.code == "S003" and f"`{meant}`" in (d.hint or "")


# --- recordings --------------------------------------------------------------------------

def _write(tmp_path, name: str, data: bytes) -> str:
    path = tmp_path / name
    path.write_bytes(data)
    return str(path)


@pytest.mark.parametrize("goal", ["0.5,0", "0.5,0,0.3,1", "nan,nan,nan", "inf,0,0",
                                  "550,0,250"])
def test_a_csv_goal_is_three_finite_coordinates_in_metres(tmp_path, goal):
    t, q = motion()
    d = fails_with("R401", read_recording, _write(tmp_path, "g.csv",
                                                  csv_bytes(t, q, goal=goal)))
    assert d.span.line == 2 and "X,Y,Z" in d.message


@pytest.mark.parametrize("edit", [
    lambda b: b.replace(b"\n0.01,", b'\n"0.01,', 1),                      # unclosed quote
    lambda b: b.replace(b"\n0.01,", b"\n0.01" + b"5" * 140_000 + b",", 1)])  # 137 KiB field
def test_a_csv_field_past_the_csv_limit_is_r401_at_its_row(tmp_path, edit):
    t, q = motion()
    d = fails_with("R401", read_recording, _write(tmp_path, "f.csv", edit(csv_bytes(t, q))))
    assert d.span.line > 1


def test_huge_csv_times_are_refused_not_allocated(tmp_path):
    """Times of 1e300 s are refused before anything is sampled at their scale."""
    t, q = motion()
    fails_with("R404", read_recording, _write(tmp_path, "h.csv", csv_bytes(t * 1e300, q)))


@pytest.mark.parametrize("key,value", [
    ("goal", [True, False, True]), ("goal", ["0.5", "0", "0.3"]), ("rate", True),
    ("rate", "250"), ("q", "3d"), ("q", "strings"), ("t", "booleans"), ("q", 1e308)])
def test_every_json_field_is_read_as_its_type(tmp_path, key, value):
    t, q = motion()
    shaped = {"3d": [[[v] for v in row] for row in q.tolist()],
              "strings": [[str(v) for v in row] for row in q.tolist()],
              "booleans": [True] * len(t)}
    if value == 1e308:
        value = [[1e308] * 7 for _ in t]
    doc = {**json_doc(t, q), key: shaped.get(value, value) if isinstance(value, str) else value}
    d = fails_with("R401", read_recording, _write(tmp_path, "j.json", json.dumps(doc).encode()))
    assert d.span.line >= 1


@pytest.mark.parametrize("dtype", ["datetime64[s]", "complex128", "S8", "bool"])
def test_npz_samples_must_be_numbers(tmp_path, dtype):
    t, q = motion()
    d = fails_with("R401", read_recording, _write(tmp_path, "q.npz", npz_of(
        t, q, q_npy=npy(np.zeros(q.shape, dtype)))))
    assert "q.npy" in d.message


@pytest.mark.parametrize("how", [{"patch_method": 9}, {"patch_method": 99},
                                 {"encrypted": True}])
def test_npz_compressions_aou_does_not_read_are_r401(tmp_path, how):
    t, q = motion()
    members = {"t.npy": npy(t), "q.npy": npy(q), "header.json": json.dumps(
        {k: v for k, v in json_doc(t, q).items() if k not in ("t", "q")}).encode()}
    fails_with("R401", read_recording, _write(tmp_path, "c.npz", npz_bytes(members, **how)))


@pytest.mark.parametrize("shape,code", [((10**9, 7), "R410"), ((10**12, 7), "R410"),
                                        ((50, 7), "R401")])
def test_npz_headers_claiming_more_than_they_hold(tmp_path, shape, code):
    """A header's claim is checked against the bound and the bytes there: no array of
    52 GiB is ever asked for."""
    t, q = motion()
    fails_with(code, read_recording, _write(tmp_path, "c.npz", npz_of(
        t, q, q_npy=npy_claiming(shape))))


def test_a_deeply_nested_npy_header_is_r401(tmp_path):
    t, q = motion()
    fails_with("R401", read_recording, _write(tmp_path, "n.npz", npz_of(
        t, q, q_npy=npy_claiming((5, 7), "[" * 3000 + "]" * 3000))))


def test_a_huge_episode_list_is_not_read(tmp_path):
    """No compiled file lists more than 1000 episodes: such a list is left out (measure
    and plot work from the samples), not walked."""
    t, q = motion()
    doc = {**json_doc(t, q), "episodes": [{"kind": "pause", "t_start": 0.1,
                                           "t_end": 0.2}] * 300_000}
    rec = read_recording(_write(tmp_path, "e.json", json.dumps(doc).encode()))
    assert rec.episodes == () and len(rec.t) == len(t)


def test_another_robot_on_a_recording_reports_the_joints(tmp_path):
    """`--robot ur5` on a Panda trajectory says which joints it lacks, not a frame."""
    import aou_dsl

    t, q = motion()
    path = _write(tmp_path, "p.json", json.dumps(json_doc(t, q)).encode())
    d = fails_with("R402", aou_dsl.measure, path, robot="ur5")
    assert "shoulder_pan_joint" in d.message and "frame" not in d.message


def test_rows_and_bytes_are_bounded_by_environment(tmp_path, monkeypatch):
    t, q = motion(400)
    path = _write(tmp_path, "b.csv", csv_bytes(t, q))
    monkeypatch.setenv("AOU_MAX_SAMPLES", "300")
    d = fails_with("R410", read_recording, path)
    assert "AOU_MAX_SAMPLES" in (d.hint or "")
    monkeypatch.delenv("AOU_MAX_SAMPLES")
    monkeypatch.setenv("AOU_MAX_INPUT_MB", "0.01")
    d = fails_with("R410", read_recording, path)
    assert "AOU_MAX_INPUT_MB" in (d.hint or "")


# --- check on any clock ------------------------------------------------------------------

def test_check_gives_the_same_verdict_whatever_the_clock_starts_at(tmp_path):
    """Unix timestamps, a start at -100 s or at -1 s: the same motion, the same torques,
    the times reported on the file's own clock."""
    import aou_dsl

    ratios, times = [], []
    for t0 in (0.0, -1.0, -100.0, 1.7e9):
        t, q = motion(t0=t0)
        path = _write(tmp_path, f"c{len(ratios)}.json", json.dumps(json_doc(t, q)).encode())
        report = aou_dsl.check(path)
        ratios.append(report.dynamic["torque_max_ratio"])
        (torque,) = [c for c in report.checks if c.name == "joint-torque"]
        times.append(torque.time - t0)
    assert max(ratios) - min(ratios) < 1e-3, ratios
    assert max(times) - min(times) < 1e-3, times


def test_check_of_times_in_milliseconds_is_refused_at_once(tmp_path):
    import aou_dsl

    t, q = motion(2000, 250.0, scale=1000.0)
    fails_with("R404", aou_dsl.check, _write(tmp_path, "ms.csv", csv_bytes(t, q)))


# --- robot files -------------------------------------------------------------------------

L = [f"l{i}" for i in range(4)]


@pytest.mark.parametrize("data,words", [
    (urdf(L, [("a", "revolute", "l0", "l1"), ("b", "revolute", "l1", "l2"),
              ("c", "revolute", "l2", "l0")]), "cycle"),
    (urdf(L[:2], [("a", "revolute", "l0", "l1"), ("b", "revolute", "l1", "l1")]), "itself"),
    (panda_with("panda_joint4", "velocity", "0"), "velocity limit of 0"),
    (panda_with("panda_joint4", "velocity", "-1"), "velocity limit of -1"),
    (panda_with("panda_joint4", "lower", "2.9"), "lower limit"),
    (panda_with("panda_joint4", "xyz", "0 0 0"), "axis"),
    (panda_with("panda_joint4", "xyz", "1e308 0 0"), "axis"),
    (panda_with("panda_joint4", "effort", "0"), "effort limit of 0")])
def test_urdfs_no_arm_can_have_are_v109(tmp_path, data, words):
    d = fails_with("V109", read_urdf, _write(tmp_path, "arm.urdf", data))
    assert words in d.message


@pytest.mark.parametrize("data", [
    chain(1000), chain(100),
    urdf([f"a{i}" for i in range(2000)],
         [(f"j{i}", "revolute", f"a{2 * i}", f"a{2 * i + 1}") for i in range(1000)])])
def test_oversized_urdfs_are_v132_at_once(tmp_path, data):
    fails_with("V132", read_urdf, _write(tmp_path, "big.urdf", data))


@pytest.mark.parametrize("uri", ["package://mypkg/../../etc/passwd",
                                 "package://mypkg/../../../../etc/passwd",
                                 "package://mypkg//etc/passwd"])
def test_package_paths_that_leave_their_package_are_v131(tmp_path, uri):
    text = re.sub(r'filename="package://[^"]*"', f'filename="{uri}"', panda_urdf(), count=1)
    d = fails_with("V131", read_urdf, _write(tmp_path, "arm.urdf", text.encode()))
    assert d.span.path == str(tmp_path / "arm.urdf")


@pytest.mark.parametrize("text", [
    'velocity_scale = inf', 'accel_scale = inf', 'limit_margin = inf',
    'allowed_contacts = [["l1", "nolink"]]', "x = " + "[" * 5000 + "]" * 5000,
    "ee_offset = " + "9" * 5000])
def test_robot_descriptions_out_of_range_are_v109(tmp_path, text):
    from aou_dsl.robot.load import load_robot

    _write(tmp_path, "u.urdf", chain(6))
    path = _write(tmp_path, "arm.toml", f'urdf = "u.urdf"\n{text}\n'.encode())
    fails_with("V109", lambda p: load_robot(read_description(p).path), path)


def test_a_mesh_that_is_a_folder_or_a_fifo_is_no_mesh(tmp_path):
    """Only regular files are meshes: PyBullet is never handed a folder (it aborts) or a
    FIFO (it waits for good)."""
    (tmp_path / "meshes").mkdir()
    os.mkfifo(tmp_path / "m.stl")
    assert resolve_uri("meshes", str(tmp_path)) is None
    assert resolve_uri("m.stl", str(tmp_path)) is None


def test_the_vendors_panda_urdf_compiles_as_a_user_urdf(tmp_path):
    """example-robot-data's own panda.urdf, given as a user's URDF: its fingers touch by a
    hair in every pose, so they are allowed to, as on the built-in arm."""
    from aou_dsl.core.robot_specs import ROBOTS
    from aou_dsl.driver.builder import build_source
    from aou_dsl.robot.load import _data_path, load_robot

    path = _data_path(ROBOTS["panda"].urdf)
    assert ("panda_leftfinger", "panda_rightfinger") in load_robot(path).spec.allowed_contacts
    res = build_source(f'robot "{path}"\napproach\npause 1s\n', str(tmp_path / "v.aou"))
    assert res.ok, [(d.code, d.message) for d in res.diagnostics]


# --- special files -----------------------------------------------------------------------

@pytest.mark.parametrize("name", ["x.csv", "x.json", "x.npz", "x"])
def test_a_fifo_recording_is_refused_without_waiting(tmp_path, name):
    os.mkfifo(tmp_path / name)
    d = fails_with("I501", read_recording, str(tmp_path / name), robot="panda")
    assert "FIFO" in d.message


@pytest.mark.parametrize("device,name", [("/dev/zero", "x.csv"), ("/dev/zero", "x.json"),
                                         ("/dev/urandom", "x.npz")])
def test_a_device_recording_is_refused_without_reading(tmp_path, device, name):
    os.symlink(device, tmp_path / name)
    d = fails_with("I501", read_recording, str(tmp_path / name), robot="panda")
    assert "character device" in d.message


@pytest.mark.parametrize("make", ["fifo", "/dev/zero"])
def test_a_special_robot_file_is_refused(tmp_path, make):
    path = tmp_path / "arm.urdf"
    os.mkfifo(path) if make == "fifo" else os.symlink(make, path)
    fails_with("I501", read_urdf, str(path))
    toml = tmp_path / "arm.toml"
    os.mkfifo(toml) if make == "fifo" else os.symlink(make, toml)
    fails_with("I501", read_description, str(toml))


def test_a_recording_goal_default_is_kept(tmp_path):
    """The bounds do not touch a good file: its goal and samples read as written."""
    t, q = motion()
    rec = read_recording(_write(tmp_path, "ok.csv", csv_bytes(t, q)))
    assert rec.goal == GOAL and rec.q.shape == q.shape


@pytest.mark.parametrize("name,meant", [("franka", "panda"), ("ur5e", "ur5"),
                                        ("pnda", "panda")])
def test_an_unknown_robot_is_answered_with_the_name_aou_uses(name, meant):
    """`robot franka` (the maker's name) and `robot pnda` (a slip) both say which
    built-in arm was meant."""
    (d,) = [d for d in lint_source(f"robot {name}\napproach\npause 1s", "t.aou").diagnostics
            if d.code == "V109"]
    assert f"`{meant}`" in (d.hint or "")


def test_aouc_robot_says_when_the_collision_meshes_are_missing(tmp_path):
    """A URDF whose collision meshes cannot be found does not pass as having collision
    geometry without a word: the text names the first missing mesh and the way out."""
    from aou_dsl.robot.summary import describe_robot

    path = _write(tmp_path, "nomesh.urdf", panda_urdf().encode())
    doc, text = describe_robot(path)
    assert doc["collision_geometry"] and doc["missing_meshes"]
    assert "not found" in text and "--package-dir" in text and "--no-check" in text


@pytest.mark.slow
def test_the_reach_search_of_an_arm_nothing_fits_is_bounded(tmp_path, monkeypatch):
    """Six joints stacked on one axis fit no reach: the search stops after its budget
    of tries (it took hundreds, minutes of IK) and says the reach was not found."""
    from aou_dsl.robot import derive
    from aou_dsl.robot.load import load_robot

    tries = []
    probe = derive._probe

    def counted(*args, **kw):
        tries.append(1)
        return probe(*args, **kw)

    monkeypatch.setattr(derive, "_probe", counted)
    robot = load_robot(_write(tmp_path, "stack.urdf", chain(6)))
    assert robot.reach_ok is False and 0 < len(tries) <= derive.MAX_PROBES
