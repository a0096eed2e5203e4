"""--track where the arm's limits refuse the file: the motion as declared, planned with
those limits lifted, tracked through each servo mode as a labelled what-if; the file
still fails. A file the arm accepts is tracked as before, with no such label."""

import re
import subprocess
import sys

import pytest

pytest.importorskip("mujoco")

from aou_dsl.cli.commands import EXIT_OK, main  # noqa: E402
from aou_dsl.cli.track_whatif import WHAT_IF  # noqa: E402
from tests.conftest import BEHAVIOURS  # noqa: E402

FEARFUL = str(BEHAVIOURS / "fearful.aou")
SHIVER = "shiver_amplitude"


def _at_risk(out: str) -> tuple[list[str], dict[str, tuple[list[float], str]]]:
    """The at-risk table of a text report: its modes, and each descriptor's share per
    mode [0..] with the words of its last column."""
    lines = out[out.index("what the arm shows of each descriptor at risk"):].splitlines()
    head = next(ln for ln in lines if ln.strip().startswith("descriptor"))
    modes = head.split()[2:-2]  # descriptor declared MODES... kept by
    rows = {}
    for ln in lines[lines.index(head) + 1:]:
        cells = re.findall(r"(\d+)%\*?", ln)
        if len(cells) != len(modes):
            break
        rows[ln.split()[0]] = ([int(c) / 100 for c in cells],
                               ln[ln.rindex("%") + 2:].strip())
    return modes, rows


@pytest.fixture(scope="module")
def fearful_on_kinova():
    """``aouc check fearful.aou --robot kinova --track`` as a user runs it: exit,
    stdout, stderr."""
    done = subprocess.run([sys.executable, "-m", "aou_dsl", "check", FEARFUL, "--robot",
                           "kinova", "--track"], capture_output=True, text=True,
                          timeout=240, check=False)
    return done.returncode, done.stdout, done.stderr


def test_a_shiver_the_arm_refuses_is_tracked_as_a_labelled_what_if(fearful_on_kinova):
    """Each mode's share of the declared shiver, the modes that keep it, under words
    saying it is a what-if; the refusal is still printed and the file still fails."""
    code, out, err = fearful_on_kinova
    assert code == 1
    assert out.startswith(f"{WHAT_IF}: the arm's limits refuse this motion")
    assert "C308" in out.splitlines()[0] and "The file still fails" in out.splitlines()[0]
    modes, rows = _at_risk(out)
    assert {"position", "feedforward"} <= set(modes)
    shares, kept = rows[SHIVER]
    assert len(shares) == len(modes) and all(s > 0 for s in shares)
    keepers = [m for m, s in zip(modes, shares, strict=True) if abs(s - 1) <= 0.5 / 6]
    assert keepers and kept == ", ".join(keepers)  # +-0.5 deg of the declared 6 deg
    assert " C308 [error]" in err and "nothing to track" not in err
    assert "what-if" in next(ln for ln in err.splitlines() if ln.startswith("aouc check"))


def test_the_what_if_shiver_is_smaller_under_plain_set_points(fearful_on_kinova):
    """Plain position set-points lag and shrink a 2.5 Hz tremor; feed-forward follows it."""
    _, out, _ = fearful_on_kinova
    modes, rows = _at_risk(out)
    shares = dict(zip(modes, rows[SHIVER][0], strict=True))
    assert shares["position"] < 0.8 * shares["feedforward"]


def test_the_what_if_plans_the_declared_motion_and_leaves_the_arms_plan_alone():
    """The lifted plan gives the declared shiver and retreat (measured independently);
    the arm's own plan, compiled after it, is still refused (no cache gives one for the
    other); tracked, the shiver is smaller under set-points than with feed-forward."""
    from aou_dsl.driver.builder import build_file
    from aou_dsl.driver.what_if import declared_motion
    from aou_dsl.measuring.measured import measure
    from aou_dsl.safety.track import track

    tr = declared_motion(FEARFUL, "kinova")
    assert tr is not None
    m = measure(tr).descriptors
    assert m[SHIVER] == pytest.approx(6.0, abs=0.05)
    assert m["retreat_acceleration"] == pytest.approx(2.0, abs=0.05)
    res = build_file(FEARFUL, robot="kinova", check=False)
    assert not res.ok and any(d.code == "C308" for d in res.diagnostics)
    position = measure(track(tr, "position").trajectory).descriptors[SHIVER]
    feedforward = measure(track(tr, "feedforward").trajectory).descriptors[SHIVER]
    assert position < 0.8 * feedforward


def test_a_file_the_arm_accepts_is_tracked_with_no_what_if(capsys):
    """Fearful on the Panda compiles: its plan is tracked, with no what-if words."""
    assert main(["check", FEARFUL, "--robot", "panda", "--no-dynamic", "--track"]) \
        == EXIT_OK
    captured = capsys.readouterr()
    assert WHAT_IF not in captured.out.lower() and "what-if" not in captured.err
    assert "tracked through the servos of panda" in captured.out
    modes, rows = _at_risk(captured.out)
    assert SHIVER in rows and "position" in modes


def test_a_refusal_lifting_the_limits_does_not_answer_is_not_tracked(tmp_path, capsys):
    """A goal out of reach is refused whatever the joints' speed: no what-if, and the
    user is told there is nothing to track."""
    far = tmp_path / "far.aou"
    far.write_text("goal (2.0, 0, 0.3)\napproach\npause 1s\n")
    assert main(["check", str(far), "--robot", "panda", "--track"]) == 1
    captured = capsys.readouterr()
    assert " C301 " in captured.err and "nothing to track" in captured.err
    assert WHAT_IF not in captured.out
