"""Input a newcomer really writes: files saved with a byte-order mark, files of formats
aou does not read, a bad row of a trajectory document, and the common slips in `.aou`
text (a decimal comma, a degree sign, `sec` for `s`, `for=`). Each is read, or refused
with a message that names the problem where it is and a hint whose fix works."""

from __future__ import annotations

import io
import json
import re
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from aou_dsl.cli.commands import EXIT_OK, EXIT_USAGE, main
from aou_dsl.core.diagnostics import AouError, has_errors
from aou_dsl.lang.linter import lint_file, lint_source
from aou_dsl.lang.parse import parse
from aou_dsl.measuring.recording import read_recording
from aou_dsl.robot.load import load_arm
from tests.conftest import BEHAVIOURS, ROOT

BOM = "\ufeff"
T = [0.0, 0.1, 0.2, 0.3, 0.4]
Q = [[0.1 * i - 0.2] for i in range(5)]


def _doc(**changes) -> dict:
    return {"format": "aou-trajectory/1", "robot": "panda", "joint_names": ["panda_joint1"],
            "goal": {"position": [0.5, 0.0, 0.3]}, "t": T, "q": Q, **changes}


def _csv_text() -> str:
    return "# robot: panda\n# goal: 0.5,0,0.3\nt,panda_joint1\n" + "".join(
        f"{t},{q[0]}\n" for t, q in zip(T, Q, strict=True))


def _npz_bytes() -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        doc = {k: v for k, v in _doc().items() if k not in ("t", "q")}
        zf.writestr("header.json", json.dumps(doc))
        for key, value in (("t", T), ("q", Q)):
            arr = io.BytesIO()
            np.save(arr, np.asarray(value, float))
            zf.writestr(f"{key}.npy", arr.getvalue())
    return buf.getvalue()


def _refused(code: str, fn, *args, **kw):
    with pytest.raises(AouError) as err:
        fn(*args, **kw)
    (d,) = err.value.diagnostics
    assert d.code == code, d.message
    return d


def _where(d) -> tuple:
    return (d.code, d.span.line, d.span.col, d.span.end_line, d.span.end_col, d.message)


# --- 1. a byte-order mark --------------------------------------------------------------

@pytest.mark.parametrize("text", [
    *((BEHAVIOURS / f"{n}.aou").read_text() for n in ("hesitant", "curious")),
    "approach a=0.1 b=2\npause 1s\n",  # an error on the first line: its column counts
    "sequence {\n  approach 0.05m\n  pause 0.1s\n}\n",
])
def test_a_file_with_a_byte_order_mark_lints_as_without_it(tmp_path, text):
    plain, marked = tmp_path / "plain.aou", tmp_path / "marked.aou"
    plain.write_text(text, encoding="utf-8")
    marked.write_text(text, encoding="utf-8-sig")  # what Windows Notepad saves
    assert marked.read_bytes().startswith(b"\xef\xbb\xbf")
    want = [_where(d) for d in lint_file(str(plain)).diagnostics]
    got = lint_file(str(marked)).diagnostics
    assert [_where(d) for d in got] == want and not any(d.code == "S003" for d in got)
    assert [_where(d) for d in lint_source(BOM + text, "plain.aou").diagnostics] == want
    assert parse(BOM + text) == parse(text)


def test_commands_read_a_file_with_a_byte_order_mark(tmp_path, capsys):
    path = tmp_path / "u12.aou"
    path.write_bytes(b"\xef\xbb\xbfapproach a=0.1\npause 1s\n")
    for argv in (["lint", str(path)], ["explain", str(path)]):
        assert main(argv) == EXIT_OK, capsys.readouterr().err
    from aou_dsl.driver.builder import build_file

    marked = build_file(str(path), check=False)
    plain = tmp_path / "plain.aou"
    plain.write_text("approach a=0.1\npause 1s\n")
    assert marked.ok and np.array_equal(marked.trajectory.q,
                                        build_file(str(plain), check=False).trajectory.q)


@pytest.mark.parametrize("name,text", [("r.csv", _csv_text()),
                                       ("r.json", json.dumps(_doc(), indent=1))])
