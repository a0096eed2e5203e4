"""What a new user met following the README, each as a promise that now holds.

(The bag written into a missing folder, and Ctrl-C's exit status, are in
tests/e2e/test_output_safety.py with the other writes.)
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from aou_dsl.cli.args import EXIT_ERRORS, EXIT_OK
from aou_dsl.cli.commands import main
from tests.conftest import BEHAVIOURS


@pytest.fixture
def here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


# --- a URDF whose meshes are missing ------------------------------------------------------


def _panda_without_meshes(folder: Path) -> Path:
    """The Panda's URDF with its meshes named where there are none."""
    from aou_dsl.robot.load import scene_urdf

    text = open(scene_urdf("panda")).read()
    text = re.sub(r'filename="[^"]*/([^/"]+)"', r'filename="gone/\1"', text)
    path = folder / "arm.urdf"
    path.write_text(text)
    return path


def test_robot_says_at_once_that_meshes_are_missing_and_how_to_compile_anyway(here,
                                                                             capsys):
    urdf = _panda_without_meshes(here)
    assert main(["robot", str(urdf)]) == EXIT_ERRORS
    out, err = capsys.readouterr()
    assert " V109 [error]" in err and "gone/" in err and "--no-check" in err
    assert "collision geometry: yes" not in out and "missing" in out
    # ... and compile, which needs the meshes for its checks, says the same
    (here / "m.aou").write_text('behaviour m : confident\nrobot "arm.urdf"\napproach\n')
    assert main(["compile", "m.aou", "-o", "m.json"]) == EXIT_ERRORS
    err = capsys.readouterr().err
    assert " V109 [error]" in err and "--no-check" in err and not (here / "m.json").exists()


@pytest.mark.parametrize("name,meant", [("franka", "panda"), ("Franka-Panda", "panda"),
                                        ("ur5e", "ur5"), ("xarm", "xarm7")])
def test_robot_suggests_the_arm_a_common_name_means(name, meant, capsys):
    assert main(["robot", name]) == EXIT_ERRORS
    assert f"did you mean `{meant}`?" in capsys.readouterr().err


# --- measure without a goal ----------------------------------------------------------------


def test_measure_without_a_goal_names_no_state_it_cannot_place(here, capsys):
    assert main(["compile", str(BEHAVIOURS / "curious.aou"), "--no-check", "-o",
                 "c.json"]) == EXIT_OK
    doc = json.loads((here / "c.json").read_text())
    del doc["goal"]
    (here / "blind.json").write_text(json.dumps(doc))
    capsys.readouterr()
    assert main(["measure", "blind.json"]) == EXIT_OK
    (line,) = [ln for ln in capsys.readouterr().out.splitlines() if "C-V" in ln]
    states = ("confident", "curious", "hesitant", "fearful", "inactive")
    assert "not placed" in line and "goal" in line, line
    assert not any(s in line for s in states), line
    assert main(["measure", "blind.json", "--format", "json"]) == EXIT_OK
    cv = json.loads(capsys.readouterr().out)["cv"]
    assert cv["state"] is None and cv["placed"] is False
    # with the goal, the point is placed and named
    assert main(["measure", "c.json", "--format", "json"]) == EXIT_OK
    cv = json.loads(capsys.readouterr().out)["cv"]
    assert cv["placed"] is True and cv["state"] in states


# --- declared values as written ------------------------------------------------------------

#: Angles whose degrees -> radians -> degrees round trip is not exact in floats.
INEXACT = [x / 10 for x in range(10, 400) if math.degrees(math.radians(x / 10)) != x / 10]


def test_declared_values_are_written_as_the_file_says(here, capsys):
    rng = np.random.default_rng(7)
    tilt, gaze = (float(x) for x in rng.choice(INEXACT[:60], 2, replace=False))
    speed = float(rng.choice([x for x in INEXACT if 10 <= x <= 30]))
    (here / "d.aou").write_text(f"behaviour d : curious\napproach\ntilt {tilt}deg "
                                f"v={speed}deg/s\ngaze horizontal {gaze}deg\npause 1.5s\n")
    assert main(["compile", "d.aou", "--no-check", "-o", "d.json"]) == EXIT_OK, \
        capsys.readouterr().err
    declared = json.loads((here / "d.json").read_text())["descriptors"]["declared"]
    assert (declared["tilt_angle"], declared["tilt_velocity"],
            declared["horizontal_gaze"]) == (tilt, speed, gaze)


# --- variants ------------------------------------------------------------------------------


def test_a_variant_changes_one_value_and_adds_no_defaults(here, capsys):
    (here / "v.aou").write_text("behaviour v : curious\n# mine\napproach a=0.5\n"
                                "pause 1500ms\ntilt 10deg\n")
    assert main(["variants", "v.aou", "--vary", "tilt_velocity=25,30", "-o", "o"]) == EXIT_OK
    mark, *lines = (here / "o" / "v-tilt_velocity-low.aou").read_text().splitlines()
    assert lines == ["behaviour v : curious", "# mine", "approach a=0.5", "pause 1500ms",
                     "tilt 10deg v=25deg/s"]
    assert main(["variants", "v.aou", "--vary", "approach_acceleration=0.3,0.6", "-o",
                 "o"]) == EXIT_OK
    _, *lines = (here / "o" / "v-approach_acceleration-high.aou").read_text().splitlines()
    assert lines[2] == "approach a=0.6" and lines[3] == "pause 1500ms"
    capsys.readouterr()


