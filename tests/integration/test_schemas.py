"""Files that describe themselves: every trajectory document says where its end-effector
frame is and which robot (URDF path and SHA-256) made it; the JSON Schemas of the
document and of the robot description ship with the package, equal to what the pydantic
models give, and an independent validator (``jsonschema``) accepts every written file."""

from __future__ import annotations

import hashlib
import io
import json
import os
import tomllib
import zipfile

import jsonschema
import pytest

from aou_dsl.compiler.output import encode
from aou_dsl.core.diagnostics import AouError
from aou_dsl.driver.builder import build_file
from aou_dsl.measuring.measured import measure
from aou_dsl.measuring.recording import read_recording
from aou_dsl.measuring.schema_files import SCHEMA_NAMES, schema_text, shipped_text
from tests.conftest import BEHAVIOURS

SAMPLES = ("t", "q", "qd", "qdd")


def _validator(name: str, *, header_only: bool = False):
    body = json.loads(shipped_text(name))
    if header_only:  # an NPZ's header.json: the document but its samples
        body = body | {"required": [k for k in body["required"] if k not in SAMPLES]}
    jsonschema.Draft202012Validator.check_schema(body)
    return jsonschema.Draft202012Validator(body)


def _errors(validator, doc) -> list[str]:
    return [e.message for e in validator.iter_errors(doc)]


@pytest.mark.parametrize("name", SCHEMA_NAMES)
def test_the_shipped_schema_is_what_the_models_give(name):
    """A model changed without `python tools/write_schemas.py` fails here."""
    assert shipped_text(name) == schema_text(name), \
        f"aou_dsl/schemas/{name} is out of date: run python tools/write_schemas.py"


@pytest.fixture(scope="module")
def built():
    """The hesitant behaviour on the Panda (the frame is a URDF link) and the curious on
    the Z1 (a frame aou adds, 15 cm ahead of its link)."""
    out = {}
    for robot, stem in (("panda", "hesitant"), ("z1", "curious")):
        res = build_file(str(BEHAVIOURS / f"{stem}.aou"), robot=robot)
        assert res.ok, [d.message for d in res.diagnostics]
        out[robot] = res
    return out


def test_a_compiled_document_says_where_its_frame_is_and_which_robot(built):
    import example_robot_data as erd

    z1 = built["z1"].document
    assert z1["ee_frame"] == "aou_ee"
    frame = z1["ee_frame_definition"]
    assert frame["parent"] == "gripperStator"
    assert frame["xyz"] == [0.15, 0.0, 0.0]  # the Z1's tool tip, ahead along +x
    # rpy turns the link's +x (its forward axis) into the frame's z axis
    assert frame["rpy"] == pytest.approx([1.5707963267948966, 0.0, 1.5707963267948966])
    ident = z1["robot_identity"]
    assert ident["name"] == "z1" and ident["urdf"] == "z1_description/urdf/z1.urdf"
    text = open(os.path.join(erd.getModelPath(ident["urdf"]), ident["urdf"]), "rb").read()
    assert ident["sha256"] == hashlib.sha256(text).hexdigest()
    panda = built["panda"].document
    assert panda["ee_frame_definition"] == {"parent": "panda_hand_tcp", "xyz": [0.0, 0.0, 0.0],
                                            "rpy": [0.0, 0.0, 0.0]}


def test_every_written_document_validates_against_the_shipped_schema(built):
    full = _validator("trajectory.schema.json")
    header = _validator("trajectory.schema.json", header_only=True)
    defs = json.loads(shipped_text("trajectory.schema.json"))["$defs"]
    for res in built.values():
        doc = json.loads(encode(res.document, "json"))
        assert _errors(full, doc) == []
        with zipfile.ZipFile(io.BytesIO(encode(res.document, "npz"))) as zf:
            assert _errors(header, json.loads(zf.read("header.json"))) == []
        # a CSV carries the frame and the identity in its comment lines
        notes = dict(line[2:].split(": ", 1) for line in
                     encode(res.document, "csv").decode().splitlines() if line.startswith("#"))
        for key, model in (("ee_frame_definition", "FrameDef"),
                           ("robot_identity", "RobotIdentity")):
            sub = jsonschema.Draft202012Validator(defs[model])
            assert json.loads(notes[key]) == res.document[key]
            assert _errors(sub, json.loads(notes[key])) == []