def test_recordings_with_a_byte_order_mark_read_as_without_it(tmp_path, name, text):
    plain, marked = tmp_path / name, tmp_path / f"bom-{name}"
    plain.write_text(text)
    marked.write_text(text, encoding="utf-8-sig")
    a, b = read_recording(str(plain)), read_recording(str(marked))
    assert np.array_equal(a.t, b.t) and np.array_equal(a.q, b.q) and a.goal == b.goal


def test_a_robot_file_with_a_byte_order_mark_loads_and_points_at_its_lines(tmp_path, capsys):
    assert main(["robot", "panda", "--format", "toml"]) == EXIT_OK
    text = capsys.readouterr().out
    path = tmp_path / "bom-panda.toml"
    path.write_text(text, encoding="utf-8-sig")
    arm, named = load_arm(str(path)), load_arm("panda")
    assert np.array_equal(arm.vmax, named.vmax) and np.array_equal(arm.lower, named.lower)
    from aou_dsl.robot.description import read_description

    bad = tmp_path / "bad.toml"
    bad.write_text('robot = "panda"\nstart_direction = [-0.6, 0.0, 0.8]\n',
                   encoding="utf-8-sig")
    assert _refused("V109", read_description, str(bad)).span.line == 2


def test_text_in_another_encoding_says_which_and_where(tmp_path):
    wide = tmp_path / "wide.aou"
    wide.write_text("approach a=0.1\npause 1s\n", encoding="utf-16")  # Notepad's "Unicode"
    (d,) = lint_file(str(wide)).diagnostics
    assert d.code == "I501" and "UTF-16" in d.message and "UTF-8" in (d.hint or "")
    latin = tmp_path / "latin.aou"
    latin.write_bytes("pause 1s\n# caf\u00e9\n".encode("latin-1"))
    (d,) = lint_file(str(latin)).diagnostics
    assert d.code == "I501" and "UTF-8" in d.message and (d.span.line, d.span.col) == (2, 6)


# --- 2. formats aou does not read --------------------------------------------------------

def _bag(tmp_path) -> str:
    bag = tmp_path / "run1"
    bag.mkdir()
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information:\n  version: 9\n")
    (bag / "run1.mcap").write_bytes(b"\x89MCAP0\r\n")
    return str(bag)


@pytest.mark.parametrize("name,content,kind", [
    ("x.mcap", b"\x89MCAP0\r\n\x01\x02", "ROS 2 bag"),
    ("x.db3", b"SQLite format 3\x00", "ROS 2 bag"),
    ("x.yaml", b"header:\n  stamp: {sec: 0}\njoint_names: [a]\n", "YAML"),
    ("README.md", (ROOT / "README.md").read_bytes(), "`.md`"),
    ("notes", b"some words\n", "without an extension"),
])
def test_a_format_aou_does_not_read_is_named_with_the_ones_it_does(tmp_path, capsys, name,
                                                                    content, kind):
    path = tmp_path / name
    path.write_bytes(content)
    d = _refused("I501", read_recording, str(path))
    assert kind in d.message and "JSON, CSV and NPZ" in d.message and d.hint
    assert "codec" not in d.message and "not valid JSON" not in d.message
    assert main(["measure", str(path)]) == EXIT_USAGE
    assert "I501" in capsys.readouterr().err


def test_a_bag_folder_is_named_a_bag(tmp_path):
    d = _refused("I501", read_recording, _bag(tmp_path))
    assert "ROS 2 bag" in d.message and "--format json" in (d.hint or "")


@pytest.mark.parametrize("name,content", [("r.txt", _csv_text().encode()),
                                          ("r.dat", json.dumps(_doc()).encode()),
                                          ("r.bin", _npz_bytes()),
                                          ("R.CSV", _csv_text().encode())])
def test_a_trajectory_under_another_extension_is_read_by_its_content(tmp_path, name,
                                                                      content):
    path = tmp_path / name
    path.write_bytes(content)
    rec = read_recording(str(path))
    assert rec.t.tolist() == T and rec.q.tolist() == Q and rec.goal == (0.5, 0.0, 0.3)


# --- 3. a bad row of a trajectory document is pointed at ----------------------------------

#: A document laid out by hand: sample i of `q` is on line 5 + i, from column 8.
LAYOUT = ('{"format": "aou-trajectory/1", "robot": "panda",\n'
          ' "joint_names": ["panda_joint1"], "rate": RATE,\n'
          ' "t": [0.0, 0.1, 0.2, T3, 0.4],\n'
          ' "q": [\n'
          '       [-0.2],\n'
          '       [-0.1],\n'
          '       [Q2],\n'
          '       [0.1],\n'
          '       [0.2]]}\n')


