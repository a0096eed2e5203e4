"""--track: the arm's servos simulated in MuJoCo. A servo of known second-order dynamics
gives the closed form's amplitude ratio and phase lag; on the Panda, the fearful shiver
sent as plain set-points shrinks, and velocity feed-forward restores it."""

import json
from dataclasses import replace

import numpy as np
import pytest

pytest.importorskip("mujoco")

from aou_dsl.cli.commands import EXIT_OK, main  # noqa: E402
from aou_dsl.core.servo_specs import PANDA, SERVOS  # noqa: E402
from aou_dsl.core.trajectory import Trajectory  # noqa: E402
from aou_dsl.robot.load import load_arm  # noqa: E402
from aou_dsl.safety.track import track  # noqa: E402
from tests.conftest import BEHAVIOURS  # noqa: E402

ARM = load_arm("panda")
POSTURE = np.array(ARM.spec.posture)
#: A soft servo on the Panda's first joint (the vertical axis: no gravity torque on it):
#: its resonance near 1.1 Hz, damping ratio ~0.4. The other joints are held a hundred
#: times stiffer than published (ten times the damping, no force limit), so joint 1 is
#: one second-order system: at the published gains their give under its reaction
#: torques changes its response by about 3 %.
KP, KV = 50.0, 5.0
SOFT = replace(PANDA, kp=(KP, *(k * 100 for k in PANDA.kp[1:])),
               kv=(KV, *(k * 10 for k in PANDA.kv[1:])), force=(1e6,) * 7)


def _sinusoid(freq: float, amp: float, seconds: float = 6.0, rate: float = 250.0):
    t = np.arange(int(seconds * rate) + 1) / rate
    w = 2 * np.pi * freq
    q = np.tile(POSTURE, (len(t), 1))
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    q[:, 0] += amp * np.sin(w * t)
    qd[:, 0] = amp * w * np.cos(w * t)
    qdd[:, 0] = -amp * w * w * np.sin(w * t)
    return Trajectory(t, q, ARM.joint_names, "panda", None, (0.5, 0.0, 0.3), qd, qdd)


def _fit(t: np.ndarray, x: np.ndarray, w: float) -> complex:
    """The phasor of ``x`` at ``w`` by least squares (``x ~ Re(z e^{iwt})``)."""
    a = np.column_stack([np.cos(w * t), -np.sin(w * t), np.ones_like(t)])
    c, s, _ = np.linalg.lstsq(a, x, rcond=None)[0]
    return complex(c, s)


@pytest.mark.parametrize("mode", ["position", "feedforward"])
def test_a_sinusoid_through_a_second_order_servo_matches_the_closed_form(mode):
    """Joint 1's inertia J from Pinocchio's mass matrix (another library than the
    simulator) plus the armature; the servo ``kp (q_ref - q) + kv (qd_ref? - qd)`` and
    the joint's damping d give H(s) = (kp [+ kv s]) / (J s^2 + (kv + d) s + kp). Once the
    start has died away the tracked joint has H's gain and phase within 2 %."""
    import pinocchio as pin

    freq, amp = 1.5, np.radians(0.5)
    w = 2 * np.pi * freq
    tr = _sinusoid(freq, amp)
    got = track(tr, mode, SOFT).trajectory
    inertia = pin.crba(ARM.model, ARM.model.createData(), POSTURE)[0, 0] + PANDA.armature[0]
    s = 1j * w
    num = KP + (KV * s if mode == "feedforward" else 0.0)
    h = num / (inertia * s * s + (KV + PANDA.damping[0]) * s + KP)
    late = tr.t >= 3.0
    ref = _fit(tr.t[late], tr.q[late, 0], w)
    out = _fit(got.t[late], got.q[late, 0], w)
    ratio = out / ref
    assert abs(ratio) == pytest.approx(abs(h), rel=0.02)
    assert np.angle(ratio) == pytest.approx(np.angle(h), rel=0.02)
    assert abs(h) < 0.9 or mode == "feedforward"  # the case has something to show


def test_the_plan_played_under_computed_torque_is_followed_closely():
    """Computed torque adds the plan's own inverse dynamics: the same soft servo keeps
    the joint within a twentieth of a degree where plain set-points lag by degrees."""
    tr = _sinusoid(1.5, np.radians(3.0))
    soft = replace(PANDA, kp=(KP, *PANDA.kp[1:]), kv=(KV, *PANDA.kv[1:]))
    late = tr.t >= 3.0  # the sine starts at full speed: its start is a step

    def lag(mode: str) -> float:
        got = track(tr, mode, soft).trajectory
        return float(np.degrees(np.abs(got.q[late, 0] - tr.q[late, 0]).max()))

    assert lag("position") > 1.0
    assert lag("torque") < 0.05


@pytest.fixture(scope="module")
def fearful_panda(tmp_path_factory):
    path = tmp_path_factory.mktemp("track") / "fearful-tracked.json"
    return path


