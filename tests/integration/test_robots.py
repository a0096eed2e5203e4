"""Any arm: the built-in arms, a user's URDF (package:// meshes, continuous joints, grippers),
robot description files, the derivations, collision geometry, and the report page."""

import json
import math
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

from aou_dsl.core.diagnostics import AouError
from aou_dsl.core.robot_specs import ROBOTS
from aou_dsl.lang.linter import lint_source
from aou_dsl.robot.chain import arm_joints, ee_link
from aou_dsl.robot.description import read_description
from aou_dsl.robot.load import load_arm, load_robot, robot_diagnostics, scene_urdf
from aou_dsl.robot.summary import describe_robot, robot_toml
from aou_dsl.robot.urdf import kinematic_xml, read_urdf, resolve_uri
from tests.conftest import BEHAVIOURS, ROOT


def _data(sub: str) -> str:
    import example_robot_data as erd

    return os.path.join(erd.getModelPath(sub), sub)


def _copy_package(name: str, dest) -> str:
    """Copy example-robot-data's ``robots/<name>`` (URDF and meshes) into ``dest``."""
    robots = os.path.dirname(os.path.dirname(os.path.dirname(_data(ROBOTS["panda"].urdf))))
    shutil.copytree(os.path.join(robots, name), dest / name)
    return str(dest / name)


# --- A small arm written here: primitives only, no meshes ------------------------------

_LINKS = [  # joint name, axis, origin xyz of the joint in its parent, link length along z
    ("j1", "0 0 1", "0 0 0.05", 0.10), ("j2", "0 1 0", "0 0 0.10", 0.35),
    ("j3", "0 1 0", "0 0 0.35", 0.30), ("j4", "0 0 1", "0 0 0.30", 0.05),
    ("j5", "0 1 0", "0 0 0.05", 0.05), ("j6", "0 0 1", "0 0 0.05", 0.04)]


def small_arm(collision: bool = True, continuous: bool = False, gripper: bool = False) -> str:
    """A 6-joint arm of cylinders standing on z (its tool looks along the last link's z)."""
    def shape(length: float) -> str:
        cyl = (f'<geometry><cylinder radius="0.03" length="{length * 0.8:.3f}"/></geometry>'
               f'<origin xyz="0 0 {length / 2:.3f}"/>')
        return f"<visual>{cyl}</visual>" + (f"<collision>{cyl}</collision>" if collision
                                            else "")

    parts = ['<robot name="small">', f'<link name="base">{shape(0.05)}</link>']
    parent = "base"
    for i, (name, axis, xyz, length) in enumerate(_LINKS):
        kind = "continuous" if continuous and i in (0, 3, 5) else "revolute"
        limit = ('<limit effort="50" velocity="2.0"/>' if kind == "continuous" else
                 '<limit effort="50" lower="-2.9" upper="2.9" velocity="2.0"/>')
        parts += [f'<link name="l{i + 1}">{shape(length)}</link>',
                  f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
                  f'<child link="l{i + 1}"/><origin xyz="{xyz}"/><axis xyz="{axis}"/>'
                  f"{limit}</joint>"]
        parent = f"l{i + 1}"
    parts += ['<link name="tool"/>', '<joint name="tool_joint" type="fixed">'
              '<parent link="l6"/><child link="tool"/><origin xyz="0 0 0.06"/></joint>']
    if gripper:
        for side in ("left", "right"):
            parts += [f'<link name="{side}_finger"/>',
                      f'<joint name="{side}_finger_joint" type="prismatic"><parent link="l6"/>'
                      f'<child link="{side}_finger"/><axis xyz="0 1 0"/>'
                      '<limit effort="5" lower="0" upper="0.03" velocity="0.1"/></joint>']
    return "\n".join(parts + ["</robot>"])


@pytest.fixture
def arm_file(tmp_path):
    def write(name="small.urdf", **kw) -> str:
        path = tmp_path / name
        path.write_text(small_arm(**kw))
        return str(path)
    return write


