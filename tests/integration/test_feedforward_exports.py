"""Every export a controller reads carries the velocities and accelerations a feed-forward
controller uses, and they are the positions' own derivatives: read back with other
libraries' readers (json, NumPy, PyYAML, rosbags), then checked against differences of
the positions, and the velocities sent to the simulated servo restore the shiver."""

import functools
import json

import numpy as np
import pytest

from aou_dsl.compiler.output import encode, write_output
from aou_dsl.driver.builder import build_file
from tests.conftest import BEHAVIOURS


@functools.cache
def _res():
    res = build_file(str(BEHAVIOURS / "fearful.aou"), check=False)
    assert res.ok
    return res


def _doc() -> dict:
    return _res().document


def _json(tmp_path, doc):
    d = json.loads(encode(doc, "json"))
    return d["t"], d["q"], d["qd"], d["qdd"]


def _npz(tmp_path, doc):
    path = tmp_path / "x.npz"
    path.write_bytes(encode(doc, "npz"))
    z = np.load(path, allow_pickle=False)
    return z["t"], z["q"], z["qd"], z["qdd"]


def _points(msg_points, key=lambda p, k: p[k]):
    return ([key(p, "positions") for p in msg_points],
            [key(p, "velocities") for p in msg_points],
            [key(p, "accelerations") for p in msg_points])


def _time(sec, nanosec) -> float:
    return sec + nanosec * 1e-9


def _yaml(tmp_path, doc):
    yaml = pytest.importorskip("yaml")
    msg = yaml.safe_load(encode(doc, "yaml"))
    t = [_time(**p["time_from_start"]) for p in msg["points"]]
    return (t, *_points(msg["points"]))


def _mcap(tmp_path, doc):
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    bag = tmp_path / "bag"
    write_output(str(bag), doc, "mcap")
    ts = get_typestore(Stores.ROS2_HUMBLE)
    with Reader(str(bag)) as reader:
        (msg,) = [ts.deserialize_cdr(raw, c.msgtype) for c, _, raw in reader.messages()]
    t = [_time(p.time_from_start.sec, p.time_from_start.nanosec) for p in msg.points]
    return (t, *_points(msg.points, lambda p, k: getattr(p, k).tolist()))


@pytest.mark.parametrize("read", [_json, _npz, _yaml, _mcap], ids=lambda f: f.__name__[1:])
def test_an_export_carries_velocities_and_accelerations_that_fit_its_positions(tmp_path,
                                                                              read):
    """Each sample step of the positions is the velocities' trapezoid over it, to within
    1 % of their peak. The accelerations are the velocities' the same way but where the
    law switches its acceleration inside a 4 ms step (three steps of fearful's 3000: a
    jerk-limited ramp of under 2 ms, which no trapezoid over 4 ms follows). There the
    plan's own acceleration, integrated at 0.05 ms over the step, gives the exported
    velocity step: the exported samples are the plan's, and the miss is the sampling's."""
    t, q, qd, qdd = (np.asarray(x, dtype=float) for x in read(tmp_path, _doc()))
    assert q.shape == qd.shape == qdd.shape and q.shape[0] == t.shape[0] > 100
    assert np.abs(qd).max() > 0.1 and np.abs(qdd).max() > 1.0  # not zeros
    dt = np.diff(t)[:, None]

    def mismatch(x, dx):  # per step, as a share of the derivative's peak
        trapezoid = (dx[1:] + dx[:-1]) / 2 * dt
        return (np.abs(np.diff(x, axis=0) - trapezoid) / dt).max(axis=1) / np.abs(dx).max()

    assert mismatch(q, qd).max() <= 0.01
    acc = mismatch(qd, qdd)
    assert (acc > 0.01).sum() <= 3 and acc.max() <= 0.15
    from aou_dsl.compiler.pipeline import evaluate

    peak = np.abs(qdd).max()
    for i in np.flatnonzero(acc > 0.01):
        fine = np.linspace(t[i], t[i + 1], 81)
        _, v, a = evaluate(_res().compiled, fine)
        assert np.abs(v[[0, -1]] - qd[[i, i + 1]]).max() <= 1e-6 * np.abs(qd).max()
        assert np.abs(a[[0, -1]] - qdd[[i, i + 1]]).max() <= 1e-6 * peak
        step = ((a[1:] + a[:-1]) / 2 * np.diff(fine)[:, None]).sum(axis=0)
        assert np.abs(step - (qd[i + 1] - qd[i])).max() / (t[i + 1] - t[i]) <= 0.01 * peak


def test_a_csv_carries_positions_only():
    """The CSV is a recording's format (``t`` and one column per joint): what it lacks
    is what a plain position interface loses (docs/ros2.md)."""
    header = [ln for ln in encode(_doc(), "csv").decode().splitlines()
              if not ln.startswith("#")][0]
    assert header.split(",") == ["t", *_doc()["joint_names"]]


def test_a_csv_with_derivatives_carries_the_documents_own_velocities_and_accelerations(
        tmp_path, capsys):
    """``--csv-derivatives``: the positions' columns as in the plain CSV, then a velocity
    and an acceleration column per joint, read back by NumPy equal to the document's;
    ``aouc measure`` reads the file as it reads the plain one."""
    import csv

    from aou_dsl.cli.commands import EXIT_OK, main

    doc = _doc()
    text = encode(doc, "csv+derivatives").decode()
    body = [ln for ln in text.splitlines() if not ln.startswith("#")]
    head = next(csv.reader(body[:1]))
    names = doc["joint_names"]
    assert head == ["t", *names, *(f"qd_{n}" for n in names), *(f"qdd_{n}" for n in names)]
    table = np.loadtxt(body[1:], delimiter=",")
    n = len(names)
    assert np.array_equal(table[:, 0], np.asarray(doc["t"]))
    for k, key in enumerate(("q", "qd", "qdd")):
        assert np.array_equal(table[:, 1 + k * n:1 + (k + 1) * n], np.asarray(doc[key]))

    src = str(BEHAVIOURS / "inactive.aou")
    plain, more = tmp_path / "plain.csv", tmp_path / "more.csv"
    assert main(["compile", src, "--no-check", "-o", str(plain)]) == EXIT_OK
    assert main(["compile", src, "--no-check", "-o", str(more), "--csv-derivatives"]) \
        == EXIT_OK
    assert more.read_text().splitlines()[:6] == plain.read_text().splitlines()[:6]
    capsys.readouterr()
    got = []
    for path in (plain, more):
        assert main(["measure", str(path), "--format", "json"]) == EXIT_OK
        got.append(json.loads(capsys.readouterr().out)["descriptors"])
    assert got[0] == got[1] and got[0]["pause_count"] == 1
    assert main(["compile", src, "--no-check", "-o", str(tmp_path / "x.json"),
                 "--csv-derivatives"]) == 2  # only a CSV has them as an option
