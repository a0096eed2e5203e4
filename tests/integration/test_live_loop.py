"""The closed loop (aou_dsl.live.loop): perception -> regulator -> checked re-plans.

Known scenes run through the geometric model: a clear view stays confident; a card
sliding over the tag walks the state towards curious and then hesitant and back when it
leaves, without chattering; darkness ends fearful or inactive, as the mapping says. The
executed motion keeps jerk within the arm's limits at the controller's rate and has no
jump in q, qd or qdd at any switch; a re-plan the gate refuses is held and the arm keeps
its motion; the recording cut at its switches measures (``aouc measure``) as the plans
of the states and intensities the log names.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import aou_dsl
from aou_dsl.core.diagnostics import AouError
from aou_dsl.lang.cv import classify
from aou_dsl.lang.ir import State
from aou_dsl.live import loop
from aou_dsl.live.geometric import Geometric
from aou_dsl.live.perception import Estimate
from aou_dsl.live.regulator import Hysteresis, Regulator
from aou_dsl.live.scenario import load, parse
from tests.conftest import ROOT

SCENARIOS = ROOT / "examples" / "scenarios"
EPS = 1e-9

CARD = """
duration = 22.0
[scene]
light = 1.0
[[occluder]]
name = "card"
center = [0.45, 0.16, 0.06]
size = [0.01, 0.06, 0.12]
[[event]]
kind = "move"
what = "card"
at = 2.0
duration = 5.0
to = [0.45, 0.0, 0.06]
[[event]]
kind = "move"
what = "card"
at = 12.0
duration = 5.0
to = [0.45, 0.16, 0.06]
"""

DARK = """
duration = 14.0
[[event]]
kind = "light"
at = 1.0
duration = 10.0
to = 0.02
"""


@pytest.fixture(scope="module")
def reg() -> Regulator:
    """One regulator whose plans every run shares (each run starts it afresh)."""
    return Regulator("panda", intensity_step=0.5, hysteresis=loop.HYSTERESIS)


def _fresh(reg: Regulator) -> Regulator:
    reg.rollback((None, None, None))
    reg._u = None
    return reg


def _run(reg, text: str, perception=None, **kw) -> loop.Run:
    sc = parse(text)
    return loop.run(perception or Geometric(sc.scene_at), duration=sc.duration, rate=sc.rate,
                    regulator=_fresh(reg), **kw)


def _states(r: loop.Run) -> list[str]:
    """The expressed states in order, each run of ticks once."""
    out: list[str] = []
    for tk in r.ticks:
        if not out or out[-1] != tk.state:
            out.append(tk.state)
    return out


@pytest.fixture(scope="module")
def card(reg) -> loop.Run:
    return _run(reg, CARD)


def test_a_clear_view_is_confident(reg):
    r = _run(reg, (SCENARIOS / "clear-view.toml").read_text())
    assert {tk.state for tk in r.ticks} == {"confident"}
    assert min(tk.confidence for tk in r.ticks) > 0.95
    assert all(s.kind != "held" for s in r.switches)


def test_a_card_over_the_tag_walks_to_hesitant_and_back(card):
    """Curious, then hesitant while the tag is hidden, and back to confident when the card
    leaves: each state entered once on the way (no chattering as the window slides)."""
    assert _states(card) == ["confident", "curious", "hesitant", "curious", "confident"]
    at = {round(tk.t, 2): tk for tk in card.ticks}
    assert at[10.0].state == "hesitant" and at[1.0].state == at[21.0].state == "confident"
    # the tag is fully hidden: the evidence says so, and the uncertainty is 1 - confidence
    assert at[10.0].evidence["visible"] == 0.0
    assert all(abs(tk.uncertainty - (1.0 - tk.confidence)) < 1e-12 for tk in card.ticks)


def test_darkness_ends_fearful_or_inactive(reg):
    """The light dims to dark: the states follow the mapping's order (confident, curious,
    hesitant, fearful, inactive), never back, and the dark end is inactive."""
    r = _run(reg, DARK)
    order = [s.value for s in (State.CONFIDENT, State.CURIOUS, State.HESITANT,
                               State.FEARFUL, State.INACTIVE)]
    seen = _states(r)
    assert seen[0] == "confident" and seen[-1] in ("fearful", "inactive")
    assert [order.index(s) for s in seen] == sorted(order.index(s) for s in seen)
    assert "fearful" in seen and r.ticks[-1].state == "inactive"


def test_no_chattering_where_a_threshold_is_crossed_slowly(reg):
    """A user's perception drifts slowly across the confident/curious border with noise
    a hundred times the drift between ticks: one switch of state, not many."""
    rng = np.random.default_rng(3)

    def perceive(t: float) -> float:
        return float(np.clip(0.92 - 0.01 * t + rng.normal(0.0, 0.01), 0.0, 1.0))

    r = loop.run(perceive, duration=16.0, rate=100.0, regulator=_fresh(reg))
    states = _states(r)
    assert states == ["confident", "curious"], states
    # without hysteresis the same signal chatters: the check can fail
    rng = np.random.default_rng(3)
    bare = Regulator("panda", intensity_step=0.5,
                     hysteresis=Hysteresis(state=0.0, intensity=0.0, uncertainty=0.0))
    bare._plans, bare._texts = reg._plans, reg._texts
    r2 = loop.run(perceive, duration=16.0, rate=100.0, regulator=bare)
    assert len(_states(r2)) > 3


def test_a_users_perception_drives_the_regulator(reg):
    """An object with perceive(t), answering Estimates, steps from sure to half sure to
    blind: the regulator expresses confident, hesitant, then inactive."""

    class Detector:
        def perceive(self, t: float) -> Estimate:
            c = 1.0 if t < 3.0 else 0.5 if t < 6.0 else 0.0
            return Estimate(c, (0.6, 0.0, 0.04) if c else None)

    r = loop.run(Detector(), duration=9.0, rate=50.0, regulator=_fresh(reg))
    assert _states(r) == ["confident", "hesitant", "inactive"]
    kinds = [(s.kind, s.state) for s in r.switches]
    assert ("replan", "hesitant") in kinds and ("replan", "inactive") in kinds


def test_jerk_within_limits_and_no_jump_at_any_switch(reg, card):
    """The executed motion at the controller's rate passes the joint-jerk check, and at
    each switch the finite differences stay within the arm's jerk and acceleration
    limits (a jump in q, qd or qdd breaks them: tests/integration/test_live.py explains
    the bounds)."""
    from aou_dsl.safety.controllers import controller_checks

    tr = card.trajectory
    jerk = [c for c in controller_checks(tr, None, rate=card.rate) if c.name == "joint-jerk"]
    assert jerk and all(c.ok for c in jerk), [c.detail for c in jerk]
    arm = reg.arm
    switched = [s for s in card.switches if s.kind in ("replan", "restart")]
    assert len(switched) >= 4
    for s in switched:
        k = int(np.searchsorted(tr.t, s.start - 1e-9))
        w = slice(max(k - 5, 0), k + 6)
        t, q, qd, qdd = tr.t[w], tr.q[w], tr.qd[w], tr.qdd[w]
        h = np.diff(t)[:, None]
        assert np.all(np.abs(np.diff(qdd, axis=0)) <= arm.jmax * h + EPS)
        assert np.all(np.abs(np.diff(qd, axis=0) - h * (qdd[1:] + qdd[:-1]) / 2)
                      <= arm.jmax * h ** 2 / 4 + EPS)
        assert np.all(np.abs(np.diff(q, axis=0) - h * (qd[1:] + qd[:-1]) / 2)
                      <= arm.amax * h ** 2 / 4 + EPS)


def test_the_gate_refuses_what_must_not_reach_the_arm(reg, card):
    tr = card.trajectory
    x = (tr.q[0], tr.qd[0], tr.qdd[0])
    assert loop.gate(reg, tr, x, 100.0) is None
    moved = (tr.q[0] + 0.01, tr.qd[0], tr.qdd[0])
    assert "position" in loop.gate(reg, tr, moved, 100.0)
    k = len(tr.t) // 3  # a step in position halfway: a jerk no arm has
    jolted = tr.with_(q=np.vstack([tr.q[:k], tr.q[k:] + 0.02]))
    assert "jerk" in loop.gate(reg, jolted, x, 100.0)
    beyond = tr.with_(q=np.where(np.arange(len(tr.t))[:, None] == k, reg.arm.upper + 0.1,
                                 tr.q))
    assert "joint ranges" in loop.gate(reg, beyond, x, 100.0)


def test_a_refused_replan_is_held_and_the_arm_keeps_its_motion(reg, monkeypatch):
    """The regulator's re-plan into hesitant is spoiled (shifted off the arm's state):
    the loop does not send it, says why, and the arm goes on with the confident reach;
    once the regulator fails outright the same holds."""
    real = Regulator.replan

    def spoiled(self, q, qd, qdd, state, level, **kw):
        rep = real(self, q, qd, qdd, state, level, **kw)
        if state is State.HESITANT:
            rep.trajectory = rep.trajectory.with_(q=rep.trajectory.q + 0.05)
        return rep

    monkeypatch.setattr(Regulator, "replan", spoiled)
    steps = lambda t: 1.0 if t < 1.0 else 0.5  # noqa: E731
    r = loop.run(steps, duration=3.0, rate=50.0, regulator=_fresh(reg))
    held = [s for s in r.switches if s.kind == "held"]
    assert held and held[0].state == "hesitant" and "position" in held[0].reason
    assert len(held) == 1  # logged once, not at every tick it lasts
    assert {tk.state for tk in r.ticks} == {"confident"}
    plan = reg.plan(State.CONFIDENT, 1.0)
    n = min(len(plan.t), len(r.trajectory.t))
    assert np.allclose(r.trajectory.q[:n], plan.q[:n])

    def broken(self, *a, **kw):
        raise AouError([])

    monkeypatch.setattr(Regulator, "replan", broken)
    with pytest.raises(AouError, match="never sent the arm a motion"):
        loop.run(steps, duration=0.5, rate=50.0, regulator=_fresh(reg))


def _measured(path) -> dict:
    return aou_dsl.measure(str(path)).descriptors


def _plan_from(reg, state: str, level: float, join: float, duration: float):
    """The plan of ``state`` at ``level`` from ``join`` for ``duration`` [s]."""
    plan = reg.plan(State(state), level)
    i = int(np.searchsorted(plan.t, join - 1e-9))
    t0 = plan.t[i]
    j = int(np.searchsorted(plan.t, t0 + duration + 1e-9))
    return plan.with_(t=plan.t[i:j] - t0, q=plan.q[i:j], qd=plan.qd[i:j], qdd=plan.qdd[i:j],
                      episodes=tuple((k, a - t0, b - t0) for k, a, b in plan.episodes
                                     if a >= t0 - 1e-9 and b <= t0 + duration + 1e-9))


def test_the_recording_measures_as_the_states_the_log_names(reg, card, tmp_path):
    """The run's recording, cut at its switches (after each transition), read back by
    `aouc measure`: each segment has the descriptors of the plan of the state and
    intensity the log says the regulator chose, over the same stretch of it (from where
    it joined, as long as the arm followed it); a whole reach reads (C-V) as its state."""
    doc = loop.document(card)
    assert json.loads(json.dumps(doc))["live"]["ticks"]["state"][0] == "confident"
    segs = [(s, d) for s, d in loop.segments(card, doc) if d["duration"] >= 2.0]
    assert {s.state for s, _ in segs} >= {"confident", "hesitant"}
    whole = 0
    for k, (s, d) in enumerate(segs):
        path = tmp_path / f"segment{k}.json"
        path.write_text(json.dumps(d))
        got = _measured(path)
        want = aou_dsl.measure(_plan_from(reg, s.state, s.intensity, s.join,
                                          d["duration"])).descriptors
        for name, w in want.items():
            g = got[name]
            assert (g is None) == (w is None), (s, name, g, w)
            if w is not None:
                assert g == pytest.approx(w, rel=0.02, abs=0.01), (s, name, g, w)
        if s.join == 0.0 and d["live"]["switch"]["complete"]:
            whole += 1
            cv = aou_dsl.measure(str(path)).cv
            assert classify(cv.C, cv.V).value == s.state
    assert whole >= 2
    # the same through the command line, on the hesitant stretch
    k = next(k for k, (s, _) in enumerate(segs) if s.state == "hesitant")
    out = subprocess.run([sys.executable, "-m", "aou_dsl", "measure",
                          str(tmp_path / f"segment{k}.json"), "--format", "json"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    cli = json.loads(out.stdout)["descriptors"]
    assert cli["retreat_count"] == _measured(tmp_path / f"segment{k}.json")["retreat_count"] > 0


def test_aouc_live_runs_a_shipped_scenario(tmp_path):
    """The command: the recording and the segments it names, a summary; inputs never
    overwritten; a bad scenario is I507 with exit 2 (an input error), not a traceback."""
    out = tmp_path / "run.json"
    p = subprocess.run([sys.executable, "-m", "aou_dsl", "live",
                        str(SCENARIOS / "clear-view.toml"), "-o", str(out)],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    doc = json.loads(out.read_text())
    assert doc["format"] == "aou-trajectory/1" and len(doc["live"]["ticks"]["t"]) == 1200
    assert "confident" in p.stdout
    bad = tmp_path / "bad.toml"
    bad.write_text("duration = 5\n[[event]]\nkind = \"move\"\nwhat = \"card\"\nat = 1\n"
                   "to = [0, 0, 0]\n")
    p = subprocess.run([sys.executable, "-m", "aou_dsl", "live", str(bad)],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and "I507" in p.stderr and "Traceback" not in p.stderr
    p = subprocess.run([sys.executable, "-m", "aou_dsl", "live", str(bad), "-o", str(bad)],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode != 0 and "I502" in p.stderr
    assert bad.read_text().startswith("duration = 5")


def test_shipped_scenarios_load():
    for path in sorted(SCENARIOS.glob("*.toml")):
        sc = load(str(path))
        assert sc.duration > 0 and sc.scene_at(0.0).light > 0


def test_aouc_live_renders_the_camera_the_confidence_and_the_arm(tmp_path):
    pytest.importorskip("imageio")
    pytest.importorskip("pupil_apriltags")
    import imageio.v2 as imageio

    sc = tmp_path / "short.toml"
    sc.write_text("duration = 1.5\n[scene]\nlight = 0.5\n")
    video = tmp_path / "run.mp4"
    p = subprocess.run([sys.executable, "-m", "aou_dsl", "live", str(sc), "--perception",
                        "camera", "--render", str(video), "-q"],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    reader = imageio.get_reader(str(video))
    frames = [f for f in reader]  # noqa: C416 - list() asks its length: an infinite one
    reader.close()
    assert len(frames) == 15 and frames[0].shape == (240, 960, 3)
    # the camera's panel shows the scene dimmed: darker than the plot's white panel
    assert frames[5][40:, :320].mean() < frames[5][40:, 320:640].mean() - 50


def test_observe_takes_a_perceptions_estimate(reg):
    """Regulator.observe is update with uncertainty = 1 - confidence; what is not an
    Estimate is refused."""
    from tests.conftest import fails_with

    r = _fresh(reg)
    q0 = r.plan(State.CONFIDENT, 1.0).q[0]
    rep = r.observe(q0, None, None, Estimate(0.5), restart=True)
    assert rep is not None and rep.state is State.HESITANT
    fails_with("I504", r.observe, q0, None, None, 0.5)


@pytest.mark.slow
@pytest.mark.parametrize(("name", "states"), [
    ("occluder", ["confident", "curious", "hesitant", "curious", "confident"]),
    ("dimming", ["confident", "curious", "hesitant", "fearful", "inactive"]),
])
def test_aouc_live_runs_the_shipped_scenarios(tmp_path, name, states):
    """The longer variant of the known scenes, through the command on the files that
    ship: the states the recording logs, in order."""
    out = tmp_path / "run.json"
    p = subprocess.run([sys.executable, "-m", "aou_dsl", "live",
                        str(SCENARIOS / f"{name}.toml"), "-o", str(out), "-q"],
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    logged = json.loads(out.read_text())["live"]["ticks"]["state"]
    seen = [s for k, s in enumerate(logged) if k == 0 or logged[k - 1] != s]
    assert seen == states


def test_detectors_are_freed_without_crashing_the_process():
    """pupil-apriltags frees a detector's tag families before the detector, whose
    teardown still reads them: a use after free. glibc's MALLOC_PERTURB_ fills freed
    memory with garbage, so that order crashes the process within a few detectors
    (without it, after some hundreds). aou's detector frees them in the safe order."""
    pytest.importorskip("pupil_apriltags")
    code = (
        "import gc, numpy as np\n"
        "from aou_dsl.live.camera import detector\n"
        "img = (np.random.default_rng(0).random((240, 320)) * 255).astype(np.uint8)\n"
        "for _ in range(20):\n"
        "    d = detector(); d.detect(img)\n"
        "    del d; gc.collect()\n"
    )
    env = {**os.environ, "MALLOC_PERTURB_": "165"}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, cwd=ROOT, env=env)
    assert run.returncode == 0, run.stderr[-2000:]


