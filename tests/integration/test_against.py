"""`aouc measure REC --against FILE.aou`: a recording of a real arm (simulated loggers,
tests/recsim.py) judged against the behaviour it should show, in JSON, CSV and NPZ;
every descriptor declared vs measured with its tolerance; exit 1 and R408 at the
declaring statement when one is outside; `--format json|github`."""

from __future__ import annotations

import io
import json
import zipfile

import numpy as np
import pytest

from aou_dsl.cli.commands import main
from aou_dsl.driver.builder import build_file
from aou_dsl.lang.descriptors import REGISTRY
from tests.conftest import BEHAVIOURS
from tests.recsim import PRESETS, record, to_csv_text, to_json_doc

HESITANT = BEHAVIOURS / "hesitant.aou"


@pytest.fixture(scope="module")
def recording():
    """The hesitant behaviour performed on the simulated Panda (its own tracking lag) and
    written by libfranka-like and plain 6-decimal loggers."""
    res = build_file(str(HESITANT), check=False)
    assert res.ok
    doc = res.document
    return {name: record(doc, PRESETS[name], dynamic=True)
            for name in ("franka_fci", "csv_6_decimals_250hz")}


def _write(tmp_path, rec: dict, fmt: str) -> tuple[str, list[str]]:
    """The recording in ``fmt``; the extra arguments a reader needs for it."""
    path = tmp_path / f"run.{fmt}"
    if fmt == "csv":  # a bare log: no robot, no goal (the behaviour's goal is used)
        path.write_text(to_csv_text(rec))
        return str(path), ["--robot", "panda"]
    doc = to_json_doc(rec)
    if fmt == "json":
        path.write_text(json.dumps(doc))
    else:
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w") as zf:
            for key in ("t", "q"):
                arr = io.BytesIO()
                np.lib.format.write_array(arr, np.asarray(doc[key], dtype=np.float64))
                zf.writestr(f"{key}.npy", arr.getvalue())
            zf.writestr("header.json", json.dumps(
                {k: v for k, v in doc.items() if k not in ("t", "q")}))
        path.write_bytes(buf.getvalue())
    return str(path), []


