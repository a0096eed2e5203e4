"""What a newcomer sees on the command line: output folders made on the way, usage errors
said as usage errors, messages in plain English, counts that agree, and warnings that
point where the robot was named."""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from aou_dsl.cli.commands import EXIT_ERRORS, EXIT_OK, EXIT_USAGE, main
from aou_dsl.core.diagnostics import AouError
from aou_dsl.core.files import atomic, check_output, write_atomic
from tests.conftest import BEHAVIOURS

ROOT = Path(__file__).resolve().parents[2]
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


# --- Output folders -----------------------------------------------------------------------

def test_plot_makes_the_missing_folders_of_its_output(tmp_path, capsys):
    out = tmp_path / "nodir3" / "deeper" / "p.png"
    assert main(["plot", "--cv", str(BEHAVIOURS), "-o", str(out)]) == EXIT_OK
    assert out.read_bytes()[:8] == PNG_MAGIC
    assert f"wrote {out}" in capsys.readouterr().err


def test_synth_makes_the_missing_folders_of_its_output(tmp_path):
    out = tmp_path / "nodir4" / "s.aou"
    assert main(["synth", "--state", "hesitant", "--no-verify", "-o", str(out)]) == EXIT_OK
    assert main(["lint", str(out)]) == EXIT_OK  # a whole behaviour file


def test_a_failed_write_leaves_no_file_and_no_new_folder(tmp_path):
    out = tmp_path / "new" / "sub" / "x.json"
    with pytest.raises(RuntimeError), atomic(str(out)) as tmp:
        Path(tmp).write_text("half")
        raise RuntimeError("the work failed")
    assert list(tmp_path.iterdir()) == []


def test_a_folder_that_cannot_be_made_is_refused_before_the_work(tmp_path):
    (tmp_path / "afile").write_text("x")
    with pytest.raises(AouError) as err:
        check_output(str(tmp_path / "afile" / "sub" / "p.png"), ("png",))
    (d,) = err.value.diagnostics
    assert d.code == "I502" and "afile" in d.message
    assert (tmp_path / "afile").read_text() == "x"


def test_an_input_is_never_written_over_even_through_a_new_path(tmp_path):
    src = tmp_path / "a.aou"
    src.write_text("pause 1s\n")
    with pytest.raises(AouError) as err:
        write_atomic(str(tmp_path / "made" / ".." / "a.aou"), b"x", inputs=[str(src)])
    assert err.value.diagnostics[0].code == "I502"
    assert src.read_text() == "pause 1s\n" and not (tmp_path / "made").exists()


# --- Usage errors -------------------------------------------------------------------------

@pytest.mark.parametrize("argv", [
    ["synth", "--C", "0.3"],
    ["synth", "--state", "curious", "--V", "0.3"],
])
def test_synth_option_misuse_is_a_usage_error_not_a_read_error(argv, capsys):
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err
    assert "aouc: error:" in err and "--V" in err
    assert "I501" not in err and "cannot-read" not in err
    assert "usage: aouc synth" in err  # as for every other misused option


# --- Wording ------------------------------------------------------------------------------

def test_lint_counts_one_error_in_the_singular(tmp_path, capsys):
    f = tmp_path / "one.aou"
    f.write_text("behaviour one : hesitant\npause 3m\n")  # a length where a duration goes
    assert main(["lint", str(f)]) == EXIT_ERRORS
    summary = capsys.readouterr().err.strip().splitlines()[-1]
    assert summary.startswith("1 file checked: 1 error, 0 warnings, 0 notes"), summary


def _beyond_joint4(path: Path) -> Path:
    """A Panda trajectory whose fourth joint rises past its top (about -0.07 rad)."""
    t = np.linspace(0.0, 1.0, 51)
    q = np.tile([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8], (51, 1))
    q[:, 3] = np.linspace(-2.2, 0.3, 51)
    path.write_text(json.dumps({
        "format": "aou-trajectory/1", "robot": "panda",
        "joint_names": [f"panda_joint{i}" for i in range(1, 8)],
        "goal": {"position": [0.55, 0.0, 0.25]}, "t": t.tolist(), "q": q.tolist()}))
    return path


def test_a_failed_check_does_not_say_it_was_within_its_limits(tmp_path, capsys):
    path = _beyond_joint4(tmp_path / "beyond.json")
    assert main(["check", str(path), "--no-dynamic", "--angle-unit", "rad"]) == EXIT_ERRORS
    out = capsys.readouterr().out
    failed = [ln for ln in out.splitlines() if ln.strip().startswith("FAIL")]
    assert any("joint-position" in ln and "panda_joint4" in ln for ln in failed), out
    for line in failed:
        assert "within" not in line, line


# --- Output formats -----------------------------------------------------------------------