# --- Built-in arms -----------------------------------------------------------------------

@pytest.mark.parametrize("name", list(ROBOTS))
def test_builtin_arm_loads_without_meshes_and_its_table_fits_the_urdf(name):
    """Every built-in arm's kinematics load from its URDF alone; the table's joints are
    the URDF's chain, the posture lies within the limits, and the compiler's inverse
    kinematics reaches the default start pose (0.30 m from the default goal, looking at
    it) from the posture."""
    from aou_dsl.lang.timeline import Pose
    from aou_dsl.robot.geometry import reach_frame
    from aou_dsl.robot.ik import solve_path

    arm = load_arm(name)
    spec = arm.spec
    assert arm.model.nq == arm.model.nv == len(spec.arm_joints)
    assert arm_joints(load_robot(name).urdf) == spec.arm_joints
    assert np.all(np.array(spec.posture) >= arm.lower) and np.all(
        np.array(spec.posture) <= arm.upper)
    assert len(spec.joint_accel) == arm.n and spec.source("joint_accel")
    start = reach_frame(spec.goal, spec.start_direction).target(Pose(0.30))
    assert solve_path(arm, [start]).ok


@pytest.mark.parametrize("name", list(ROBOTS))
def test_derivations_agree_with_the_built_in_table(name):
    """The derivation rules, run on each built-in arm's URDF, find the table's shiver
    joint and (where the table names the URDF's own link) its forward axis."""
    from aou_dsl.robot import derive
    from aou_dsl.robot.kinematics import frame_id

    r = load_robot(name)
    spec = r.spec
    link = spec.ee_link or spec.ee_frame
    q = np.clip(np.zeros(len(spec.arm_joints)), r.model.lowerPositionLimit,
                r.model.upperPositionLimit)
    forward, _ = derive.forward_axis(r.model, q, frame_id(r.model, link))
    assert forward == spec.forward
    shiver, _ = derive.shiver_joint(r.model, q, frame_id(r.model, spec.ee_frame), "+z")
    assert shiver == spec.shiver_joint


def test_ur3_is_the_ur3_not_example_robot_data_s_ur5():
    """example-robot-data's `ur3` entry loads a UR5; aou's is the UR3 (shorter links)."""
    ur3, ur5 = load_arm("ur3"), load_arm("ur5")
    p3 = ur3.fk(np.zeros(6))[0][0]
    p5 = ur5.fk(np.zeros(6))[0][0]
    assert np.linalg.norm(p3) < np.linalg.norm(p5) - 0.2


def test_each_robot_is_loaded_once_per_process():
    assert load_robot("kinova") is load_robot("kinova")
    assert load_arm("kinova") is load_arm("kinova")


# --- Reading URDFs -----------------------------------------------------------------------

def test_package_uris_resolve_from_dirs_parents_and_ros_package_path(tmp_path, monkeypatch):
    """package://pkg/x is found in an explicit folder, in a parent folder named pkg (or
    holding pkg), in ROS_PACKAGE_PATH, and by its tail for a package copied elsewhere."""
    mesh = tmp_path / "ws" / "pkg" / "meshes" / "a.stl"
    mesh.parent.mkdir(parents=True)
    mesh.write_text("solid a\nendsolid a\n")
    urdf_dir = tmp_path / "ws" / "pkg" / "urdf"
    urdf_dir.mkdir()
    other = tmp_path / "elsewhere"
    other.mkdir()
    want = str(mesh)
    assert resolve_uri("package://pkg/meshes/a.stl", str(urdf_dir)) == want
    assert resolve_uri("package://pkg/meshes/a.stl", str(other)) is None
    assert resolve_uri("package://pkg/meshes/a.stl", str(other),
                       [str(tmp_path / "ws")]) == want
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws"))
    assert resolve_uri("package://pkg/meshes/a.stl", str(other)) == want
    monkeypatch.delenv("ROS_PACKAGE_PATH")
    assert resolve_uri("package://installed-name/robots/pkg/meshes/a.stl",
                       str(urdf_dir)) == want
    assert resolve_uri("../meshes/a.stl", str(urdf_dir)) == want


