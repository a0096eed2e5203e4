"""Behaviours as DMPs: the round trip through a DMP keeps the motion and its meaning, the
scaling rules hold when the goal and the tempo change, and the files are the library's."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("movement_primitives")

import aou_dsl  # noqa: E402
from aou_dsl.core.diagnostics import AouError
from aou_dsl.dmp import read_dmp, solve, to_dmp, write_dmp
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.robot.load import load_arm

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def hesitant():
    build = aou_dsl.compile("behaviours/hesitant.aou")
    assert build.ok
    return build, to_dmp(build.trajectory, state="hesitant")


def _pose_error(a, b, offset: float) -> tuple[float, float]:
    """Worst hand position [mm] and orientation [deg] difference between trajectory ``a``
    and ``b``, whose clock runs ``offset`` seconds ahead (``b`` interpolated at a's times)."""
    arm = load_arm(a.robot, a.ee_frame)
    pa, ra = arm.fk(a.q)
    qb = np.array([np.interp(a.t + offset, b.t, b.q[:, j]) for j in range(b.q.shape[1])]).T
    pb, rb = arm.fk(qb)
    ang = [math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(x.T @ y) - 1) / 2))))
           for x, y in zip(ra, rb, strict=True)]
    return 1000 * float(np.linalg.norm(pa - pb, axis=1).max()), max(ang)


def _within(name, want, got, slack=1.0) -> bool:
    if want is None or got is None:
        return want is None and got is None
    return abs(got - want) <= slack * REGISTRY[name].tolerance(want) + 1e-9


@pytest.mark.parametrize("name, robot", [
    ("confident", "panda"), ("curious", "panda"), ("hesitant", "panda"),
    ("fearful", "panda"), ("inactive", "panda"), ("confident", "ur5"), ("curious", "ur5"),
    ("hesitant", "ur5"), ("inactive", "ur5")])
def test_same_goal_and_tempo_reproduces_the_compiled_motion(name, robot):
    """Rolled out at its own goal and tempo, a shipped behaviour's hand stays within 1 mm
    and 0.5 deg of the compiled trajectory, passes the safety checks, and measures every
    descriptor as the compiled trajectory does, within the descriptor's tolerance. On
    the Panda and the UR5, every shipped behaviour but fearful on the UR5 (whose wrist
    shivers at a tremor's rate only too narrow to stay fearful: --fit refuses it), each
    fitted to the arm as ``--fit`` does where the file asks more than the arm gives."""
    from aou_dsl.lang.descriptors import compare

    build = aou_dsl.compile(f"behaviours/{name}.aou", robot=robot)
    if not build.ok and robot != "panda":
        build = aou_dsl.compile(f"behaviours/{name}.aou", robot=robot, fit=True)
    assert build.ok, [d.message for d in build.diagnostics]
    seq = to_dmp(build.trajectory, state=name)
    out = solve(seq)
    assert out.ok, [d.message for d in out.diagnostics]
    mm, deg = _pose_error(build.trajectory, out.trajectory, out.rollout.offset)
    assert mm < 1.0 and deg < 0.5, (mm, deg)
    assert compare(build.measured.descriptors, out.measured.descriptors) == []


@pytest.mark.parametrize("name, move, k", [
    ("hesitant", (0.05, 0.05, 0.0), 1.5), ("hesitant", (-0.05, -0.04, 0.05), 0.8),
    ("curious", (0.0, 0.06, -0.03), 2.0), ("fearful", (0.04, 0.0, 0.02), 0.5)])
def test_moved_goal_and_time_scale_follow_the_scaling_rules(hesitant, name, move, k):
    """Goal moved by up to 10 cm and the tempo scaled by 0.5 to 2: every descriptor
    measured on the rolled-out motion is what its scaling rule predicts from the compiled
    one, within its tolerance (pauses K times as long, accelerations s / K^2 times as
    high, distances s times, angles and counts kept), and the motion passes the safety
    checks; or it is refused with a code naming the limit (D603, D604)."""
    from aou_dsl.lang.descriptors import compare

    build, seq = hesitant
    if name != "hesitant":
        build = aou_dsl.compile(f"behaviours/{name}.aou")
        seq = to_dmp(build.trajectory, state=name)
    assert np.linalg.norm(move) <= 0.1
    out = solve(seq, goal=tuple(np.add(seq.goal, move)), time_scale=k)
    refused = [d for d in out.diagnostics if d.code in ("D603", "D604")]
    if refused:
        assert not out.ok and all("limit" in d.message or "reach" in d.message
                                  for d in refused), [d.message for d in refused]
        return
    assert out.ok, [d.message for d in out.diagnostics]
    src, m, s = build.measured.descriptors, out.measured.descriptors, out.rollout.scale
    assert m["pause_count"] == src["pause_count"]
    assert _within("pause_duration", src["pause_duration"] * k, m["pause_duration"])
    assert _within("approach_acceleration", src["approach_acceleration"] * s / k ** 2,
                   m["approach_acceleration"])
    assert compare(out.rollout.predicted, m) == []