def test_an_extension_naming_another_format_is_refused(tmp_path, capsys):
    out = tmp_path / "x.json"
    argv = ["compile", str(BEHAVIOURS / "inactive.aou"), "--no-check", "--format", "csv"]
    assert main([*argv, "-o", str(out)]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert "I502" in err and "x.json" in err and "x.csv" in err
    assert not out.exists()
    # An extension aou does not know is written as --format says.
    other = tmp_path / "x.txt"
    assert main([*argv, "-o", str(other)]) == EXIT_OK
    assert [ln for ln in other.read_text().splitlines()
            if not ln.startswith("#")][0].startswith("t,panda_joint1,")


# --- Where the robot came from ------------------------------------------------------------

def _c313(err: str) -> list[str]:
    return [ln for ln in err.splitlines() if " C313 " in ln]


def test_a_robot_given_on_the_command_line_is_pointed_at_there(tmp_path, capsys):
    out = tmp_path / "hes-ur5.json"
    assert main(["compile", str(BEHAVIOURS / "hesitant.aou"), "--robot", "ur5", "--no-check",
                 "-o", str(out)]) == EXIT_OK
    err = capsys.readouterr().err
    (line,) = _c313(err)
    assert line.startswith("<command line>:"), line
    assert "robot panda" not in err  # the file's own robot line is not where ur5 came from
    # Checked later, the robot is the one the trajectory file names.
    assert main(["check", str(out), "--no-dynamic"]) == EXIT_OK
    err = capsys.readouterr().err
    (line,) = _c313(err)
    assert line.startswith(f"{out}:"), line
    assert "site-packages" not in err and ".urdf" not in line
    assert main(["check", str(out), "--no-dynamic", "--robot", "ur5"]) == EXIT_OK
    (line,) = _c313(capsys.readouterr().err)
    assert line.startswith("<command line>:"), line


def test_a_built_in_robot_is_named_not_its_installed_urdf():
    from aou_dsl.robot import robot_diagnostics

    (d,) = robot_diagnostics("ur5")
    assert d.code == "C313" and d.span.path == "<robot ur5>"


# --- Rendering ----------------------------------------------------------------------------

@pytest.mark.slow
def test_render_progress_and_summary_count_the_same_things(tmp_path):
    out = tmp_path / "nodir" / "c.gif"
    proc = subprocess.run([sys.executable, "-m", "aou_dsl", "render",
                           str(BEHAVIOURS / "confident.aou"), "-o", str(out), "--fps", "5",
                           "--size", "64x48"], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    last = proc.stderr.strip().splitlines()[-1]
    m = re.search(r"(\d+) frames at 5 fps .* (\d+) images? drawn", last)
    assert m, last
    frames, drawn = int(m.group(1)), int(m.group(2))
    import aou_dsl

    motion = aou_dsl.compile(BEHAVIOURS / "confident.aou", check=False).trajectory
    assert frames == int(np.floor(motion.duration * 5)) + 1  # a frame every 1/5 s, t=0 too
    assert 1 <= drawn < frames  # the arm holds still at the end: frames repeat an image
    progress = re.findall(r"\((\d+)/(\d+) images\)", proc.stderr)
    assert progress and progress[-1] == (str(drawn), str(drawn))
    from PIL import Image

    with Image.open(out) as gif:  # Pillow merges repeated frames: at most `frames` remain
        assert 1 <= gif.n_frames <= frames


# --- Examples -----------------------------------------------------------------------------

@pytest.mark.slow
def test_plot_profile_says_once_what_it_wrote(tmp_path):
    proc = subprocess.run([sys.executable, str(ROOT / "examples" / "plot_profile.py"),
                           str(tmp_path)], cwd=ROOT, capture_output=True, text=True,
                          timeout=300, check=True)
    said = (proc.stdout + proc.stderr).count(f"wrote {tmp_path / 'cv-map.png'}")
    assert said == 1, proc.stdout + proc.stderr


def test_a_csv_aou_writes_measures_without_naming_robot_or_goal(tmp_path):
    """What measure_csv.py's docstring says: aou's own CSVs carry the robot and the goal
    in comment lines; a log without them needs both named."""
    import aou_dsl

    doc = ast.get_docstring(ast.parse((ROOT / "examples" / "measure_csv.py").read_text()))
    assert doc is not None and "comment" in doc and "--robot" in doc
    csv = tmp_path / "inactive.csv"
    assert main(["compile", str(BEHAVIOURS / "inactive.aou"), "--no-check", "-o",
                 str(csv)]) == EXIT_OK
    tr = aou_dsl.read_trajectory(csv)
    assert tr.robot == "panda" and tr.goal is not None
    bare = tmp_path / "log.csv"
    bare.write_text("\n".join(ln for ln in csv.read_text().splitlines()
                              if not ln.startswith("#")) + "\n")
    with pytest.raises(AouError):
        aou_dsl.read_trajectory(bare)
    assert aou_dsl.read_trajectory(bare, robot="panda", goal=tuple(tr.goal)).robot == "panda"
