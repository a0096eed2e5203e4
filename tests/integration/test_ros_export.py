"""ROS 2 export: the compiled trajectory as one trajectory_msgs/msg/JointTrajectory, in a
bag with MCAP storage (read back here with rosbags' own reader) and as YAML (read back
with PyYAML, as `ros2 topic pub` reads it)."""

import functools
import os

import numpy as np
import pytest

from aou_dsl.compiler.output import encode, output_paths, write_output
from aou_dsl.compiler.ros import MSGTYPE, TOPIC
from aou_dsl.core.diagnostics import AouError
from aou_dsl.driver.builder import build_file
from tests.conftest import BEHAVIOURS


@functools.cache
def _doc() -> dict:
    res = build_file(str(BEHAVIOURS / "confident.aou"), check=False)
    assert res.ok
    return res.document


def _read(bag: str):
    """Every message of a bag, deserialised by rosbags: (topic, type, message)."""
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(bag) as reader:
        return [(c.topic, c.msgtype, ts.deserialize_cdr(raw, c.msgtype))
                for c, _, raw in reader.messages()]


def test_the_bag_holds_the_json_trajectory(tmp_path):
    """`-o x.mcap` writes the bag folder `x` (metadata and an MCAP file); it holds one
    JointTrajectory on the controller's topic whose points are the JSON's samples: same
    joints, positions, velocities and accelerations, time_from_start = t (to the
    nanosecond); the first point (t = 0) is the start state, the last is at rest."""
    doc = _doc()
    dests, fmt = output_paths([("confident.aou", None)], str(tmp_path / "x.mcap"), None)
    assert fmt == "mcap" and dests == [str(tmp_path / "x")]
    write_output(dests[0], doc, fmt)
    assert sorted(os.listdir(tmp_path / "x")) == ["metadata.yaml", "x.mcap"]
    assert (tmp_path / "x" / "x.mcap").read_bytes()[:8] == b"\x89MCAP0\r\n"
    (topic, msgtype, msg), = _read(str(tmp_path / "x"))
    assert (topic, msgtype) == (TOPIC, MSGTYPE) == (
        "/joint_trajectory_controller/joint_trajectory", "trajectory_msgs/msg/JointTrajectory")
    assert list(msg.joint_names) == doc["joint_names"]
    pts = msg.points
    assert len(pts) == len(doc["t"])
    for key, name in (("q", "positions"), ("qd", "velocities"), ("qdd", "accelerations")):
        got = np.array([getattr(p, name) for p in pts])
        assert np.array_equal(got, np.array(doc[key])), key
    ns = np.array([p.time_from_start.sec * 10**9 + p.time_from_start.nanosec for p in pts])
    assert np.abs(ns - np.round(np.array(doc["t"]) * 1e9)).max() == 0
    assert ns[0] == 0 and np.all(np.diff(ns) > 0)
    assert ns[-1] == round(doc["duration"] * 1e9)
    assert np.abs(pts[0].velocities).max() == 0 and np.abs(pts[0].accelerations).max() == 0
    assert np.abs(pts[-1].velocities).max() < 1e-9
    assert np.abs(pts[-1].accelerations).max() < 1e-9
    assert msg.header.stamp.sec == 0 and msg.header.stamp.nanosec == 0


def test_a_bag_is_the_same_bytes_every_time(tmp_path):
    """The same document written twice gives the same files (nothing varies by run)."""
    a, b = tmp_path / "a" / "t", tmp_path / "b" / "t"
    a.parent.mkdir()
    b.parent.mkdir()
    write_output(str(a), _doc(), "mcap")
    write_output(str(b), _doc(), "mcap")
    for name in ("t.mcap", "metadata.yaml"):
        assert (a / name).read_bytes() == (b / name).read_bytes()


def test_writing_a_bag_replaces_a_bag_and_nothing_else(tmp_path, monkeypatch):
    """An existing bag is replaced whole; a folder that is not a bag is refused (I502)
    and left as it was; a failure leaves no bag and no temporary folder behind."""
    bag = tmp_path / "t"
    write_output(str(bag), _doc(), "mcap")
    first = (bag / "t.mcap").read_bytes()
    short = dict(_doc(), t=_doc()["t"][:5], q=_doc()["q"][:5], qd=_doc()["qd"][:5],
                 qdd=_doc()["qdd"][:5])
    write_output(str(bag), short, "mcap")
    assert len(_read(str(bag))[0][2].points) == 5 and (bag / "t.mcap").read_bytes() != first
    other = tmp_path / "notes"
    other.mkdir()
    (other / "keep.txt").write_text("mine")
    with pytest.raises(AouError) as err:
        write_output(str(other), _doc(), "mcap")
    assert err.value.diagnostics[0].code == "I502"
    assert os.listdir(other) == ["keep.txt"]
    from rosbags.rosbag2 import Writer

    def full(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Writer, "write", full)
    with pytest.raises(AouError) as err:  # the disk fills up while writing
        write_output(str(tmp_path / "full"), _doc(), "mcap")
    assert err.value.diagnostics[0].code == "I502"
    with pytest.raises(AouError):  # ... or while replacing a bag: the old one stays
        write_output(str(bag), _doc(), "mcap")
    assert sorted(os.listdir(tmp_path)) == ["notes", "t"]
    assert len(_read(str(bag))[0][2].points) == 5


def test_several_inputs_give_one_bag_each_in_the_folder(tmp_path):
    """With several inputs, -o is a folder and each input's bag is named after it."""
    dests, fmt = output_paths([("a.aou", None), ("b.aou", None)], str(tmp_path) + os.sep,
                              "mcap")
    assert fmt == "mcap" and dests == [str(tmp_path / "a"), str(tmp_path / "b")]
    bag = tmp_path / "one"
    write_output(str(bag), _doc(), "mcap")
    dests, _ = output_paths([("one.aou", None)], str(bag), "mcap")  # an existing bag
    assert dests == [str(bag)]


def test_the_yaml_is_the_same_message(tmp_path):
    """The YAML parses (PyYAML, as ROS 2's command line) into the bag's message: every
    number a float equal to the JSON's, the same joints and times."""
    yaml = pytest.importorskip("yaml")
    doc = _doc()
    data = yaml.safe_load(encode(doc, "yaml"))
    bag = tmp_path / "t"
    write_output(str(bag), doc, "mcap")
    msg = _read(str(bag))[0][2]
    assert data["joint_names"] == list(msg.joint_names)
    assert data["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}
    assert len(data["points"]) == len(msg.points)
    for p, m in zip(data["points"], msg.points, strict=True):
        for name in ("positions", "velocities", "accelerations"):
            assert all(isinstance(x, float) for x in p[name])
            assert p[name] == getattr(m, name).tolist()
        assert p["effort"] == []
        assert p["time_from_start"] == {"sec": m.time_from_start.sec,
                                        "nanosec": m.time_from_start.nanosec}


def test_small_numbers_stay_floats_in_yaml():
    """1e-05 is a string to YAML 1.1; the export writes 1.0e-05."""
    yaml = pytest.importorskip("yaml")
    doc = {"t": [0.0], "q": [[1e-05, -2e-300]], "qd": [[0.0, 1e+20]], "qdd": [[0.5, 3.0]],
           "joint_names": ["a", "b"], "behaviour": "x", "robot": "panda"}
    p = yaml.safe_load(encode(doc, "yaml"))["points"][0]
    assert p["positions"] == [1e-05, -2e-300] and p["velocities"] == [0.0, 1e20]
