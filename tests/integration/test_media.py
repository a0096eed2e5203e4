"""Pictures and videos show what they claim: plotted data equal the trajectory's; videos
have the expected frames and duration, move while the arm moves and stay still in
pauses; variant pairs differ in one descriptor only."""

import json
import subprocess
import sys

import numpy as np
import pytest

import aou_dsl
from aou_dsl.cli.commands import EXIT_ERRORS, EXIT_OK, EXIT_USAGE, main
from aou_dsl.driver.builder import build_file
from aou_dsl.lang.linter import lint_file
from aou_dsl.robot.load import load_arm
from tests.conftest import BEHAVIOURS


@pytest.fixture(scope="module")
def confident():
    res = build_file(str(BEHAVIOURS / "confident.aou"), check=False)
    return res.compiled.trajectory


def test_profile_plot_draws_the_trajectory(confident):
    from aou_dsl.media.plot import profile_data, profile_figure

    d = profile_data(confident)
    fig = profile_figure(d)
    ax_v, ax_d, ax_q, ax_qd = fig.axes
    assert np.array_equal(ax_v.lines[0].get_xdata(), confident.t)
    assert np.array_equal(ax_v.lines[0].get_ydata(), d.speed)
    # The speed drawn is the hand's: |J(q) qd| from Pinocchio agrees with it.
    import pinocchio as pin

    arm = load_arm("panda")
    data = arm.model.createData()
    i = len(confident.t) // 3
    j = pin.computeFrameJacobian(arm.model, data, confident.q[i], arm.frame_id,
                                 pin.LOCAL_WORLD_ALIGNED)
    assert d.speed[i] == pytest.approx(np.linalg.norm(j[:3] @ confident.qd[i]), rel=1e-3)
    assert np.array_equal(ax_d.lines[0].get_ydata(), d.distance)
    assert d.distance[0] == pytest.approx(0.30) and d.distance[-1] == pytest.approx(0.10)
    # One shaded span per episode in each panel, labelled on the speed panel.
    assert len(ax_v.patches) == len(confident.episodes) == 2
    assert [t.get_text() for t in ax_v.texts] == ["approach", "pause"]
    assert len(ax_q.lines) == 7 + 2 and len(ax_qd.lines) == 7 + 2  # joints + limits


def test_cv_plot_places_each_behaviour_at_its_inferred_point():
    from aou_dsl.media.plot import cv_figure

    results = [lint_file(str(BEHAVIOURS / f"{n}.aou")) for n in ("hesitant", "fearful")]
    fig = cv_figure([(r.behaviour.name, r.cv) for r in results])
    points = fig.axes[0].collections[-1].get_offsets()
    assert np.allclose(points, [[r.cv.C, r.cv.V] for r in results])


def test_plot_command_writes_png_and_svg(tmp_path):
    png, svg = tmp_path / "h.png", tmp_path / "cv.svg"
    assert main(["plot", str(BEHAVIOURS / "inactive.aou"), "-o", str(png)]) == EXIT_OK
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["plot", "--cv", str(BEHAVIOURS), "-o", str(svg)]) == EXIT_OK
    assert b"<svg" in svg.read_bytes()[:400]


def _mp4_frames(path):
    import imageio.v2 as imageio

    reader = imageio.get_reader(str(path))
    fps = reader.get_meta_data()["fps"]
    frames = np.array([f.astype(float) for f in reader])
    reader.close()
    return fps, frames


@pytest.mark.slow
def test_video_has_the_frames_and_duration_and_moves_only_when_the_arm_does(tmp_path,
                                                                            confident):
    out = tmp_path / "c.mp4"
    assert main(["render", str(BEHAVIOURS / "confident.aou"), "-o", str(out),
                 "--size", "160x120"]) == EXIT_OK
    fps, frames = _mp4_frames(out)
    # Real time: a frame at every k/30 s of the motion, 2 sqrt(0.2 / 0.1) + 1.67 s long
    # (plus the few milliseconds the jerk limit adds to the approach).
    assert confident.duration == pytest.approx(2 * np.sqrt(0.2 / 0.1) + 1.67, abs=5e-3)
    duration = confident.duration
    assert fps == 30 and len(frames) == int(np.floor(duration * 30)) + 1
    change = np.abs(np.diff(frames, axis=0)).mean(axis=(1, 2, 3))
    t = np.arange(1, len(frames)) / fps
    approach, pause = (t > 0.5) & (t < 2.3), (t > 3.0) & (t < 4.4)
    assert change[approach].min() > 5 * change[pause].max()
    assert change[pause].max() < 0.5


