"""The trajectory file's encoder: orjson where it is installed, the standard ``json``
module where not, the same bytes either way; every float reads back as the float that
was written, the documents validate against the shipped schema, and documents written
before (Python's ``repr`` floats, ASCII escapes) read as they did.

The expected floats come from the arrays themselves (read back bit for bit), not from
what the encoder printed; the adversarial values are chosen where the two encoders'
float formats part (exponents from -5 to -9, the largest and the smallest doubles,
negative zero, values that are not numbers) and where text could be mistaken for a
number (``1e-05`` inside a string)."""

from __future__ import annotations

import io
import json
import math
import random
import struct
import zipfile

import jsonschema
import numpy as np
import pytest

from aou_dsl.compiler import output
from aou_dsl.compiler.output import SAMPLE_KEYS, array_document, encode, json_bytes
from aou_dsl.driver.builder import build_file
from aou_dsl.measuring.recording import read_json, read_recording
from aou_dsl.measuring.schema_files import shipped_text
from tests.conftest import BEHAVIOURS

orjson = pytest.importorskip("orjson")

ENCODERS = ("orjson", "json")


@pytest.fixture(scope="module")
def built():
    res = build_file(str(BEHAVIOURS / "curious.aou"))
    assert res.ok, [d.message for d in res.diagnostics]
    return res


@pytest.fixture
def encoder(request, monkeypatch):
    """The encoder a test runs with: orjson, or the standard module as where orjson is
    not installed."""
    monkeypatch.setattr(output, "_FAST", request.param == "orjson")
    return request.param


def _bits(a) -> bytes:
    """An array's floats to the bit (-0.0 is not 0.0 here)."""
    return np.ascontiguousarray(a, dtype=np.float64).tobytes()


def test_orjson_is_used_where_it_is_installed():
    """The probe that keeps an orjson writing floats another way out passes with the
    orjson the tests install: the fast path is what these tests exercise."""
    assert output._FAST


@pytest.mark.parametrize("encoder", ENCODERS, indirect=True)
def test_a_document_reads_back_equal_to_its_arrays(built, encoder):
    tr = built.trajectory
    doc = array_document(built.header, tr)
    back = json.loads(encode(doc, "json"))
    for key in SAMPLE_KEYS:
        assert _bits(back[key]) == _bits(getattr(tr, key)), key
    assert {k: v for k, v in back.items() if k not in SAMPLE_KEYS} == json.loads(
        json.dumps(built.header))
    rows = [line.split(",") for line in encode(doc, "csv").decode().splitlines()
            if not line.startswith("#")]
    assert rows[0] == ["t", *tr.joint_names]
    table = np.array([[float(x) for x in row] for row in rows[1:]])
    assert _bits(table[:, 0]) == _bits(tr.t) and _bits(table[:, 1:]) == _bits(tr.q)
    with np.load(io.BytesIO(encode(doc, "npz")), allow_pickle=False) as npz:
        for key in SAMPLE_KEYS:
            assert _bits(npz[key]) == _bits(getattr(tr, key)), key


def test_arrays_and_lists_and_both_encoders_give_the_same_bytes(built, monkeypatch):
    """The samples as the trajectory's arrays (what aouc writes) or as lists (the
    document of the API), by orjson or by the standard module: one file, byte for byte,
    in every format that is text or holds text."""
    arrays = array_document(built.header, built.trajectory)
    lists = built.document
    for fmt in ("json", "csv", "npz"):
        fast = encode(arrays, fmt)
        assert encode(lists, fmt) == fast, fmt
        monkeypatch.setattr(output, "_FAST", False)
        assert encode(arrays, fmt) == fast, fmt
        assert encode(lists, fmt) == fast, fmt
        monkeypatch.setattr(output, "_FAST", True)