def test_pinned_acceleration_is_kept_when_the_goal_moves(hesitant):
    """A pinned approach acceleration keeps its value at a goal 8 cm further away."""
    build, seq = hesitant
    out = solve(seq, goal=(0.63, 0.0, 0.25), pinned=("approach_acceleration",), check=False)
    assert out.rollout.scale > 1.1
    assert _within("approach_acceleration", build.measured.descriptors["approach_acceleration"],
                   out.measured.descriptors["approach_acceleration"])


def test_intensity_moves_pauses_without_a_replan(hesitant):
    """Hesitance reads stronger with longer pauses: at intensity 1 a pause is the
    synthesis' span (1.5x) longer than at 0.5, rolled from the same DMPs."""
    build, seq = hesitant
    out = solve(seq, intensity=1.0, check=False)
    assert _within("pause_duration", 1.5 * build.measured.descriptors["pause_duration"],
                   out.measured.descriptors["pause_duration"])


@pytest.mark.parametrize("k", [1.0, 1.37, 1.79])
def test_a_motion_ends_at_rest_at_any_time_scale(hesitant, k):
    """Each motion's rollout ends at its goal exactly at its (scaled) duration and at
    rest, so that holding its end pose after it adds no step of velocity: read at the
    sequence's rate, from any phase of the samples, the hand's acceleration (second
    differences) around the motion's start and end never leaves the range the motion's
    own acceleration spans over the same samples. A step of velocity would read as a
    spike beyond it: a reversal rolled out at a time scale of 1.79 read 3.6 % over its rule."""
    from aou_dsl.dmp.rollout import _rolled

    _, seq = hesitant
    h = 1.0 / seq.rate
    for i, part in enumerate(seq.parts):
        if part.dmp is None:
            continue
        runs, spline = _rolled({}, i, part, part.start, part.end, 1.0, np.eye(3), k, False)
        assert runs == pytest.approx(k * part.dmp.execution_time_, abs=1e-9)
        assert np.allclose(spline(runs), part.end, atol=1e-9)
        fine = np.linspace(0.0, runs, 20001)
        peak = float(np.abs(spline(fine, 2)[:, :3]).max())
        for edge in (0.0, runs):
            for shift in np.linspace(0.0, h, 5, endpoint=False):
                t = edge + shift + h * np.arange(-5, 6)
                read = np.diff(spline(np.clip(t, 0.0, runs))[:, :3], 2, axis=0) / h ** 2
                for j, row in enumerate(read):
                    span = np.linspace(t[j], t[j + 2], 401)
                    inside = ((span > 0.0) & (span < runs))[:, None]
                    acc = np.where(inside, spline(np.clip(span, 0.0, runs), 2)[:, :3], 0.0)
                    beyond = np.maximum(row - acc.max(axis=0), acc.min(axis=0) - row)
                    assert beyond.max() <= 1e-3 * peak, (part.kind, edge, shift, j)


def test_unreachable_goal_is_refused_with_a_code(hesitant):
    """A goal far out of reach is refused (D603), not rolled out."""
    _, seq = hesitant
    out = solve(seq, goal=(1.5, 0.0, 0.25), check=False)
    assert not out.ok and {d.code for d in out.diagnostics} == {"D603"}


def test_written_folder_reads_back_to_the_same_rollout(hesitant, tmp_path):
    """write_dmp then read_dmp gives a sequence that rolls out to the same poses."""
    from aou_dsl.dmp.rollout import roll

    _, seq = hesitant
    write_dmp(str(tmp_path / "h.dmp"), seq)
    back = read_dmp(str(tmp_path / "h.dmp"))
    a, b = roll(seq, goal=(0.6, 0.0, 0.25)), roll(back, goal=(0.6, 0.0, 0.25))
    assert np.allclose(a.pos, b.pos, atol=1e-9) and np.allclose(a.t, b.t)


def test_a_folder_that_is_not_a_sequence_is_refused(tmp_path):
    """A manifest of another format is D602; a missing folder I501."""
    (tmp_path / "x.dmp").mkdir()
    (tmp_path / "x.dmp" / "manifest.json").write_text('{"format": "other"}')
    with pytest.raises(AouError) as err:
        read_dmp(str(tmp_path / "x.dmp"))
    assert err.value.diagnostics[0].code == "D602"
    with pytest.raises(AouError) as err:
        read_dmp(str(tmp_path / "missing.dmp"))
    assert err.value.diagnostics[0].code == "I501"


def test_cli_compile_then_roll(tmp_path, capsys):
    """`aouc compile --format dmp` writes the folder (a second compile replaces it, never
    writes inside it); `aouc dmp roll` rolls it to a new goal and writes a trajectory that
    `aouc measure` reads."""
    from aou_dsl.cli.commands import main

    out = tmp_path / "c.dmp"
    assert main(["compile", "behaviours/confident.aou", "-o", str(out)]) == 0
    assert (out / "manifest.json").is_file()
    assert main(["compile", "behaviours/confident.aou", "-o", str(out)]) == 0  # replaced
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json", "parts"]
    rolled = tmp_path / "r.json"
    assert main(["dmp", "roll", str(out), "--goal", "0.58,0.03,0.27", "--time-scale", "1.2",
                 "-o", str(rolled)]) == 0
    assert "pause_duration" in capsys.readouterr().out
    assert main(["measure", str(rolled)]) == 0


