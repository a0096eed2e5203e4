"""A trajectory document's header from another tool: each wrong field is named by its
path, keys the format does not name are kept out of the way, NPZ headers likewise."""

from __future__ import annotations

import io
import json
import zipfile

import numpy as np
import pytest

from aou_dsl.core.diagnostics import AouError
from aou_dsl.measuring.recording import read_json, read_npz, read_recording

T = [0.0, 0.1, 0.2, 0.3]
Q = [[0.1 * i] for i in range(4)]


def _doc(**changes) -> dict:
    doc = {"format": "aou-trajectory/1", "robot": "panda", "joint_names": ["panda_joint1"],
           "goal": {"position": [0.5, 0.0, 0.3]}, "t": T, "q": Q}
    doc.update(changes)
    return {k: v for k, v in doc.items() if v is not None}


def _refused(doc: dict) -> str:
    with pytest.raises(AouError) as info:
        read_json("x.json", json.dumps(doc))
    (d,) = info.value.diagnostics
    assert d.code == "R401"
    return d.message


@pytest.mark.parametrize("changes,path", [
    ({"joint_names": ["panda_joint1", 7]}, "`joint_names.1`"),
    ({"joint_names": []}, "`joint_names`"),
    ({"robot": ""}, "`robot`"),
    ({"ee_frame": 3}, "`ee_frame`"),
    ({"rate": "fast"}, "`rate`"),
    ({"duration": -1}, "`duration`"),
])
def test_a_wrong_field_is_named_by_its_path(changes, path):
    assert path in _refused(_doc(**changes))


@pytest.mark.parametrize("goal", [{"position": [0.5, 0.0]}, {"position": [0.5, "far", 0.3]},
                                  {"where": [0.5, 0.0, 0.3]}, "final", [1, 2, 3, 4]])
def test_a_wrong_goal_says_what_a_goal_is_and_what_was_found(goal):
    message = _refused(_doc(goal=goal))
    assert '`goal` must be {"position": [x, y, z]}' in message
    assert json.dumps(goal) in message


def test_a_goal_given_replaces_a_wrong_one_in_the_file():
    text = json.dumps(_doc(goal={"position": [1, 2]}))
    with pytest.raises(AouError):
        read_recording_text(text)
    assert read_recording_text(text, goal=(0.5, 0.0, 0.3)).goal == (0.5, 0.0, 0.3)


def test_an_infinite_goal_is_refused():
    text = json.dumps(_doc()).replace("[0.5, 0.0, 0.3]", "[0.5, Infinity, 0.3]")
    with pytest.raises(AouError) as info:
        read_json("x.json", text)
    assert "`goal` must be" in info.value.diagnostics[0].message


def read_recording_text(text: str, **kw):
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "x.json"
        path.write_text(text)
        return read_recording(str(path), **kw)


def test_missing_keys_are_listed_together():
    message = _refused({"format": "aou-trajectory/1", "t": T, "q": Q})
    assert "missing key" in message and "robot" in message and "joint_names" in message


def test_several_wrong_fields_are_all_named():
    message = _refused(_doc(robot="", ee_frame=3, goal=[1]))
    assert "`robot`" in message and "`ee_frame`" in message and "`goal`" in message


def test_keys_the_format_does_not_name_and_a_bare_goal_are_read():
    rec = read_json("x.json", json.dumps(_doc(goal=[0.5, 0.0, 0.3],
                                              my_tool={"operator": "A", "take": 3})))
    assert rec.goal == (0.5, 0.0, 0.3) and rec.robot == "panda"
    assert read_json("x.json", json.dumps(_doc(goal=None))).goal is None


def _npz(header: dict) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("header.json", json.dumps(header))
        for key, value in (("t", np.array(T)), ("q", np.array(Q))):
            arr = io.BytesIO()
            np.lib.format.write_array(arr, value)
            zf.writestr(f"{key}.npy", arr.getvalue())
    return buf.getvalue()


def test_an_npz_header_is_held_to_the_same_rules():
    header = {k: v for k, v in _doc().items() if k not in ("t", "q")}
    assert read_npz("x.npz", _npz(header)).goal == (0.5, 0.0, 0.3)
    with pytest.raises(AouError) as info:
        read_npz("x.npz", _npz({**header, "goal": {"position": [1, 2]}}))
    assert "`goal` must be" in info.value.diagnostics[0].message
    with pytest.raises(AouError) as info:
        read_npz("x.npz", _npz(["not", "an", "object"]))  # type: ignore[arg-type]
    assert info.value.diagnostics[0].code == "R401"