def _hard_floats(n: int = 20_000) -> list[float]:
    rng = random.Random(32)
    out = [0.0, -0.0, 1.0, 0.1, 1 / 3, 5e-324, -5e-324, 2.2250738585072014e-308,
           1.7976931348623157e308, -1.7976931348623157e308, 1e15, 1e16, 1e17, 1e22,
           123456789012345680.0, 9999999999999998.0]
    for e in range(-12, 18):  # around every switch between plain and exponent form
        out += [10.0 ** e, -(10.0 ** e), 1.2345678901234567 * 10.0 ** e,
                math.nextafter(10.0 ** e, 0.0), math.nextafter(10.0 ** e, math.inf)]
    while len(out) < n:
        x = struct.unpack("<d", struct.pack("<Q", rng.getrandbits(64)))[0]
        if math.isfinite(x):
            out.append(x)
        out.append(rng.uniform(-1, 1) * 10.0 ** rng.randint(-11, 3))
    return out


def test_the_standard_module_writes_what_orjson_writes(monkeypatch):
    """Floats of every size (and in NumPy arrays and scalars), values that are not
    numbers, text that looks like a float, text outside ASCII, escapes, nesting: the
    same bytes from both encoders, and every float reads back as itself."""
    floats = _hard_floats()
    doc = {"format": "aou-trajectory/1", "behaviour": "h\u00e9sitant \u2028 \x01 \x7f",
           "robot": 'arms/1e-05 "quoted" \\ 2.5e-07.urdf', "q": np.array(floats),
           "t": floats, "nested": {"a": [np.float64(1.5e-07), (1e-05, None, True)],
                                   "b": [float("nan"), float("inf"), -float("inf")]},
           "count": 3, "none": None}
    fast = json_bytes(doc)
    monkeypatch.setattr(output, "_FAST", False)
    assert json_bytes(doc) == fast
    back = json.loads(fast)
    assert _bits(back["q"]) == _bits(floats) and _bits(back["t"]) == _bits(floats)
    assert back["robot"] == doc["robot"] and back["behaviour"] == doc["behaviour"]
    assert back["nested"] == {"a": [1.5e-07, [1e-05, None, True]], "b": [None, None, None]}
    assert fast.endswith(b"\n") and b"\\u00e9" not in fast  # UTF-8, not escapes
    table = np.array(floats[:len(floats) // 7 * 7]).reshape(-1, 7)
    csv = output._csv_rows(table[:, 0], table[:, 1:])
    monkeypatch.setattr(output, "_FAST", True)
    assert output._csv_rows(table[:, 0], table[:, 1:]) == csv
    assert _bits([float(x) for line in csv.decode().split() for x in line.split(",")]) \
        == _bits(table)


def test_floats_of_less_precision_are_written_as_their_float64_by_either_encoder(
        monkeypatch):
    """orjson writes a float32 as the shortest float32 (``0.1``); its list holds the
    float64 of it (``0.10000000149011612``): such a document is written the standard
    module's way by both, so its bytes do not depend on the encoder installed."""
    doc = {"a": np.array([0.1, 1e-07], dtype=np.float32), "b": [[1.0, np.float32(0.1)]],
           "c": np.float16(0.1), "d": np.array([1, 2], dtype=np.int8), "e": np.bool_(True)}
    fast = json_bytes(doc)
    monkeypatch.setattr(output, "_FAST", False)
    assert json_bytes(doc) == fast
    back = json.loads(fast)
    assert back["a"] == np.array([0.1, 1e-07], dtype=np.float32).astype(float).tolist()
    assert back["b"][0][1] == float(np.float32(0.1)) != 0.1
    assert back["c"] == float(np.float16(0.1)) and back["d"] == [1, 2] and back["e"] is True


@pytest.mark.parametrize("encoder", ENCODERS, indirect=True)
def test_a_lone_surrogate_is_written_as_its_escape(encoder):
    """A path from a file name that is not UTF-8 holds a lone surrogate, which orjson
    refuses: it is written as the standard module writes it, its ``\\u`` escape, by
    either encoder, and reads back as itself."""
    doc = {"robot": "arm\udcff.urdf", "q": np.array([[1e-05, 2.0]])}
    got = json_bytes(doc)
    assert got == b'{"robot":"arm\\udcff.urdf","q":[[0.00001,2.0]]}\n'
    assert json.loads(got)["robot"] == doc["robot"]


@pytest.mark.parametrize("encoder", ENCODERS, indirect=True)
def test_a_written_document_validates_against_the_shipped_schema(built, encoder):
    validator = jsonschema.Draft202012Validator(json.loads(shipped_text(
        "trajectory.schema.json")))
    doc = json.loads(encode(array_document(built.header, built.trajectory), "json"))
    assert [e.message for e in validator.iter_errors(doc)] == []
    del doc["q"]  # the validator can refuse
    assert [e.message for e in validator.iter_errors(doc)] != []


def test_documents_written_before_read_as_the_new_ones(built, tmp_path):
    """A document written before this encoder (the standard module's floats, ``1e-05``,
    and ASCII escapes) and a CSV of ``repr`` floats read as the new ones do: the same
    samples to the bit."""
    doc = built.document
    old = (json.dumps(doc, separators=(",", ":")) + "\n").encode()
    new = encode(array_document(built.header, built.trajectory), "json")
    assert old != new  # (the floats' form changed: this compares two writings)
    a, b = read_json("old.json", old.decode()), read_json("new.json", new.decode())
    for key in SAMPLE_KEYS:
        assert _bits(getattr(a, key)) == _bits(getattr(b, key)) \
            == _bits(getattr(built.trajectory, key)), key
    old_csv = "\n".join(["t," + ",".join(doc["joint_names"])] + [
        ",".join(repr(v) for v in [t, *row]) for t, row in zip(doc["t"], doc["q"],
                                                              strict=True)]) + "\n"
    (tmp_path / "old.csv").write_text(old_csv)
    (tmp_path / "new.csv").write_bytes(encode(doc, "csv"))
    goal = tuple(doc["goal"]["position"])
    a, b = (read_recording(str(tmp_path / f"{k}.csv"), robot=doc["robot"], goal=goal)
            for k in ("old", "new"))
    assert _bits(a.t) == _bits(b.t) and _bits(a.q) == _bits(b.q)


def test_npz_members_are_stored_not_deflated(built):
    """An NPZ is written at the speed of copying: its arrays are stored as they are
    (and read by NumPy as any archive's)."""
    data = encode(array_document(built.header, built.trajectory), "npz")
    with zipfile.ZipFile(io.BytesIO(data)) as zf:
        assert {i.filename: i.compress_type for i in zf.infolist()} == {
            f"{k}.npy": zipfile.ZIP_STORED for k in SAMPLE_KEYS} | {
            "header.json": zipfile.ZIP_STORED}


@pytest.mark.parametrize("fmt", ["json", "csv", "npz"])
def test_aouc_compile_writes_without_making_the_samples_lists(built, tmp_path, fmt,
                                                              monkeypatch, capsys):
    """``aouc compile`` writes from the trajectory's arrays: the document's lists of
    samples (a float object each, a serial cost per file in a batch's parent) are never
    made, and the file holds the arrays to the bit."""
    from aou_dsl.cli.commands import main

    def refused(*args, **kwargs):
        raise AssertionError("the document's lists were made")

    monkeypatch.setattr(output, "with_samples", refused)
    out = tmp_path / f"c.{fmt}"
    assert main(["compile", str(BEHAVIOURS / "curious.aou"), "-o", str(out)]) == 0
    tr = built.trajectory
    if fmt == "json":
        back = json.loads(out.read_bytes())
        assert all(_bits(back[k]) == _bits(getattr(tr, k)) for k in SAMPLE_KEYS)
    else:
        got = read_recording(str(out), robot=tr.robot, goal=tuple(tr.goal))
        assert _bits(got.t) == _bits(tr.t) and _bits(got.q) == _bits(tr.q)