@pytest.mark.parametrize("logger", ["franka_fci", "csv_6_decimals_250hz"])
@pytest.mark.parametrize("fmt", ["json", "csv", "npz"])
def test_a_recording_of_the_behaviour_passes_against_it(recording, tmp_path, capsys,
                                                        fmt, logger):
    path, extra = _write(tmp_path, recording[logger], fmt)
    code = main(["measure", path, "--against", str(HESITANT), *extra, "--format", "json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0, out
    rows = {r["descriptor"]: r for r in out["descriptors"]}
    assert list(rows) == list(REGISTRY)
    assert all(r["ok"] for r in rows.values())
    assert rows["pause_count"]["declared"] == 5 and rows["pause_count"]["measured"] == 5
    assert rows["pause_duration"]["tolerance"] == pytest.approx(0.0334)
    assert rows["horizontal_gaze"]["declared"] is None
    assert out["cv"]["declared"]["state"] == out["cv"]["measured"]["state"] == "hesitant"
    assert out["goal_from_behaviour"] is (fmt == "csv")


def test_a_descriptor_outside_its_tolerance_fails_the_run_at_its_statement(
        recording, tmp_path, capsys):
    """The same run judged against a file declaring 2 s pauses: exit 1, one R408 at the
    pause statement, the rest pass."""
    other = tmp_path / "longer.aou"
    other.write_text(HESITANT.read_text().replace("pause 1.67s", "pause 2s"))
    path, extra = _write(tmp_path, recording["franka_fci"], "json")
    assert main(["measure", path, "--against", str(other), *extra]) == 1
    out, err = capsys.readouterr()
    fails = [ln for ln in out.splitlines() if ln.rstrip().endswith("FAIL")]
    assert len(fails) == 1 and fails[0].split()[0] == "pause_duration"
    assert "10 of 11 descriptors within tolerance" in out
    (line,) = [ln for ln in err.splitlines() if " R408 " in ln]
    pause_line = next(i for i, ln in enumerate(other.read_text().splitlines(), 1)
                      if ln.startswith("pause"))
    assert line.startswith(f"{other}:{pause_line}:1: R408")
    assert main(["measure", path, "--against", str(other), "--format", "github"]) == 1
    (ann,) = capsys.readouterr().out.splitlines()
    assert ann.startswith(f"::error file={other},line={pause_line},")
    assert "pause_duration: declared 2 s, measured 1.6" in ann


def test_a_behaviour_file_with_errors_is_said_and_nothing_judged(recording, tmp_path, capsys):
    bad = tmp_path / "bad.aou"
    bad.write_text("pause 3m\n")
    path, _ = _write(tmp_path, recording["franka_fci"], "json")
    assert main(["measure", path, "--against", str(bad)]) == 1
    out, err = capsys.readouterr()
    assert "descriptor" not in out and "bad.aou:1:" in err


def test_the_table_shows_a_lopsided_interval_as_measure_does():
    """The verdict table printed every interval as +- its larger half, where `aouc
    measure` prints +up -down: 0.05009 in 0.04231..0.05577 read "+-0.0078" in one and
    "+0.0057 -0.0078" in the other."""
    from types import SimpleNamespace

    from aou_dsl.cli.against import _pm

    row = SimpleNamespace(measured=0.05009, low=0.04231, high=0.05577)
    assert _pm(row) == "+0.0057 -0.0078"
    assert _pm(SimpleNamespace(measured=1.0, low=0.9, high=1.095)) == "+- 0.1"
    assert _pm(SimpleNamespace(measured=5, low=4, high=6)) == "4..6"


def test_a_file_that_cannot_be_read_exits_2_in_every_format(tmp_path, capsys):
    """A recording with a non-number in it exited 1, the code of a failed verdict, and
    printed nothing on stdout under --format json or github; a behaviour file that does
    not exist was reported as the recording lacking its robot."""
    import json as _json

    from aou_dsl.cli.commands import main

    bad = tmp_path / "bad.csv"
    bad.write_text("t,panda_joint1\n0.0,0.1\n0.004,abc\n")
    behaviour = str(BEHAVIOURS / "hesitant.aou")
    assert main(["measure", str(bad), "--against", behaviour]) == 2
    assert "R401" in capsys.readouterr().err
    assert main(["measure", str(bad), "--against", behaviour, "--format", "json"]) == 2
    doc = _json.loads(capsys.readouterr().out)
    assert doc["result"] is None and doc["diagnostics"][0]["code"] == "R401"
    assert main(["measure", str(bad), "--against", behaviour, "--format", "github"]) == 2
    assert capsys.readouterr().out.startswith("::error file=")
    missing = str(tmp_path / "nothere.aou")
    assert main(["measure", str(bad), "--against", missing]) == 2
    err = capsys.readouterr().err
    assert "I501" in err and "nothere.aou" in err and "without its robot" not in err


def test_columns_that_are_not_the_robots_joints_exit_2_in_every_format(tmp_path, capsys):
    """A recording whose columns name no joint of the robot (renamed, and no --map)
    cannot be read as that robot's: exit 2 with its R402 in every format. It exited 1,
    a failed verdict's code, and printed nothing at all under --format json or github."""
    import json as _json

    from aou_dsl.cli.commands import main

    ren = tmp_path / "renamed.csv"
    ren.write_text("t," + ",".join(f"j{i}" for i in range(1, 8)) + "\n" + "".join(
        f"{k * 0.004:.3f}," + ",".join(["0.1"] * 7) + "\n" for k in range(50)))
    behaviour = str(BEHAVIOURS / "hesitant.aou")
    args = ["measure", str(ren), "--robot", "panda", "--against", behaviour]
    assert main(args) == 2
    assert "R402" in capsys.readouterr().err
    assert main([*args, "--format", "json"]) == 2
    doc = _json.loads(capsys.readouterr().out)
    assert doc["result"] is None and doc["diagnostics"][0]["code"] == "R402"
    assert main([*args, "--format", "github"]) == 2
    assert "R402" in capsys.readouterr().out


def _noisy_hesitant(tmp_path, seed: int):
    """Hesitant with 1e-3 rad of white noise at 250 Hz, as a CSV."""
    from tests.integration.test_episode_spread import _white
    from tests.integration.test_recordings import build

    doc, _, _ = build((BEHAVIOURS / "hesitant.aou").read_text(), "hesitant")
    tr = _white(doc, 1e-3, seed)
    path = tmp_path / "noisy.csv"
    path.write_text("t," + ",".join(tr.joint_names) + "\n" + "".join(
        f"{t:.6f}," + ",".join(f"{v:.9f}" for v in row) + "\n"
        for t, row in zip(tr.t, tr.q, strict=True)))
    return path


def test_a_noisy_failure_gives_its_interval(tmp_path, capsys):
    """R408 on a noisy recording says the interval that missed the tolerance, as R412
    does: hesitant's retreats (6 cm) against a file declaring 9 cm."""
    path = _noisy_hesitant(tmp_path, 2)
    other = tmp_path / "far.aou"
    other.write_text((BEHAVIOURS / "hesitant.aou").read_text().replace(
        "retreat 0.06m", "retreat 0.09m"))
    code = main(["measure", str(path), "--robot", "panda", "--goal", "0.55,0,0.25",
                 "--against", str(other), "--format", "json"])
    doc = json.loads(capsys.readouterr().out)
    (r408,) = [d for d in doc["diagnostics"] if d["code"] == "R408"]
    low, high = r408["fields"]["low"], r408["fields"]["high"]
    assert code == 1 and low < r408["fields"]["measured"] < high < 0.09 - 0.001
    assert f"95 % interval {low:.4g} to {high:.4g}" in r408["message"]


def test_the_measured_point_reads_as_measure_prints_it(tmp_path, capsys):
    """The verdict's measured C-V point carries what `aouc measure` prints of it: its
    intervals, the states the re-noised copies read, the untrusted values it was read
    from. Hesitant logged with 1e-3 rad of noise at 250 Hz; the verdict printed a bare
    point, with no sign that the copies read another state."""
    path = _noisy_hesitant(tmp_path, 1)
    goal = ["--robot", "panda", "--goal", "0.55,0,0.25"]
    main(["measure", str(path), *goal])
    point = next(ln for ln in capsys.readouterr().out.splitlines() if "C-V:" in ln)
    main(["measure", str(path), *goal, "--against", str(BEHAVIOURS / "hesitant.aou")])
    verdict = next(ln for ln in capsys.readouterr().out.splitlines() if "C-V measured:" in ln)
    assert verdict.split("C-V measured: ")[1] == point.split("C-V: ")[1]
    assert "+-" in point and "re-noised copies read" in point
