"""Safety checks in PyBullet: hand-built trajectories that each break one rule fail on
exactly that check, at the right sample; the shipped behaviours pass."""

import json

import numpy as np
import pytest

from aou_dsl.cli.commands import EXIT_ERRORS, EXIT_OK, main
from aou_dsl.core.trajectory import Trajectory
from aou_dsl.robot.load import load_arm
from aou_dsl.robot.scene import Scene
from aou_dsl.safety.replay import replay
from tests.conftest import BEHAVIOURS
from tests.synth import Synth

GOAL = (0.55, 0.0, 0.25)
RATE = 250.0
POSTURE = np.array(load_arm("panda").spec.posture)
#: A folded configuration in which link 5 and link 7 interpenetrate (found by search).
FOLDED = np.array([0.0, 0.254, 0.0, -2.725, 0.153, 0.017, 0.785])


def _trajectory(q: np.ndarray, qd=None, qdd=None) -> dict:
    t = np.arange(len(q)) / RATE
    qd = np.zeros_like(q) if qd is None else qd
    qdd = np.zeros_like(q) if qdd is None else qdd
    return {"format": "aou-trajectory/1", "behaviour": "hand-built", "state": None,
            "robot": "panda", "ee_frame": "panda_hand_tcp",
            "joint_names": [f"panda_joint{i}" for i in range(1, 8)],
            "goal": {"position": list(GOAL)}, "t": t.tolist(), "q": q.tolist(),
            "qd": qd.tolist(), "qdd": qdd.tolist()}


def _hold_then(q_after: np.ndarray, n_before: int = 250, n_after: int = 50) -> np.ndarray:
    """At the posture for ``n_before`` samples, then at ``q_after``."""
    return np.vstack([np.tile(POSTURE, (n_before, 1)), np.tile(q_after, (n_after, 1))])


def _failed(doc: dict) -> list:
    t = np.array(doc["t"])
    tr = Trajectory(t, np.array(doc["q"]), tuple(doc["joint_names"]), "panda", None, GOAL,
                    np.array(doc["qd"]), np.array(doc["qdd"]))
    report = replay(tr)
    return [c for c in report.checks if not c.ok]


def test_joint_limit_crossing_fails_the_position_check_at_the_worst_sample():
    """Joint 7 ramps smoothly past its 2.8973 rad limit; the worst sample is the last."""
    n = 500
    s = np.linspace(0, 1, n)
    q = np.tile(POSTURE, (n, 1))
    q[:, 6] = 2.5 + 0.5 * (3 * s**2 - 2 * s**3)  # rest to rest, 2.5 -> 3.0 rad
    qd = np.gradient(q, 1 / RATE, axis=0)
    (fail,) = _failed(_trajectory(q, qd, np.gradient(qd, 1 / RATE, axis=0)))
    assert fail.name == "joint-position" and fail.joint == "panda_joint7"
    assert fail.time == pytest.approx((n - 1) / RATE)
    assert fail.value == pytest.approx(3.0) and fail.limit == pytest.approx(2.8973)


def test_self_collision_fails_at_the_first_colliding_sample():
    (fail,) = _failed(_trajectory(_hold_then(FOLDED)))
    assert fail.name == "self-collision"
    assert set(fail.joint.split(" / ")) == {"panda_link5", "panda_link7"}
    assert fail.time == pytest.approx(250 / RATE)


