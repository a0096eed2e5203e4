"""A clock stamped on arrival with no sample dropped: the positions exact at a steady
250 Hz, the stamps jittered by up to a fifth of a step. Both readings (the stamps',
the evened clock's) put hesitant's approach at about 0.063 m/s^2, where it was
declared and made at 0.05; with copies that kept the recording's stamps its interval
was narrow about that, trusted, and ``measure --against`` failed a motion made as
declared. Stamped afresh, the copies read what another arrival would."""

from __future__ import annotations

import json

import numpy as np

from aou_dsl.cli.commands import main
from aou_dsl.driver.builder import build_file
from tests.conftest import BEHAVIOURS


def _arrival_csv(tmp_path) -> str:
    doc = build_file(str(BEHAVIOURS / "hesitant.aou"), check=False).document
    t, q = np.asarray(doc["t"], float), np.asarray(doc["q"], float)
    rng = np.random.default_rng(2)
    stamps = t + rng.uniform(-0.2, 0.2, t.shape) * float(np.median(np.diff(t)))
    path = tmp_path / "arrival.csv"
    rows = ["t," + ",".join(doc["joint_names"])]
    rows += [f"{ti:.6f}," + ",".join(f"{v:.7f}" for v in qi)
             for ti, qi in zip(stamps, q, strict=True)]
    path.write_text("\n".join(rows) + "\n")
    return str(path)


def test_a_clock_stamped_on_arrival_leaves_the_rate_undecided_not_failed(tmp_path, capsys):
    path = _arrival_csv(tmp_path)
    code = main(["measure", path, "--against", str(BEHAVIOURS / "hesitant.aou")])
    out = capsys.readouterr()
    assert code == 3, out.out + out.err
    assert "R408" not in out.err and "R412" in out.err
    assert "the clock's stamps, taken on arrival" in out.err
    code = main(["measure", path, "--robot", "panda", "--goal", "0.55,0,0.25",
                 "--format", "json"])
    doc = json.loads(capsys.readouterr().out)
    approach = doc["uncertainty"]["approach_acceleration"]
    assert approach["low"] <= 0.05 <= approach["high"] and not approach["stable"]