def test_goal_changed_mid_motion_blends_within_the_declared_peak(hesitant):
    """The goal moves 7 cm while the second approach runs: the blended motion passes the
    safety checks, and its approach peak is within 10 % of the larger of the peaks the
    scaling rules give toward either goal."""
    from aou_dsl.dmp.blend import change_goal
    from aou_dsl.dmp.rollout import roll

    _, seq = hesitant
    goal = (0.60, 0.05, 0.25)
    ro = roll(seq)
    t0, t1 = [(a, b) for k, a, b in ro.parts if k == "approach"][1]
    out = change_goal(seq, 0.5 * (t0 + t1), goal)
    assert out.ok, [d.message for d in out.diagnostics]
    toward = [roll(seq, goal=g).predicted["approach_acceleration"] for g in (seq.goal, goal)]
    assert out.measured.descriptors["approach_acceleration"] <= 1.1 * max(toward)
    assert out.measured.descriptors["pause_count"] == seq.descriptors["pause_count"]


def test_intensity_changed_while_running_keeps_the_motion_continuous(hesitant):
    """Hesitance raised to intensity 1 during the first pause: the motion before the
    change is the one already running, the later pauses are 1.5x longer, and the joint
    accelerations change by no more from sample to sample than they do without a
    change (continuous q, qd, qdd)."""
    from aou_dsl.core.diagnostics import Span
    from aou_dsl.dmp.intensity import change_intensity
    from aou_dsl.dmp.rollout import roll
    from aou_dsl.dmp.solve import to_trajectory

    _, seq = hesitant
    before = roll(seq)
    pause = next((a, b) for k, a, b in before.parts if k == "pause")
    at = 0.5 * sum(pause)
    after = change_intensity(seq, at, 1.0)
    n = int(np.searchsorted(before.t, pause[1]))
    assert np.allclose(after.pos[:n], before.pos[:n], atol=1e-12)
    holds = [b - a for k, a, b in after.parts if k == "pause"]
    assert holds[0] == pytest.approx(pause[1] - pause[0])
    assert holds[1] == pytest.approx(1.5 * holds[0], rel=1e-6)
    where = Span.whole_file("<test>")
    steps = [np.abs(np.diff(to_trajectory(seq, ro, where).qdd, axis=0)).max()
             for ro in (before, after)]
    assert steps[1] <= 1.05 * steps[0]


@pytest.mark.parametrize("code", ["D603", "D604"])
def test_each_rollout_rule_example_triggers_its_own_code(code, tmp_path, capsys, monkeypatch):
    """`aouc rules D603|D604` show commands; run on the shipped behaviour they name,
    compiled to a .dmp folder, each reports that very code and exits 1."""
    import shlex

    from aou_dsl.cli.commands import main
    from aou_dsl.core.diagnostics import RULES

    argv = shlex.split(RULES[code].example.split("#")[0])[1:]
    name = argv[2].removesuffix(".dmp")
    monkeypatch.chdir(tmp_path)
    assert main(["compile", str(ROOT / "behaviours" / f"{name}.aou"),
                 "-o", f"{name}.dmp"]) == 0
    capsys.readouterr()
    assert main(argv) == 1
    assert f" {code} " in capsys.readouterr().err


def test_bad_dmp_rule_example_triggers_its_own_code(tmp_path, capsys):
    """D602's example, a manifest of another format, is refused with D602 (exit 1)."""
    import json as _json

    from aou_dsl.cli.commands import main
    from aou_dsl.core.diagnostics import RULES

    where, text = RULES["D602"].example.split(": ", 1)
    (tmp_path / where).parent.mkdir()
    (tmp_path / where).write_text(text)
    assert _json.loads(text)["format"] != "aou-dmp/1"
    assert main(["dmp", "roll", str(tmp_path / "x.dmp")]) == 1
    assert " D602 " in capsys.readouterr().err


def test_recording_cannot_become_dmps():
    """D601: a trajectory without the compiler's episodes (a recording) is refused."""
    build = aou_dsl.compile("behaviours/confident.aou")
    with pytest.raises(AouError) as err:
        to_dmp(build.trajectory.with_(episodes=()))
    assert err.value.diagnostics[0].code == "D601"


def test_without_the_extra_the_command_names_it(tmp_path, capsys, monkeypatch):
    """With movement_primitives missing, `aouc compile --format dmp` says which extra to
    install (exit 2) and writes nothing."""
    import sys

    from aou_dsl.cli.commands import main

    for name in ("movement_primitives", "movement_primitives.dmp", "movement_primitives.io",
                 "pytransform3d", "pytransform3d.rotations"):
        monkeypatch.setitem(sys.modules, name, None)
    out = tmp_path / "c.dmp"
    assert main(["compile", "behaviours/confident.aou", "-o", str(out)]) == 2
    assert "pip install '.[dmp]'" in capsys.readouterr().err
    assert not out.exists() and list(tmp_path.iterdir()) == []