def test_the_recording_keeps_one_sample_step_across_every_switch(card):
    """A controller's clock has one step: every transition lasts a whole number of the
    plan's samples, so the executed motion is sampled evenly from its start to its end
    (`aouc measure` reads it as one recording)."""
    t = loop.document(card)["t"]
    step = np.diff(t)
    assert len(card.switches) >= 4
    assert step.max() - step.min() < 1e-9, (step.min(), step.max())


def test_a_new_reach_starts_from_rest_after_its_return(card, tmp_path):
    """At a restart the arm comes back to where the reach starts and holds there
    RESTART_HOLD before it reaches again; the stretch around it measures as a return, a
    pause and an approach (the return and the reach run into each other otherwise, and
    the measurement's own check refused the whole run there)."""
    from aou_dsl.live.splice import RESTART_HOLD

    tr = card.trajectory
    doc = loop.document(card)
    restarts = [s for s in card.switches if s.kind == "restart"]
    assert restarts
    for s in restarts:
        begin = s.start + s.transition
        held = (tr.t >= begin - RESTART_HOLD + 1e-6) & (tr.t < begin - 1e-6)
        assert held.sum() >= round(RESTART_HOLD * 250) - 2
        assert np.abs(tr.qd[held]).max() < 1e-9 and np.abs(tr.qdd[held]).max() < 1e-9
        t = np.asarray(doc["t"])
        rows = np.flatnonzero((t >= s.start - 1.0) & (t < begin + 3.0))
        sub = {k: v for k, v in doc.items() if k not in ("t", "q", "qd", "qdd", "live",
                                                         "episodes")}
        sub |= {"t": (t[rows] - t[rows[0]]).tolist(), "episodes": [],
                "duration": float(t[rows[-1]] - t[rows[0]]),
                **{k: [doc[k][i] for i in rows] for k in ("q", "qd", "qdd")}}
        path = tmp_path / f"restart-{s.t:.2f}.json"
        path.write_text(json.dumps(sub))
        kinds = [e.kind for e in aou_dsl.measure(str(path)).episodes]
        assert "pause" in kinds and "approach" in kinds, kinds