def test_continuous_joints_are_one_angle_each(arm_file):
    """Pinocchio gives a continuous joint two coordinates; aou's model has one angle per
    joint, within one turn either way."""
    path = arm_file(continuous=True)
    arm = load_arm(path)
    assert arm.model.nq == arm.model.nv == 6
    assert arm.upper[0] == pytest.approx(2 * math.pi) and arm.lower[3] == pytest.approx(
        -2 * math.pi)
    assert "continuous" not in kinematic_xml(read_urdf(path), arm.joint_names, {})


def test_gripper_joints_are_not_arm_joints_and_stay_locked(arm_file):
    path = arm_file(gripper=True)
    urdf = read_urdf(path)
    assert arm_joints(urdf) == ("j1", "j2", "j3", "j4", "j5", "j6")
    assert ee_link(urdf, arm_joints(urdf)) == "tool"
    assert load_arm(path).joint_names == ("j1", "j2", "j3", "j4", "j5", "j6")


def test_a_urdf_s_derivations(arm_file):
    """The small arm's tool looks along its z axis, its last joint turns about that axis,
    and the search finds a reach; every value says where it came from."""
    r = load_robot(arm_file())
    spec = r.spec
    assert (spec.ee_frame, spec.forward, spec.shiver_joint) == ("tool", "+z", "j6")
    assert r.reach_ok is True
    for key in ("arm_joints", "ee_frame", "forward", "shiver_joint", "goal", "posture",
                "joint_accel"):
        assert spec.source(key).startswith(("derived", "no source")), key


def test_missing_meshes_refuse_the_scene_but_not_the_kinematics(tmp_path):
    """Kinematics read no mesh: a URDF whose meshes are gone still measures; the safety
    scene says which mesh is missing."""
    path = tmp_path / "panda.urdf"
    shutil.copy(_data(ROBOTS["panda"].urdf), path)
    arm = load_arm(str(path))
    assert arm.n == 9 - 2  # the fingers are the gripper's
    with pytest.raises(AouError) as err:
        scene_urdf(str(path))
    assert err.value.diagnostics[0].code == "V109" and "--package-dir" in (
        err.value.diagnostics[0].hint or "")


# --- Robot descriptions ------------------------------------------------------------------

def test_description_errors_point_at_their_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('urdf = "a.urdf"\njoint_acel = 5\n')
    with pytest.raises(AouError) as err:
        read_description(str(bad))
    d = err.value.diagnostics[0]
    assert (d.code, d.span.line) == ("V109", 2) and "joint_accel" in (d.hint or "")
    bad.write_text('urdf = "a.urdf"\njoint_accel = -5\n')
    with pytest.raises(AouError):
        read_description(str(bad))
    bad.write_text('robot = "panda"\nurdf = "a.urdf"\n')
    with pytest.raises(AouError):
        read_description(str(bad))


def test_a_description_pins_what_it_names(arm_file, tmp_path):
    arm_file()
    (tmp_path / "small.toml").write_text(
        'urdf = "small.urdf"\njoint_accel = 7.0\njoint_jerk = [900, 900, 900, 900, 900, 900]\n'
        'goal = [0.4, 0.1, 0.2]\n[sources]\njoint_accel = "my datasheet"\n')
    arm = load_arm(str(tmp_path / "small.toml"))
    assert list(arm.amax) == [7.0] * 6 and list(arm.jmax) == [900.0] * 6
    assert arm.spec.goal == (0.4, 0.1, 0.2)
    assert arm.spec.source("joint_accel") == "my datasheet"
    assert robot_diagnostics(str(tmp_path / "small.toml")) == []