@pytest.mark.slow
def test_gif_lasts_the_motion_and_side_by_side_is_two_wide(tmp_path):
    from PIL import Image, ImageSequence

    out = tmp_path / "pair.gif"
    assert main(["render", "--side-by-side", str(BEHAVIOURS / "inactive.aou"),
                 str(BEHAVIOURS / "confident.aou"), "-o", str(out),
                 "--size", "80x60"]) == EXIT_OK
    gif = Image.open(out)
    assert gif.size == (160, 60)
    total = sum(f.info["duration"] for f in ImageSequence.Iterator(gif))
    # The longer of the two (confident) at 30 fps; GIF delays are whole centiseconds that
    # add up to the video's length (identical frames are merged into one).
    confident = aou_dsl.compile(BEHAVIOURS / "confident.aou", check=False).trajectory
    frames = int(np.floor(confident.duration * 30)) + 1
    assert total == round(frames * 100 / 30) * 10


def test_a_frame_is_pybullets_own_picture_of_the_whole_scene():
    """The still things (table, target, pedestal) are drawn once and the arm laid over
    them by depth: each frame is, pixel for pixel, the image PyBullet draws of everything
    together, at the start, with the hand at its nearest to the target, and with the
    hand pushed through the table (which must hide it)."""
    from aou_dsl.core.options import SceneOptions
    from aou_dsl.media.render import Camera, _Clip, _pedestal, _stage, render_configurations
    from aou_dsl.robot.scene import Scene

    tr = build_file(str(BEHAVIOURS / "hesitant.aou"), check=False).trajectory
    clip, cam, opts = _Clip.of(tr, 30.0), Camera(width=160, height=120), SceneOptions()
    whole = Scene(tr.robot, clip.goal, opts)
    _pedestal(whole, clip.goal, opts)
    pb, st = whole.pb, _stage(tr.robot, clip.goal, opts, cam)

    def drawn_together(q):
        whole.set_arm(q)
        rgba = pb.getCameraImage(160, 120, st.view, st.proj, renderer=pb.ER_TINY_RENDERER,
                                 physicsClientId=whole.client)[2]
        return np.reshape(np.asarray(rgba, dtype=np.uint8), (120, 160, 4))[:, :, :3]

    def hand(q):
        whole.set_arm(q)
        return whole.ee_pose()[0]

    nearest = min(range(len(clip.qs)),
                  key=lambda k: np.linalg.norm(hand(clip.qs[k]) - clip.goal))
    through = np.array([0.5, 1.7, 0.0, -0.3, 0.0, 1.0, 0.8])
    assert hand(through)[2] < -0.03  # below the table
    qs = np.array([clip.qs[0], clip.qs[nearest], through])
    try:
        frames = render_configurations(tr.robot, clip.goal, opts, cam, qs)
        for frame, q in zip(frames, qs, strict=True):
            assert np.array_equal(frame, drawn_together(q))
        assert not np.array_equal(frames[0], frames[1])  # the arm is in the picture
    finally:
        whole.close()


def test_render_rejects_unknown_formats(tmp_path):
    assert main(["render", str(BEHAVIOURS / "inactive.aou"), "-o",
                 str(tmp_path / "x.avi")]) == EXIT_USAGE


def test_variants_differ_in_one_statement_and_lint_clean(tmp_path):
    src = BEHAVIOURS / "hesitant.aou"
    assert main(["variants", str(src), "--vary", "pause_duration=1.0,2.5",
                 "-o", str(tmp_path)]) == EXIT_OK
    base = src.read_text().splitlines()
    for label, value in (("low", 1.0), ("high", 2.5)):
        path = tmp_path / f"hesitant-pause_duration-{label}.aou"
        mark, *lines = path.read_text().splitlines()  # aou's mark, then the file
        assert mark.startswith("# written by `aouc variants` from hesitant.aou")
        changed = [i for i, (a, b) in enumerate(zip(base, lines, strict=True)) if a != b]
        assert len(changed) == 1 and lines[changed[0]].startswith("pause ")
        r = lint_file(str(path))
        assert r.ok
        assert r.behaviour.first("pause").duration == value
        assert r.behaviour.first("pause").count == 5