def test_fearful_on_the_panda_loses_its_shiver_to_plain_set_points(fearful_panda, capsys):
    """Plain set-points through the Panda's published servo: the shiver arrives at about
    half its amplitude (C322 names it, the value, and a mode that keeps it); with
    velocity feed-forward it is within its tolerance. The tracked recording measures as
    the report says."""
    argv = ["check", str(BEHAVIOURS / "fearful.aou"), "--no-dynamic", "--track",
            "--tracked", str(fearful_panda), "--format", "json"]
    assert main(argv) == EXIT_OK  # a warning: the motion is as safe as the plan
    out = capsys.readouterr()
    doc = json.loads(out.out)
    modes = {m["mode"]: {d["descriptor"]: d for d in m["descriptors"]}
             for m in doc["tracking"]["modes"]}
    assert set(modes) == {"position", "feedforward", "torque"}
    pos, ff = modes["position"]["shiver_amplitude"], modes["feedforward"]["shiver_amplitude"]
    assert 0.3 < pos["measured"] / pos["declared"] < 0.75 and not pos["ok"]
    assert ff["ok"] and abs(ff["measured"] - 6.0) <= ff["tolerance"]
    (lost,) = [d for d in doc["diagnostics"] if d["code"] == "C322"
               and d["fields"]["descriptor"] == "shiver_amplitude"]
    assert "feedforward" in lost["fields"]["keeps"] and "--servo feedforward" in lost["hint"]
    assert lost["line"] == 8 and lost["severity"] == "warning"  # at the shiver statement
    assert main(["measure", str(fearful_panda), "--format", "json"]) == EXIT_OK
    measured = json.loads(capsys.readouterr().out)["descriptors"]["shiver_amplitude"]
    assert measured == pytest.approx(pos["measured"], rel=1e-6)


def test_feedforward_mode_keeps_the_shiver_and_says_which_modes_keep_it(capsys):
    """With --servo feedforward no diagnostic names the shiver, and the text report says
    how much of it each mode shows and which keep it."""
    main(["check", str(BEHAVIOURS / "fearful.aou"), "--no-dynamic", "--track",
          "--servo", "feedforward"])
    out = capsys.readouterr()
    assert "shiver_amplitude: declared" not in out.err
    line = next(ln for ln in out.out.splitlines() if "the shiver (6 deg declared)" in ln)
    assert "under plain position set-points" in line and "Kept by: feedforward, torque." in line
    assert "max tracking error per joint" in out.out


def test_compile_track_writes_the_plan_and_the_tracked_recording(tmp_path, capsys):
    """compile --track: the trajectory is written (tracking warns, it does not refuse),
    the report goes to standard error, the tracked motion to --tracked."""
    out, rec = tmp_path / "f.json", tmp_path / "f-tracked.csv"
    assert main(["compile", str(BEHAVIOURS / "fearful.aou"), "--no-check", "--track",
                 "-o", str(out), "--tracked", str(rec)]) == EXIT_OK
    err = capsys.readouterr().err
    assert "tracked through the servos of panda" in err and " C322 " in err
    assert json.loads(out.read_text())["qd"]
    assert rec.read_text().splitlines()[0] == "# format: aou-trajectory/1"
    assert main(["measure", str(rec)]) == EXIT_OK
    assert main(["compile", str(BEHAVIOURS / "fearful.aou"), "-o", str(out),
                 "--tracked", str(rec)]) == 2  # --tracked without --track


def test_an_arm_without_a_servo_table_gets_the_generic_one_and_a_warning(capsys):
    assert "z1" not in SERVOS
    main(["check", str(BEHAVIOURS / "curious.aou"), "--robot", "z1", "--no-dynamic",
          "--track"])
    out = capsys.readouterr()
    assert " C323 " in out.err and "generic servo" in out.err
    assert "tracked through the servos of z1" in out.out


def test_tracking_a_trajectory_file_reports_the_error_without_a_verdict(tmp_path, capsys):
    tr = _sinusoid(0.5, np.radians(2.0), seconds=2.0)
    doc = {"format": "aou-trajectory/1", "robot": "panda", "joint_names":
           list(tr.joint_names), "goal": {"position": [0.5, 0.0, 0.3]},
           "t": tr.t.tolist(), "q": tr.q.tolist()}
    path = tmp_path / "sine.json"
    path.write_text(json.dumps(doc))
    assert main(["check", str(path), "--no-dynamic", "--track", "--format", "json"]) \
        == EXIT_OK
    modes = json.loads(capsys.readouterr().out)["tracking"]["modes"]
    assert all(m["descriptors"] is None for m in modes)
    assert modes[0]["tracking_max_rad"]["panda_joint1"] > 0


@pytest.mark.slow
@pytest.mark.parametrize("robot", ["panda", "ur5", "kinova", "z1"])
@pytest.mark.parametrize("name", ["confident", "curious", "hesitant", "inactive"])
def test_every_shipped_behaviour_tracks_on_every_arm(robot, name, capsys):
    """Each shipped behaviour (fearful's shiver is refused on the smaller arms) tracked
    in each mode: the torque mode follows within a degree on every joint."""
    main(["check", str(BEHAVIOURS / f"{name}.aou"), "--robot", robot, "--no-dynamic",
          "--track", "--format", "json"])
    doc = json.loads(capsys.readouterr().out)
    for m in doc["tracking"]["modes"]:
        assert m["descriptors"] is not None
        if m["mode"] == "torque":
            assert max(m["tracking_max_rad"].values()) < np.radians(1.0)