def test_describe_is_json_and_its_toml_reloads_to_the_same_robot(tmp_path):
    """`aouc robot` output: JSON-able, and its pinning description loads the same arm."""
    doc, text = describe_robot("kinova")
    json.dumps(doc)
    assert "j2s6s200_joint_6" in text and doc["sources"]["posture"]
    (tmp_path / "k.toml").write_text(doc["toml"])
    again = load_arm(str(tmp_path / "k.toml")).spec
    spec = ROBOTS["kinova"]
    for key in ("arm_joints", "ee_frame", "forward", "shiver_joint", "goal", "posture",
                "joint_accel", "start_direction"):
        assert getattr(again, key) == pytest.approx(getattr(spec, key)) if isinstance(
            getattr(spec, key), float) else getattr(again, key) == getattr(spec, key), key


# --- Limits and collision geometry -------------------------------------------------------

def test_unsourced_limits_warn_with_the_file_to_write(arm_file):
    path = arm_file()
    (warning,) = robot_diagnostics(path)
    assert warning.code == "C313" and "small.toml" in warning.hint
    assert ROBOTS["panda"].source("joint_accel").startswith("Franka")
    assert [d.code for d in robot_diagnostics("z1")] == ["C313"]
    assert robot_diagnostics("panda") == []


def test_a_urdf_without_collision_geometry_is_refused_unless_asked(arm_file):
    path = arm_file(name="ghost.urdf", collision=False)
    codes = [d.code for d in robot_diagnostics(path)]
    assert "C312" in codes
    assert "C312" not in [d.code for d in robot_diagnostics(path, collision_check=False)]
    assert "C312" not in [d.code for d in robot_diagnostics(arm_file())]


# --- The robot setting -------------------------------------------------------------------

def test_robot_setting_takes_a_quoted_path_from_the_file_s_folder(arm_file, tmp_path):
    arm_file()
    aou = tmp_path / "b.aou"
    res = lint_source('robot "small.urdf"\napproach a=0.1\n', str(aou))
    assert res.behaviour.settings.robot == str(tmp_path / "small.urdf")
    res = lint_source('robot "missing.urdf"\napproach a=0.1\n', str(aou))
    assert [d.code for d in res.diagnostics if d.code.startswith("V")] == ["V109"]
    res = lint_source("robot xarm\napproach a=0.1\n", str(aou))
    (d,) = [d for d in res.diagnostics if d.code == "V109"]
    assert "xarm7" in d.message


# --- Compiling on a user's robot ---------------------------------------------------------

def _build(tmp_path, behaviour: str, robot: str):
    from aou_dsl.driver.builder import build_file

    lines = (BEHAVIOURS / f"{behaviour}.aou").read_text().replace("robot panda\n", "")
    lines = lines.splitlines(keepends=True)
    at = next(i for i, line in enumerate(lines) if line.startswith("behaviour")) + 1
    path = tmp_path / f"{behaviour}.aou"
    path.write_text("".join(lines[:at] + [f'robot "{robot}"\n'] + lines[at:]))
    return build_file(str(path))


@pytest.mark.slow
def test_a_copied_urdf_compiles_the_same_as_the_named_robot(tmp_path):
    """The Panda's package copied out of example-robot-data (its mesh paths still name
    the data package) and pinned like the built-in arm compiles the very same
    trajectory, and passes the checks with the copied meshes."""
    from aou_dsl.driver.builder import build_file

    pkg = _copy_package("panda_description", tmp_path)
    urdf = os.path.relpath(os.path.join(pkg, "urdf", "panda.urdf"), tmp_path)
    (tmp_path / "panda.toml").write_text(robot_toml(load_robot("panda"), urdf=urdf))
    ours = _build(tmp_path, "fearful", "panda.toml")
    named = build_file(str(BEHAVIOURS / "fearful.aou"), robot="panda")
    assert ours.ok and named.ok, [d.message for d in ours.diagnostics]
    assert np.array_equal(ours.trajectory.q, named.trajectory.q)
    assert all(c.ok for c in ours.checks) and ours.checks


