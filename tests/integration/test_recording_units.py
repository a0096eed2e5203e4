"""A time unit that contradicts the robot is refused, like an angle unit that does.

An arm moves within its joint velocity limits. Seconds read as milliseconds make every
joint move a thousand times faster than it did, far beyond those limits: such a reading
is refused (R404) naming the joint and the unit, and the file read in seconds measures
as the behaviour declares. The logs come from tests/recsim.py (the loggers of real arms:
noise, rates, jittered clocks, dropped samples), from a compiled behaviour.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from aou_dsl.cli.commands import EXIT_ERRORS, main
from aou_dsl.measuring.measured import measure
from aou_dsl.measuring.plausible import FASTEST
from aou_dsl.measuring.recording import read_recording
from aou_dsl.robot.load import load_arm
from tests.conftest import BEHAVIOURS, fails_with
from tests.recsim import PRESETS, record, to_csv_text, to_json_doc

COUNTS = ("pause_count", "retreat_count")


@pytest.fixture(scope="module")
def hesitant():
    """The slowest shipped behaviour (its joints stay near a tenth of their limits): the
    hardest to tell from a slow arm. Its compiled document and declared descriptors."""
    from aou_dsl.driver.builder import build_source

    res = build_source((BEHAVIOURS / "hesitant.aou").read_text(), "hesitant.aou",
                       check=False)
    assert res.ok and res.declared is not None
    return res.document, res.declared


def _csv(tmp_path, rec: dict, name: str) -> str:
    path = tmp_path / name
    path.write_text(to_csv_text(rec))
    return str(path)


def _goal(rec: dict) -> tuple[float, float, float]:
    return tuple(rec["goal"]["position"])


@pytest.mark.parametrize("logger", list(PRESETS))
def test_seconds_read_as_milliseconds_are_refused_by_every_logger(hesitant, tmp_path,
                                                                    logger):
    doc, declared = hesitant
    rec = record(doc, PRESETS[logger], dynamic=False)
    path = _csv(tmp_path, rec, f"{logger}.csv")
    d = fails_with("R404", read_recording, path, robot="panda", goal=_goal(rec), time_unit="ms")
    assert "--time-unit ms" in d.message and "seconds" in d.message
    assert "leave out --time-unit ms" in (d.hint or "")
    # The joint named really moves beyond its limit on that reading: even its mean speed
    # over the whole log read in milliseconds, rests included, is above it.
    arm = load_arm("panda")
    j = arm.joint_names.index(d.fields["joint"])
    col = np.asarray(rec["q"])[:, rec["joint_names"].index(d.fields["joint"])]
    t_ms = np.asarray(rec["t"]) * 1e-3
    assert np.ptp(col) / (t_ms[-1] - t_ms[0]) > arm.vmax[j]  # rests included
    # The span points at the row named, a line of the file that holds that sample.
    assert d.span.line == d.fields["row"] and f"row {d.fields['row']}" in d.message
    line = open(path).read().splitlines()[d.span.line - 1]
    assert float(line.split(",")[0]) == pytest.approx(rec["t"][d.fields["sample"]])
    # Read in seconds (the unit left out, or given), the same log measures as declared.
    for unit in (None, "s"):
        got = measure(read_recording(path, robot="panda", goal=_goal(rec),
                                     time_unit=unit)).descriptors
        assert all(got[k] == declared[k] for k in COUNTS), (unit, got)


def test_the_command_line_refuses_it_and_names_the_unit(hesitant, tmp_path, capsys):
    doc, _ = hesitant
    rec = record(doc, PRESETS["franka_fci"], dynamic=False)
    path = _csv(tmp_path, rec, "rec.csv")
    assert main(["measure", path, "--robot", "panda", "--goal", "0.55,0,0.25",
                 "--time-unit", "ms"]) == EXIT_ERRORS
    err = capsys.readouterr().err
    assert "R404" in err and "--time-unit ms" in err


def test_a_json_recording_points_at_the_time_it_misreads(hesitant, tmp_path):
    doc, _ = hesitant
    rec = record(doc, PRESETS["ur_rtde"], dynamic=False)
    path = tmp_path / "rec.json"
    text = json.dumps(to_json_doc(rec), indent=1)
    path.write_text(text)
    d = fails_with("R404", read_recording, str(path), time_unit="ms")
    i = d.fields["sample"]
    lines = text.splitlines()
    first = lines.index(' "t": [') + 2  # the line of t[0] (1-based)
    assert d.span.line == first + i and f"sample {i}" in d.message
    assert float(lines[d.span.line - 1].strip().rstrip(",")) == rec["t"][i]


def test_milliseconds_read_as_milliseconds_measure_as_seconds_do(hesitant, tmp_path):
    """A log really in milliseconds: refused without the unit (its clock is too slow for
    seconds), read with it exactly as the same log in seconds."""
    doc, declared = hesitant
    log = PRESETS["teleop_guided"]
    in_s, in_ms = record(doc, log, dynamic=False), record(doc, log.with_(time_unit="ms"),
                                                          dynamic=False)
    s_path, ms_path = _csv(tmp_path, in_s, "s.csv"), _csv(tmp_path, in_ms, "ms.csv")
    d = fails_with("R404", read_recording, ms_path, robot="panda", goal=_goal(in_s))
    assert "milliseconds" in d.message
    a = measure(read_recording(s_path, robot="panda", goal=_goal(in_s))).descriptors
    b = measure(read_recording(ms_path, robot="panda", goal=_goal(in_s),
                               time_unit="ms")).descriptors
    assert all(b[k] == declared[k] for k in COUNTS)
    for k, v in a.items():
        assert b[k] == (pytest.approx(v, rel=1e-6, abs=1e-9) if isinstance(v, float) else v)


def test_a_slow_arm_is_not_mistaken_for_milliseconds(hesitant, tmp_path):
    """The same motion ten times slower (a slow arm, 25 Hz) is a plausible recording in
    seconds: nothing in slowness alone says the times are in milliseconds."""
    doc, _ = hesitant
    slow = {**doc, "t": (np.asarray(doc["t"]) * 10).tolist(),
            "qd": (np.asarray(doc["qd"]) / 10).tolist()}
    rec = record(slow, PRESETS["csv_6_decimals_250hz"].with_(rate=25.0), dynamic=False)
    path = _csv(tmp_path, rec, "slow.csv")
    got = read_recording(path, robot="panda", goal=_goal(rec))
    assert got.t[-1] == pytest.approx(rec["t"][-1])


def test_glitches_do_not_make_a_recording_too_fast(hesitant, tmp_path):
    """Three samples glitched by 0.3 rad (inside the joint's limits) would be joint speeds
    of hundreds of rad/s at 1 kHz; they are glitches, not a unit."""
    doc, _ = hesitant
    rec = record(doc, PRESETS["franka_fci"], dynamic=False)
    q = np.asarray(rec["q"]).copy()
    k = rec["joint_names"].index("panda_joint1")
    for i in (500, 4000, 9000):
        q[i, k] += 0.3
    path = _csv(tmp_path, {**rec, "q": q}, "glitch.csv")
    assert 0.3 / np.diff(rec["t"])[500] > FASTEST * load_arm("panda").vmax[0]
    read_recording(path, robot="panda", goal=_goal(rec))


def test_a_file_aou_wrote_with_a_time_unit_is_still_refused(hesitant, tmp_path):
    """aou's own files are in seconds: --time-unit ms on one is refused, as before."""
    from aou_dsl.compiler.output import encode

    doc, _ = hesitant
    path = tmp_path / "h.json"
    path.write_bytes(encode(doc, "json"))
    d = fails_with("R404", read_recording, str(path), time_unit="ms")
    assert "aou wrote this file" in d.message