# --- a robot description's [servo] table -------------------------------------------------

def test_a_description_gives_its_own_servo_table(tmp_path):
    """Identified values in a robot description are what --track simulates: one number
    for every joint or one per joint; a description without a table keeps the built-in
    arm's; a named published table is that table."""
    from aou_dsl.safety.track import arm_servo

    own = tmp_path / "own.toml"
    own.write_text('robot = "panda"\n[servo]\nkp = [900, 900, 900, 900, 300, 300, 300]\n'
                   'kv = 30\nrate = 500\nmodes = ["position"]\nsource = "our lab, 2026"\n')
    table, generic = arm_servo(str(own))
    assert not generic and table.kp == (900.0,) * 4 + (300.0,) * 3
    assert table.kv == (30.0,) * 7 and table.rate == 500.0 and table.modes == ("position",)
    assert table.damping == (0.0,) * 7 and table.source == "our lab, 2026"
    plain = tmp_path / "plain.toml"
    plain.write_text('robot = "panda"\n')
    assert arm_servo(str(plain)) == (PANDA, False)
    named = tmp_path / "named.toml"
    named.write_text('robot = "panda"\n[servo]\ntable = "kinova_gen3"\n')
    assert arm_servo(str(named))[0] == SERVOS["kinova_gen3"]


@pytest.mark.parametrize(("servo", "words"), [
    ("kp = [1, 2]", "one per arm joint"),
    ("kp = -5", "must be a number from 0"),
    ("kq = 5", "unknown key `kq`"),
    ("kv = 5", "needs `kp`"),
    ('modes = ["velocity"]\nkp = 5', "`modes` must be a list"),
    ('table = "no_such_arm"', "names no table aou knows"),
])
def test_a_bad_servo_table_is_refused_with_what_is_wrong(tmp_path, servo, words):
    from aou_dsl.core.diagnostics import AouError
    from aou_dsl.safety.track import arm_servo

    path = tmp_path / "bad.toml"
    path.write_text(f'robot = "panda"\n[servo]\n{servo}\n')
    with pytest.raises(AouError) as err:
        arm_servo(str(path))
    (d,) = err.value.diagnostics
    assert d.code == "V109" and words in d.message, d.message


def test_tracked_never_overwrites_an_input(tmp_path, capsys):
    """--tracked goes through the output rule: the behaviour itself is refused (I502,
    exit 2) before the tracking is simulated, and left as it was."""
    src = tmp_path / "f.aou"
    src.write_text((BEHAVIOURS / "inactive.aou").read_text())
    before = src.read_bytes()
    assert main(["check", str(src), "--no-dynamic", "--track", "--tracked", str(src)]) == 2
    assert " I502 " in capsys.readouterr().err and src.read_bytes() == before


@pytest.mark.slow
def test_the_vendor_gen3_with_its_published_servos_keeps_the_shiver_with_feedforward(
        tmp_path, capsys):
    """The Gen3 URDF in the tests, described with Menagerie's Gen3 table: a tremor
    (fitted to the arm) loses part of its shiver to plain set-points, and feed-forward
    keeps it."""
    from tests.integration.test_fit import GEN3
    from tests.integration.test_track_report import TREMBLE

    desc = tmp_path / "gen3.toml"
    desc.write_text(f'urdf = "{GEN3}"\n[servo]\ntable = "kinova_gen3"\n')
    src = tmp_path / "tremble.aou"
    src.write_text(TREMBLE)
    main(["check", str(src), "--robot", str(desc), "--fit",
          "--no-dynamic", "--no-collision-check", "--track", "--format", "json"])
    doc = json.loads(capsys.readouterr().out)
    assert doc["tracking"]["servo"]["source"].startswith("MuJoCo Menagerie")
    shiver = {m["mode"]: next(d for d in m["descriptors"]
                              if d["descriptor"] == "shiver_amplitude")
              for m in doc["tracking"]["modes"]}
    assert not shiver["position"]["ok"] and shiver["feedforward"]["ok"]


def test_a_behaviour_the_arm_refuses_is_tracked_as_a_what_if_and_the_user_is_told_why(
        capsys):
    """Fearful's shiver is too fast for the Kinova as written (C308): --track tracks the
    motion as declared as a what-if (tests/integration/test_track_what_if.py), says the
    file still fails, and that --fit cannot give one that stays a fearful tremor."""
    assert main(["check", str(BEHAVIOURS / "fearful.aou"), "--robot", "kinova",
                 "--track"]) == 1
    captured = capsys.readouterr()
    err = captured.err
    assert " C308 " in err and "nothing to track" not in err and "C315" in err
    assert captured.out.startswith("what if:")