def test_variant_counts_and_angles(tmp_path):
    assert main(["variants", str(BEHAVIOURS / "curious.aou"), "--vary",
                 "horizontal_gaze=10,30", "-o", str(tmp_path)]) == EXIT_OK
    hi = lint_file(str(tmp_path / "curious-horizontal_gaze-high.aou")).behaviour
    assert hi.first("gaze", "horizontal").angle == pytest.approx(np.radians(30))


@pytest.mark.parametrize("descriptor,low,high", [
    ("retreat_count", 1, 3), ("pause_count", 4, 6), ("retreat_count", 2, 1),
    ("retreat_count", 0, 2), ("pause_duration", 1.25, 2.5),
    ("retreat_acceleration", 0.05, 0.3)])
def test_each_variant_declares_the_value_it_reports(tmp_path, capsys, descriptor, low,
                                                    high):
    """Read back, each file declares the value its name and the report give: the
    formatter leaves out a count of 1, and the low file kept the base's x3."""
    from aou_dsl.lang.declared import written

    assert main(["variants", str(BEHAVIOURS / "hesitant.aou"), "--vary",
                 f"{descriptor}={low},{high}", "-o", str(tmp_path)]) == EXIT_OK
    err = capsys.readouterr().err
    texts = []
    for label, value in (("low", low), ("high", high)):
        path = tmp_path / f"hesitant-{descriptor}-{label}.aou"
        assert f"({descriptor}={value:g})" in err
        r = lint_file(str(path))
        assert r.ok and written(r.behaviour)[descriptor] == pytest.approx(value)
        texts.append(path.read_text().split("\n", 1)[1])
    assert texts[0] != texts[1]


def test_a_variant_that_does_not_say_what_it_reports_is_refused():
    """The read-back check fails on a file whose text declares another value."""
    from aou_dsl.core.diagnostics import AouError
    from aou_dsl.lang.linter import lint_source
    from aou_dsl.media.variants import Variant, _check_says

    text = (BEHAVIOURS / "hesitant.aou").read_text()
    b = lint_source(text, "v.aou").behaviour
    with pytest.raises(AouError) as err:
        _check_says(Variant("low", 1.0, text, "v-low.aou"), b, "retreat_count", b.span)
    (d,) = err.value.diagnostics
    assert d.code == "I504" and "retreat_count=3" in d.message and "not the 1" in d.message
    _check_says(Variant("high", 3.0, text, "v-high.aou"), b, "retreat_count", b.span)
    with pytest.raises(AouError):
        _check_says(Variant("low", 1.6, text, "v-low.aou"), b, "pause_duration", b.span)


def test_variants_that_would_be_one_file_are_refused(tmp_path):
    assert main(["variants", str(BEHAVIOURS / "hesitant.aou"), "--vary",
                 "pause_duration=1.0000001,1.0000002", "-o", str(tmp_path)]) == EXIT_USAGE
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("vary,code", [
    ("shiver_amplitude=2,8", EXIT_USAGE),     # hesitant has no shiver to vary
    ("no_such=1,2", EXIT_USAGE),
    ("retreat_count=1.5,3", EXIT_USAGE),       # a count is a whole number
    ("retreat_count=1,9", EXIT_ERRORS),        # 9 retreats need 10 pauses: not written
    ("pause_duration", EXIT_USAGE),
])
def test_variant_errors(tmp_path, vary, code):
    assert main(["variants", str(BEHAVIOURS / "hesitant.aou"), "--vary", vary,
                 "-o", str(tmp_path)]) == code
    assert list(tmp_path.iterdir()) == []


def test_compile_and_measure_never_import_matplotlib_or_video_libraries(tmp_path):
    src, out = BEHAVIOURS / "confident.aou", tmp_path / "c.json"
    code = ("import sys\nfrom aou_dsl.cli.commands import main\n"
            f"main(['compile', r'{src}', '-o', r'{out}'])\n"
            f"main(['measure', r'{out}'])\n"
            "print(sorted({'matplotlib', 'imageio', 'PIL'} & set(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"
    assert json.loads((tmp_path / "c.json").read_text())["format"] == "aou-trajectory/1"
