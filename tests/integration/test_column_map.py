"""Recordings whose columns are named otherwise than the robot's joints: ``--map`` with
column=joint pairs or a mapping file, for measure, check and plot; and ``measure
--against B.aou`` reading a bare CSV with the behaviour's robot."""

from __future__ import annotations

import json

import pytest

from aou_dsl.cli.commands import main
from aou_dsl.driver.builder import build_file
from tests.conftest import BEHAVIOURS
from tests.recsim import Logger, record, to_csv_text

HESITANT = BEHAVIOURS / "hesitant.aou"


@pytest.fixture(scope="module")
def logged() -> dict:
    res = build_file(str(HESITANT), check=False)
    assert res.ok
    rec = record(res.document, Logger(rate=250.0, noise=3e-5, seed=1), dynamic=False)
    # The logger names the joints its own way: j1..j7, in another order.
    names = [n.replace("panda_joint", "j") for n in rec["joint_names"]]
    return rec | {"joint_names": names[::-1], "q": rec["q"][:, ::-1]}


def _write(tmp_path, rec) -> str:
    path = tmp_path / "run.csv"
    path.write_text(to_csv_text(rec))
    return str(path)


PAIRS = ",".join(f"j{i}=panda_joint{i}" for i in range(1, 8))


def test_map_pairs_and_a_mapping_file_read_the_same(logged, tmp_path, capsys):
    path = _write(tmp_path, logged)
    assert main(["measure", path, "--robot", "panda", "--goal", "0.55,0,0.25"]) == 1
    assert "R402" in capsys.readouterr().err  # without the mapping: joints missing
    assert main(["measure", path, "--robot", "panda", "--goal", "0.55,0,0.25",
                 "--map", PAIRS, "--format", "json"]) == 0
    inline = json.loads(capsys.readouterr().out)
    mapping = tmp_path / "names.txt"
    mapping.write_text("# the logger's names\n" + "\n".join(PAIRS.split(",")) + "\n")
    assert main(["measure", path, "--robot", "panda", "--goal", "0.55,0,0.25",
                 "--map", str(mapping), "--format", "json"]) == 0
    from_file = json.loads(capsys.readouterr().out)
    assert inline["descriptors"] == from_file["descriptors"]
    assert inline["descriptors"]["pause_count"] == 5
    assert inline["descriptors"]["retreat_count"] == 3


def test_check_and_plot_take_the_map(logged, tmp_path, capsys):
    path = _write(tmp_path, logged)
    assert main(["check", path, "--robot", "panda", "--no-dynamic", "--map", PAIRS]) == 0
    out = tmp_path / "p.png"
    assert main(["plot", path, "--robot", "panda", "--map", PAIRS, "-o", str(out)]) == 0
    assert out.stat().st_size > 0


@pytest.mark.parametrize("spec,says", [
    ("j1=panda_joint1,j1=panda_joint2", "mapped twice"),
    ("j1=panda_joint1,j2=panda_joint1", "both mapped onto joint"),
    ("j1=,j2=panda_joint2", "column=joint"),
    ("j9=panda_joint1", "does not have"),
    ("j1=j2", "already has"),
])
def test_a_wrong_mapping_is_a_coded_error(logged, tmp_path, capsys, spec, says):
    path = _write(tmp_path, logged)
    assert main(["measure", path, "--robot", "panda", "--map", spec]) in (1, 2)
    err = capsys.readouterr().err
    assert "R401" in err and says in err and "Traceback" not in err


def test_a_missing_mapping_file_is_i501(logged, tmp_path, capsys):
    path = _write(tmp_path, logged)
    assert main(["measure", path, "--robot", "panda", "--map", str(tmp_path / "no")]) == 2
    assert "I501" in capsys.readouterr().err


def test_measure_against_takes_the_robot_from_the_behaviour(logged, tmp_path, capsys):
    """A bare CSV (no robot, no goal) against hesitant.aou: read with the file's robot
    (the panda) and measured at its goal; without --against it is refused for want of
    a robot."""
    path = _write(tmp_path, logged)
    assert main(["measure", path, "--map", PAIRS]) == 2
    assert "without its robot" in capsys.readouterr().err
    code = main(["measure", path, "--map", PAIRS, "--against", str(HESITANT),
                 "--format", "json"])
    doc = json.loads(capsys.readouterr().out)
    assert code in (0, 3) and doc["robot"] == "panda" and doc["goal_from_behaviour"]
    rows = {r["descriptor"]: r for r in doc["descriptors"]}
    assert rows["pause_count"]["result"] == "pass"


def test_a_pair_written_with_a_colon_is_a_malformed_pair_not_a_missing_file(logged, tmp_path,
                                                                            capsys):
    """``--map j1:panda_joint1`` was looked up as a mapping file and refused as "no
    such file" (I501) at a location named after the pair; it is a malformed pair (R401),
    with the pairs' form in the hint. Without --map, R402 now says --map exists."""
    path = _write(tmp_path, logged)
    assert main(["measure", path, "--robot", "panda", "--map", "j1:panda_joint1"]) == 1
    err = capsys.readouterr().err
    assert "R401" in err and "I501" not in err and "column=joint" in err
    main(["measure", path, "--robot", "panda"])
    err = capsys.readouterr().err
    assert "R402" in err and "--map" in err