def test_the_schema_refuses_what_a_reader_would(built):
    """The validator is not a rubber stamp: a document without the frame, with a wrong
    digest or a sample that is not a number fails."""
    full = _validator("trajectory.schema.json")
    doc = json.loads(encode(built["panda"].document, "json"))
    assert _errors(full, {k: v for k, v in doc.items() if k != "ee_frame_definition"})
    assert _errors(full, doc | {"robot_identity": doc["robot_identity"] | {"sha256": "x"}})
    assert _errors(full, doc | {"t": ["0.0", *doc["t"][1:]]})
    assert _errors(full, doc | {"ee_frame_definition": {"parent": "a", "xyz": [0, 0]}})


def test_measure_reads_the_frame_from_the_file_on_an_arm_aou_does_not_know(built, tmp_path):
    """The Z1's file, measured with a robot description of the same URDF that calls its
    end-effector `gripperStator` (no `aou_ee` in it): the frame comes from the file."""
    import example_robot_data as erd

    sub = "z1_description/urdf/z1.urdf"
    urdf = tmp_path / "my_z1.urdf"
    urdf.write_bytes(open(os.path.join(erd.getModelPath(sub), sub), "rb").read())
    desc = tmp_path / "my_z1.toml"
    desc.write_text('urdf = "my_z1.urdf"\nee_frame = "gripperStator"\nforward = "+z"\n'
                    "goal = [0.4, 0.0, 0.2]\nfrom = [-0.8, 0.0, 0.6]\n"
                    "posture = [0.0, 0.99, -1.1, 0.76, 0.0, 0.0]\n")
    path = tmp_path / "curious.json"
    doc = built["z1"].document
    path.write_bytes(encode(doc, "json"))
    rec = read_recording(str(path), robot=str(desc))
    m = measure(rec)
    assert m.descriptors["horizontal_gaze"] == pytest.approx(20.0, abs=0.1)
    assert m.gaze_error < 1e-3
    # the same file without the definition: the frame is nowhere to be found
    path.write_bytes(encode({k: v for k, v in doc.items() if k != "ee_frame_definition"},
                            "json"))
    with pytest.raises(AouError) as err:
        measure(read_recording(str(path), robot=str(desc)))
    assert err.value.diagnostics[0].code == "R402"


def test_the_robot_schema_has_the_keys_a_description_may_have_and_accepts_aous_own():
    from aou_dsl.robot.description import KEYS
    from aou_dsl.robot.load import load_robot
    from aou_dsl.robot.summary import robot_toml

    body = json.loads(shipped_text("robot.schema.json"))
    assert set(body["properties"]) == set(KEYS)
    v = _validator("robot.schema.json")
    for name in ("z1", "kinova", "panda"):
        text = robot_toml(load_robot(name))
        assert _errors(v, tomllib.loads(text)) == [], text
    for bad in ({"urdf": "a.urdf", "robot": "ur5"}, {"goal": [0, 0, 0]},
                {"robot": "ur5", "joint_accel": -1}, {"robot": "ur5", "forward": "up"},
                {"robot": "ur5", "goal": [1, 2]}, {"robot": "ur5", "colour": "red"}):
        assert _errors(v, bad), bad


def test_aouc_measure_of_a_file_on_a_urdf_aou_does_not_know(built, tmp_path, capsys):
    """The command a user runs: `aouc measure FILE.json --robot URDF`, the Z1's file
    measured on the Z1's URDF copied out of its package (aou derives another frame for
    it): the file's own frame is used and the behaviour measures as compiled."""
    import example_robot_data as erd

    from aou_dsl.cli.commands import main

    sub = "z1_description/urdf/z1.urdf"
    urdf = tmp_path / "arm.urdf"
    urdf.write_bytes(open(os.path.join(erd.getModelPath(sub), sub), "rb").read())
    path = tmp_path / "curious.json"
    path.write_bytes(encode(built["z1"].document, "json"))
    assert main(["measure", str(path), "--robot", str(urdf), "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    want = built["z1"].document["descriptors"]["measured"]
    assert out["descriptors"]["horizontal_gaze"] == pytest.approx(want["horizontal_gaze"],
                                                                  abs=0.05)
    assert out["cv"]["state"] == "curious"