def _layout(rate="10", t3="0.3", q2="0.0") -> str:
    return LAYOUT.replace("RATE", rate).replace("T3", t3).replace("Q2", q2)


@pytest.mark.parametrize("q2,where,words", [
    ("0.0, 1", (7, 8), "has 2 values"),          # a short (here: long) row
    ("NaN", (7, 9), "not a finite number"),      # the joint's value in the row
    ('"x"', (7, 9), "not a number"),
])
def test_a_bad_row_is_pointed_at_where_it_is(q2, where, words):
    d = _refused("R401", read_recording_text, _layout(q2=q2))
    assert (d.span.line, d.span.col) == where and "sample 2" in d.message
    assert words in d.message


@pytest.mark.parametrize("t3,words", [("0.1", "increase strictly"), ('"soon"', "not a number"),
                                      ("Infinity", "not a finite number")])
def test_a_bad_time_is_pointed_at_where_it_is(t3, words):
    d = _refused("R401", read_recording_text, _layout(t3=t3))
    assert (d.span.line, d.span.col) == (3, 23) and "sample 3" in d.message
    assert words in d.message


def test_a_wrong_header_field_is_pointed_at():
    d = _refused("R401", read_recording_text, _layout(rate='"fast"'))
    assert (d.span.line, d.span.col) == (2, 43) and "`rate`" in d.message


def read_recording_text(text: str, **kw):
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "x.json"
        path.write_text(text)
        return read_recording(str(path), goal=(0.5, 0.0, 0.3), **kw)


# --- 4. slips in `.aou` text ------------------------------------------------------------

def _one_error(text: str):
    errors = [d for d in lint_source(text, "s.aou").diagnostics if d.severity == "error"]
    assert len(errors) == 1, [(d.code, d.message) for d in errors]
    return errors[0]


def _clean(text: str) -> bool:
    return not has_errors(lint_source(text, "s.aou").diagnostics)


def _suggested(d) -> str:
    """The text a hint suggests writing (`write `X``, `did you mean `X`?`)."""
    m = re.search(r"(?:write|did you mean) `([^`]+)`", d.hint or "")
    assert m, d.hint
    return m.group(1)


def _span_text(text: str, d) -> str:
    line = text.splitlines()[d.span.line - 1]
    return line[d.span.col - 1:d.span.end_col - 1]


@pytest.mark.parametrize("text,slip", [
    ("approach a=0.1\npause 1,5s\n", "1,5s"),
    ("approach a=0,1\npause 1s\n", "0,1"),
    ("shiver 10deg for 1,25s\npause 1s\n", "1,25s"),
])
def test_a_decimal_comma_is_named_and_its_point_suggested(text, slip):
    d = _one_error(text)
    assert d.code == "S001" and "decimal mark is a point" in d.message
    assert "STRING" not in d.message and _span_text(text, d) == slip
    assert _suggested(d) == slip.replace(",", ".")
    assert _clean(text.replace(slip, _suggested(d)))


def _with_others(statement: str) -> str:
    """``statement`` in a file that has an approach and a pause (descriptor form: each
    kind once)."""
    others = [s for s in ("approach a=0.1", "pause 1s") if s.split()[0] != statement.split()[0]]
    return "\n".join([*others, statement]) + "\n"


@pytest.mark.parametrize("unit,meant,statement", [
    *((u, "s", "pause 1.25{}") for u in ("sec", "secs", "second", "seconds", "Sec", "S")),
    *((u, "ms", "pause 250{}") for u in ("msec", "msecs", "milliseconds", "MS")),
    *((u, "deg", "tilt 20{}") for u in ("degree", "degrees", "degs", "Deg", "DEG")),
    *((u, "rad", "tilt 0.3{}") for u in ("rads", "radians")),
    *((u, "Hz", "shiver 10deg f=3{}") for u in ("hz", "HZ", "hertz")),
    ("mps", "m/s", "approach v=0.2{}"), ("m/s2", "m/s^2", "approach a=0.1{}"),
    ("m/sec^2", "m/s^2", "approach a=0.1{}"), ("deg/sec", "deg/s", "tilt 20deg v=10{}"),
])
def test_a_unit_written_another_way_suggests_the_real_one(unit, meant, statement):
    text = _with_others(statement.format(unit))
    d = _one_error(text)
    quantity = statement.format(unit).split()[-1].split("=")[-1]
    assert d.code == "V104" and f"`{unit}`" in d.message
    assert _suggested(d) == quantity[:-len(unit)] + meant
    assert _clean(_with_others(statement.format(meant)))


