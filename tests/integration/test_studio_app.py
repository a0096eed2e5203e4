"""The studio without a browser: a recording played with its measured episodes, a
variant pair on one clock, and the pieces of the page."""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("viser", reason="the studio extra is missing: pip install '.[studio]'")

from aou_dsl.api import compile as aou_compile
from aou_dsl.api import measure
from aou_dsl.studio import plots
from aou_dsl.studio.app import Studio

ROOT = str(Path(__file__).resolve().parents[2])


def _copy(tmp_path, name: str) -> str:
    path = tmp_path / f"{name}.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", f"{name}.aou"), path)
    return str(path)


def test_a_recording_plays_with_the_episodes_measure_finds(tmp_path):
    build = aou_compile(_copy(tmp_path, "hesitant"), check=False)
    rec = tmp_path / "rec.csv"
    tr = build.trajectory
    rows = ["t," + ",".join(tr.joint_names)] + [
        ",".join(f"{x:.6f}" for x in (t, *q)) for t, q in zip(tr.t, tr.q, strict=True)]
    rec.write_text("\n".join(rows) + "\n")  # a bare recording: no goal, no episodes
    studio = Studio(str(rec), robot="panda", port=0).start()
    try:
        shown = studio.shown
        assert shown.recorded and studio.sliders.handles == {}
        m = measure(shown.trajectory)
        want = [(e.kind, e.t_start + m.t_origin, e.t_end + m.t_origin) for e in m.episodes]
        assert list(shown.trajectory.episodes) == want
        assert {k for k, _, _ in want} >= {"approach", "pause", "retreat"}
        assert 'data-descriptor="pause_count"' in studio.table.content
    finally:
        studio.close()
    assert sorted(os.listdir(tmp_path)) == ["hesitant.aou", "rec.csv"]


def test_compare_shows_a_second_arm_on_the_same_clock(tmp_path):
    studio = Studio(_copy(tmp_path, "hesitant"), port=0,
                    compare=_copy(tmp_path, "fearful")).start()
    try:
        a, b = studio.shown.trajectory, studio.other.trajectory
        assert studio.player.duration == pytest.approx(max(a.duration, b.duration))
        studio.player.seek(2.0)
        for arm, tr in ((studio.arm, a), (studio.ghost, b)):
            k = arm.track.index(2.0)
            assert tr.t[k] - tr.t[0] <= 2.0 < tr.t[min(k + 1, len(tr.t) - 1)] - tr.t[0]
    finally:
        studio.close()


def test_the_profile_and_timeline_show_every_episode(tmp_path):
    build = aou_compile(_copy(tmp_path, "hesitant"), check=False)
    tr = build.trajectory
    speed = np.linspace(0, 0.1, len(tr.t))
    svg = plots.velocity_profile(tr.t, speed, tr.episodes)
    line = plots.timeline(tr.episodes, float(tr.t[0]), tr.duration, 1.5)
    for kind, _a, _b in tr.episodes:
        assert f"<title>{kind} " in svg and f"<title>{kind} " in line
    assert svg.count("<rect") == line.count("<rect") == len(tr.episodes)
    assert 'data-now="1.500"' in line


def test_a_synthesized_file_gets_an_intensity_slider_that_writes_it_again(tmp_path):
    from aou_dsl.synth.synthesis import synthesize

    path = tmp_path / "h.aou"
    path.write_text(synthesize("hesitant", intensity=0.5, verify=False))
    studio = Studio(str(path), port=0, watch=False).start()
    try:
        values = studio.sliders.values()
        assert values["intensity"] == 0.5 and "pause_duration" in values
        m = studio.set_values({**values, "intensity": 0.8})
        assert m.ok and studio.shown is m
        assert m.text == synthesize("hesitant", intensity=0.8, robot="panda", verify=False)
        assert studio.sliders.values()["intensity"] == 0.8
        studio.save()
        assert path.read_text() == m.text
    finally:
        studio.close()


def test_track_ghosts_the_arm_its_servos_give_and_follows_each_new_motion(tmp_path):
    """--track: the ghost is the shown plan as the Panda's published position servos
    track it (the same simulation as `aouc check --track`), so fearful's shiver is
    visibly smaller on it; a slider's new motion gets its own tracked ghost."""
    pytest.importorskip("mujoco")
    from aou_dsl.safety.track import track

    studio = Studio(_copy(tmp_path, "fearful"), port=0, track="position").start()
    try:
        plan = studio.shown.trajectory
        want = track(plan, "position").trajectory
        assert np.array_equal(studio.tracked.trajectory.q, want.q)
        assert studio.ghost.track is not None
        assert np.array_equal(studio.ghost.track.t, studio.arm.track.t)
        wrist = plan.joint_names.index("panda_joint7")
        swing = np.ptp(plan.q[:, wrist]), np.ptp(want.q[:, wrist])
        assert swing[1] < swing[0]  # the servos lag the shiver and narrow it
        assert "ghosted: the arm through its position servos" in studio.status.content
        m = studio.set_values({**studio.sliders.values(), "pause_duration": 2.0})
        assert m.ok and studio.shown.trajectory.duration > plan.duration
        again = track(studio.shown.trajectory, "position").trajectory
        assert np.array_equal(studio.tracked.trajectory.q, again.q)
    finally:
        studio.close()