def test_the_whole_recorded_run_measures(card, tmp_path):
    """`aouc measure` reads the whole recording of a run, switches and restarts included
    (its own checks once refused it at a restart)."""
    path = tmp_path / "run.json"
    path.write_text(json.dumps(loop.document(card)))
    m = aou_dsl.measure(str(path))
    kinds = {e.kind for e in m.episodes}
    assert {"approach", "pause", "retreat"} <= kinds
    out = subprocess.run([sys.executable, "-m", "aou_dsl", "measure", str(path)],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr


FOLLOW = """
duration = 12.0
goal = [0.55, 0.0, 0.25]
follow = true
[scene]
target = [0.6, 0.0, 0.04]
[[event]]
kind = "move"
what = "target"
at = 2.0
duration = 3.0
to = [0.6, 0.08, 0.04]
"""


def test_the_goal_follows_a_moving_target(reg, tmp_path):
    """With ``follow``, the goal moves with the target the perception sees (kept where
    the scenario's goal is from it): the loop re-plans (``retarget``) into plans for the
    new goal, each checked, and the arm's reach ends where the moved goal puts it."""
    from aou_dsl.live.scenario import parse
    from aou_dsl.robot.batch_fk import batch_fk

    sc = parse(FOLLOW)
    assert sc.offset == pytest.approx((-0.05, 0.0, 0.21))
    fresh = _fresh(reg)
    start_goal = fresh.goal
    fresh.goal = sc.goal
    try:
        r = loop.run(Geometric(sc.scene_at), duration=sc.duration, rate=sc.rate,
                     regulator=fresh, follow=sc.offset)
        moved = [s for s in r.switches if s.kind == "retarget"]
        assert moved and not [s for s in r.switches if s.kind == "held"]
        assert moved[-1].goal == pytest.approx((0.55, 0.08, 0.25), abs=0.021)
        assert all(b[1] >= a[1] for a, b in zip((s.goal for s in moved),
                                               (s.goal for s in moved[1:]), strict=False))
        last = r.switches[-1]
        plan_new = fresh.plan(State(last.state), last.intensity)
        fresh.goal = sc.goal
        plan_old = fresh.plan(State(last.state), last.intensity)
        arm = fresh.arm
        end_new = batch_fk(arm, plan_new.q[-1:])[0][0]
        end_old = batch_fk(arm, plan_old.q[-1:])[0][0]
        assert end_new - end_old == pytest.approx(np.subtract(last.goal, sc.goal), abs=0.01)
        doc = loop.document(r)
        assert doc["live"]["switches"][-1]["goal"] == pytest.approx(list(last.goal))
        segs = loop.segments(r, doc)
        assert segs[-1][1]["goal"]["position"] == pytest.approx(list(last.goal))
    finally:
        fresh.goal = start_goal