def test_a_unit_of_another_dimension_is_not_suggested():
    d = _one_error("pause 20degrees\n")
    assert d.code == "V104" and not (d.hint and "deg" in d.hint)


def test_for_written_as_a_key_suggests_for_with_a_space():
    text = "approach a=0.1\npause 1s\nshiver 10deg for=1.25s\n"
    d = _one_error(text)
    assert d.code == "V112" and "`for DURATION`" in d.message
    assert _suggested(d) == "for 1.25s" and _clean(text.replace("for=1.25s", "for 1.25s"))


@pytest.mark.parametrize("text,slip,fix,words", [
    ("tilt 20°\n", "20°", "20deg", "degree sign"),
    ("tilt 20 °\n", "20 °", "20deg", "degree sign"),
    ("sequence {\n  tilt \u221220deg\n}\n", "\u2212", "-", "minus"),
    ("robot \u201cpanda.urdf\u201d\n", "\u201cpanda.urdf\u201d", '"panda.urdf"', "quote"),
    ("tilt 20\u00a0deg\n", "\u00a0", "", "U+00A0"),
    ("pause 1s \u00d73\napproach\n", "\u00d7", "x", "multiplication"),
])
def test_a_look_alike_character_is_named_with_what_to_write(text, slip, fix, words):
    d = _one_error(text)
    assert d.code == "S003" and words in d.message and d.hint
    assert (d.span.line, d.span.col) == _position(text, next(c for c in slip if ord(c) > 127))
    fixed = lint_source(text.replace(slip, fix), "s.aou").diagnostics
    assert not any(d.code.startswith("S") for d in fixed), fixed
    if fix == "20deg":
        assert _suggested(d) == fix


def _position(text: str, ch: str) -> tuple[int, int]:
    """1-based line and column of the first ``ch`` in ``text``."""
    before = text[:text.index(ch)]
    return before.count("\n") + 1, len(before) - (before.rfind("\n") + 1) + 1


@pytest.mark.parametrize("statement,spaced,glued", [
    ("pause 1.25 s", "1.25 s", "1.25s"), ("tilt 20 deg", "20 deg", "20deg"),
    ("retreat 5 cm x2", "5 cm", "5cm"), ("shiver 10deg f=3 Hz", "f=3 Hz", "f=3Hz"),
    ("shiver 10deg for 1.5 sec", "1.5 sec", "1.5s"),
])
def test_a_unit_apart_from_its_number_is_one_error_with_the_glued_form(statement, spaced,
                                                                       glued):
    text = _with_others(statement).replace("pause 1s", "pause 1s x3")
    d = _one_error(text)
    assert d.code in ("V103", "V113") and _suggested(d) == glued
    assert _clean(text.replace(spaced, glued))


def test_a_repeat_count_apart_from_its_x_is_one_error():
    text = "approach a=0.1\npause 1s x 3\nretreat 5cm x2\n"
    d = _one_error(text)
    assert d.code == "V113" and "`x3`" in (d.hint or "")
    assert _clean(text.replace("x 3", "x3"))


def test_a_vector_without_parentheses_says_how_to_write_one():
    d = _one_error("goal 0.5, 0, 0.3\napproach\npause 1s\n")
    assert d.code == "S001" and "(0.5, 0, 0.3)" in (d.hint or "")


def test_linting_slips_stays_light():
    """The hints need no heavy import: linting every slip above loads no numpy."""
    code = ("import sys\nfrom aou_dsl.lang.linter import lint_source\n"
            "for t in ['pause 1,5s', 'tilt 20°', 'pause 1.25sec', 'shiver 1deg for=1s',\n"
            "          'pause 1.25 s', 'goal 0.5, 0, 0.3', 'approach v=0.2mps']:\n"
            "    lint_source(t)\n"
            "print(sorted(m for m in ('numpy', 'scipy', 'pinocchio') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True)
    assert out.stdout.strip() == "[]"