def test_varying_a_variant_keeps_the_base_name_and_one_mark(here, capsys):
    shutil.copy(BEHAVIOURS / "hesitant.aou", here / "h.aou")
    assert main(["variants", "h.aou", "--vary", "pause_duration=1,2", "-o", "o"]) == EXIT_OK
    assert main(["variants", "o/h-pause_duration-low.aou", "--vary", "retreat_count=1,2",
                 "-o", "o"]) == EXIT_OK
    assert sorted(os.listdir(here / "o")) == [
        "h-pause_duration-high.aou", "h-pause_duration-low.aou",
        "h-retreat_count-high.aou", "h-retreat_count-low.aou"]
    text = (here / "o" / "h-retreat_count-low.aou").read_text()
    assert text.count("written by `aouc variants`") == 1
    assert text.startswith("# written by `aouc variants` from h-pause_duration-low.aou")
    capsys.readouterr()


# --- figures and videos --------------------------------------------------------------------


def test_behaviours_at_one_point_share_one_label_on_the_cv_map():
    from aou_dsl.lang.linter import lint_file
    from aou_dsl.media.plot import cv_figure, point_labels

    cv = lint_file(str(BEHAVIOURS / "hesitant.aou")).cv
    other = lint_file(str(BEHAVIOURS / "confident.aou")).cv
    points = [(f"b{k}", cv) for k in range(5)] + [("c", other)]
    labels = point_labels(points)
    assert [t for t, _ in labels] == [f"b0, b1, b2 +2 more ({cv.state.value})",
                                      f"c ({other.state.value})"]
    fig = cv_figure(points)
    drawn = [t.get_text() for t in fig.axes[0].texts]
    assert sum(t.startswith("b") for t in drawn) == 1 and "b3" not in " ".join(drawn)


def test_each_half_of_a_side_by_side_video_is_captioned():
    from aou_dsl.media.annotate import caption, side_by_side

    grey = np.full((120, 160, 3), 128, np.uint8)
    one = caption(grey, "hesitant-pause_duration-low")
    assert one.shape == grey.shape
    band = one[:12]
    assert (band == 255).any() and (band < 60).any()  # a white band with dark text
    assert (one[40:] == 128).all()  # the picture below is untouched
    both = side_by_side([grey, grey], ["a", "a much longer name than fits in the half"])
    assert both.shape == (120, 320, 3)
    assert (both[:12, :160] < 60).any() and (both[:12, 160:] < 60).any()
    assert not np.array_equal(both[:12, :160], both[:12, 160:])


def test_a_video_of_two_names_each_clip_after_its_file(here):
    from aou_dsl.api import read_trajectory
    from aou_dsl.media.render import _Clip

    assert main(["compile", str(BEHAVIOURS / "inactive.aou"), "--no-check", "-o",
                 "i.json"]) == EXIT_OK
    clip = _Clip.of(read_trajectory("i.json"), 10.0)
    assert clip.title in ("inactive", "i.json")


# --- check fails with a code ---------------------------------------------------------------


def test_check_never_fails_without_a_code(here, capsys):
    """A trajectory past a joint's limit fails `check` (exit 1), and each failed check is
    a diagnostic with its code, as compile gives it; a passing one prints none."""
    n = 50
    t = [k * 0.02 for k in range(n)]
    q = [[0.0, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8] for _ in t]
    for k, row in enumerate(q):
        row[0] = 3.2 * k / (n - 1)  # past panda_joint1's 2.9 rad
    doc = {"format": "aou-trajectory/1", "robot": "panda", "joint_names": [
        f"panda_joint{k}" for k in range(1, 8)], "t": t, "q": q,
        "goal": {"position": [0.5, 0.0, 0.3]}}
    (here / "far.json").write_text(json.dumps(doc))
    assert main(["check", "far.json", "--no-dynamic"]) == EXIT_ERRORS
    out, err = capsys.readouterr()
    assert "FAIL  joint-position" in out
    assert re.search(r"far\.json:1:1: C306 \[error\] joint-position check failed", err), err
    assert main(["check", "far.json", "--no-dynamic", "--format", "json"]) == EXIT_ERRORS
    diags = json.loads(capsys.readouterr().out)["diagnostics"]
    assert diags and all(d["code"] in ("C306", "C311") for d in diags)


def test_a_profile_of_a_very_long_episode_list_is_drawn_with_what_a_figure_can_show():
    """A trajectory may list any number of episodes; the figure shades the first
    MAX_SHADED and says so, instead of drawing for minutes."""
    from aou_dsl.media.plot import MAX_SHADED, ProfileData, profile_figure

    n, joints = 200, 2
    t = np.linspace(0, 10, n)
    eps = tuple(("pause", k * 1e-4, k * 1e-4 + 5e-5) for k in range(50_000))
    d = ProfileData("many", ("a", "b"), t, np.ones(n), np.ones(n), np.zeros((n, joints)),
                    np.zeros((n, joints)), -np.ones(joints), np.ones(joints),
                    np.ones(joints), eps)
    fig = profile_figure(d)
    assert f"the first {MAX_SHADED} of 50000 episodes" in fig.axes[0].get_title()
    assert len(fig.axes[0].patches) == MAX_SHADED