def test_entering_the_target_fails_the_target_check():
    """The hand moves until its centre point is 1 cm from the cube's centre: inside."""
    s = Synth(d=0.10)
    s.line(-0.09, 0.1)
    rec = s.recording()
    qd = np.gradient(rec.q, rec.t, axis=0)
    doc = _trajectory(rec.q, qd, np.gradient(qd, rec.t, axis=0))
    (fail,) = _failed(doc)
    assert fail.name == "target-contact"
    # The reported sample is the first that touches: the one before is clear (asked of a
    # fresh scene), and contact comes no later than the hand's centre entering the cube.
    i = int(round(fail.time * RATE))
    with Scene("panda", GOAL) as scene:
        for k, touching in ((i - 1, False), (i, True)):
            scene.set_arm(rec.q[k])
            d = min(p[8] for p in scene.pb.getClosestPoints(
                scene.body, scene.target, 0.5, physicsClientId=scene.client))
            assert (d <= 0) == touching, (k, d)
    pos, _ = load_arm("panda").fk(rec.q)
    centre_inside = np.max(np.abs(pos - np.array(GOAL)), axis=1) <= 0.025
    assert fail.time <= rec.t[np.argmax(centre_inside)]


def test_exceeding_an_acceleration_limit_fails_at_the_peak():
    """Joint 2 oscillates at 2 Hz with 0.06 rad amplitude: 9.5 rad/s^2 peaks, over its 7.5."""
    n = 500
    t = np.arange(n) / RATE
    w = 2 * np.pi * 2.0
    q = np.tile(POSTURE, (n, 1))
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q)
    q[:, 1] += 0.06 * np.sin(w * t)
    qd[:, 1] = 0.06 * w * np.cos(w * t)
    qdd[:, 1] = -0.06 * w * w * np.sin(w * t)
    (fail,) = _failed(_trajectory(q, qd, qdd))
    assert fail.name == "joint-acceleration" and fail.joint == "panda_joint2"
    assert fail.time == pytest.approx(t[np.argmax(np.abs(qdd[:, 1]))])
    assert abs(fail.value) == pytest.approx(0.06 * w * w, rel=1e-3)


@pytest.mark.parametrize("name", ["confident", "curious", "hesitant", "fearful", "inactive"])
def test_shipped_behaviours_pass_and_report_clearances_and_agreement(name, capsys):
    assert main(["check", str(BEHAVIOURS / f"{name}.aou"), "--format", "json"]) == EXIT_OK
    report = json.loads(capsys.readouterr().out)
    assert report["ok"]
    assert report["clearances"]["target"] > 0.02 and report["clearances"]["self"] > 0
    assert report["agreement"]["position_mm"] <= 1.0
    assert report["agreement"]["rotation_deg"] <= 0.5
    assert report["dynamic"]["torque_max_ratio"] <= 1.0


def test_check_text_report_names_each_check(capsys, tmp_path):
    path = tmp_path / "h.json"
    path.write_text(json.dumps(_trajectory(_hold_then(FOLDED))))
    assert main(["check", str(path), "--no-dynamic"]) == EXIT_ERRORS
    out = capsys.readouterr().out
    assert "FAIL  self-collision" in out and "pass  joint-position" in out
    assert "PyBullet vs Pinocchio" in out and "clearances:" in out


def test_compile_refuses_to_write_an_unsafe_trajectory(tmp_path, capsys):
    """A standoff inside the target: the fingers would touch it. The diagnostic points at
    the approach, and nothing is written."""
    src = tmp_path / "close.aou"
    src.write_text("standoff 0.02m\napproach\npause 1s\n")
    out = tmp_path / "close.json"
    assert main(["compile", str(src), "-o", str(out)]) == EXIT_ERRORS
    err = capsys.readouterr().err
    assert "close.aou:2:1: C306" in err and "target-contact" in err
    assert not out.exists()


def test_target_size_is_an_option(tmp_path):
    """The same reach passes with a target small enough for the standoff."""
    src = tmp_path / "close.aou"
    src.write_text("standoff 0.04m\napproach\npause 1s\n")
    out = tmp_path / "close.json"
    assert main(["compile", str(src), "-o", str(out)]) == EXIT_ERRORS
    assert main(["compile", str(src), "-o", str(out), "--target-size", "0.01"]) == EXIT_OK
    assert json.loads(out.read_text())["checks"]["kinematic"]["ok"]