@pytest.fixture(scope="module")
def kinova_copy(tmp_path_factory):
    """Kinova's package (package:// meshes, three continuous joints) copied out of the
    data package into a folder of its own."""
    dest = tmp_path_factory.mktemp("vendor")
    pkg = _copy_package("kinova_description", dest)
    return dest, os.path.join(pkg, "robots", "kinova.urdf")


@pytest.mark.slow
def test_a_vendor_urdf_with_package_paths_and_continuous_joints_compiles(kinova_copy):
    """The URDF as shipped, nothing pinned: its meshes are found from its folder, its
    continuous joints are one column each, and the behaviour passes the checks and
    measures as declared."""
    dest, urdf = kinova_copy
    res = _build(dest, "curious", urdf)
    assert res.ok, [(d.code, d.message) for d in res.diagnostics]
    tr = res.trajectory
    assert tr.q.shape[1] == 6 and tr.robot == urdf
    assert all(c.ok for c in res.checks)
    assert not [d for d in res.diagnostics if d.code == "C310"]


@pytest.mark.slow
def test_a_csv_recording_of_a_user_s_arm_measures_like_its_trajectory(kinova_copy):
    """read_recording(csv, robot=PATH) + measure: the CSV of a compiled trajectory on the
    user's arm measures the same descriptors as the trajectory itself, within each
    descriptor's tolerance (the CSV has no velocities, which place episode edges more
    exactly)."""
    from aou_dsl.lang.descriptors import REGISTRY
    from aou_dsl.measuring.measured import measure
    from aou_dsl.measuring.recording import read_recording

    dest, urdf = kinova_copy
    res = _build(dest, "hesitant", urdf)
    assert res.ok, [(d.code, d.message) for d in res.diagnostics]
    tr = res.trajectory
    csv = dest / "hesitant.csv"
    rows = ["t," + ",".join(tr.joint_names)]
    rows += [",".join(repr(float(x)) for x in (t, *q)) for t, q in zip(tr.t, tr.q,
                                                                       strict=True)]
    csv.write_text("\n".join(rows) + "\n")
    rec = read_recording(str(csv), robot=urdf, goal=tuple(tr.goal))
    got, want = measure(rec).descriptors.to_json(), res.measured.descriptors.to_json()
    assert got.keys() == want.keys()
    for key, value in want.items():
        if value is None or REGISTRY[key].is_count:
            assert got[key] == value, key
        else:
            assert abs(got[key] - value) <= REGISTRY[key].tolerance(value), key


@pytest.mark.slow
def test_the_robots_page_is_what_the_report_script_writes():
    """docs/robots.md's report is the output of tools/robots_report.py, run now."""
    out = subprocess.run([sys.executable, str(ROOT / "tools" / "robots_report.py"),
                          "--check"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr


def test_every_robot_of_example_robot_data_is_in_the_arms_table():
    """The generated table (tools/every_arm.py) has one row per entry of the data
    package, built-in arms with the status it is given, and every entry a status."""
    import example_robot_data.robots_loader as rl

    sys.path.insert(0, str(ROOT / "tools"))
    try:
        from every_arm import every_arm
    finally:
        sys.path.remove(str(ROOT / "tools"))
    rows = [ln for ln in every_arm({"panda": "built in: P"}) if ln.startswith("| `")]
    names = [ln.split("`")[1] for ln in rows]
    assert names == sorted(rl.ROBOTS)
    by = dict(zip(names, rows, strict=True))
    assert by["panda"].endswith("| fixed | 7 | built in: P |")
    assert "free-flying" in by["a1"] and "not a fixed-base arm" in by["a1"]
    assert all(r.split("|")[-2].strip() for r in rows)  # every entry has a status
