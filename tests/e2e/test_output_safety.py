"""Never lose a file: the cases where a user's file was replaced, each as it was met, and
what a killed or interrupted process leaves behind (nothing).

tests/generated/test_fuzz_outputs.py generates the output rule's cases; these are the ones a user
met, spelled as they were, plus what the generator cannot see: a run that succeeds
beside the user's files, a process killed while it writes, and the temporary folders of
the checks.
"""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from aou_dsl.cli.args import EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE
from aou_dsl.cli.commands import main
from tests.conftest import BEHAVIOURS, ROOT
from tests.generated.test_fuzz_outputs import _workspace

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="makes FIFOs and devices, reads /proc")

#: Seconds before a subprocess that should have ended counts as hung.
HUNG = 120


def _hashes(root: Path) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file() and not p.is_symlink()}


@pytest.fixture
def ws(tmp_path, monkeypatch):
    root = tmp_path / "ws"
    root.mkdir()
    _workspace(root)
    monkeypatch.chdir(root)
    return root


@pytest.mark.parametrize("argv", [
    ["compile", "a.aou", "--robot", "arm/arm.toml", "--format", "json", "-o", "arm/arm.toml"],
    ["compile", "a.aou", "--robot", "arm/arm.toml", "--format", "json", "-o", "arm/arm.urdf"],
    ["compile", "a.aou", "--robot", "arm/arm.toml", "--format", "json", "-o",
     "arm/meshes/base.stl"],
    ["compile", "y.aou", "--format", "json", "-o", "arm/arm.toml"],  # its `robot` line
    ["robot", "arm/arm.toml", "--format", "toml", "-o", "arm/arm.urdf"],
    ["plot", "t.png", "-o", "t.png"],
    ["render", "t.gif", "-o", "t.gif"],
])
def test_the_files_users_lost_are_refused(ws, argv, capsys):
    for name in ("t.png", "t.gif"):
        (ws / name).write_bytes(b"the user's picture")
    before = _hashes(ws)
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err
    assert " I502 [error]" in err and "refusing" in err, err
    assert _hashes(ws) == before


def test_synth_into_a_link_to_its_robot_file_is_refused(ws, capsys):
    os.symlink("arm/arm.toml", "s.aou")
    before = _hashes(ws)
    assert main(["synth", "--state", "confident", "--robot", "arm/arm.toml", "--no-verify",
                 "-o", "s.aou", "--force"]) == EXIT_USAGE
    assert "arm/arm.toml" in capsys.readouterr().err and _hashes(ws) == before


@pytest.mark.parametrize("argv", [["plot", "t.json", "-o", "out.png"],
                                  ["plot", "--cv", "y.aou", "-o", "out.png"]])
def test_a_link_named_like_an_output_to_an_input_is_refused(ws, argv, capsys):
    os.symlink(argv[-3], "out.png")
    before = _hashes(ws)
    assert main(argv) == EXIT_USAGE
    assert f"links to `{argv[-3]}`" in capsys.readouterr().err and _hashes(ws) == before


def test_special_files_stay_what_they_are(ws, capsys):
    os.mkfifo("fifo.json")
    try:
        os.mknod("null", 0o666 | 0o020000, os.makedev(1, 3))
    except PermissionError:
        pytest.skip("making a device needs root")
    for out in ("fifo.json", "./null"):
        assert main(["compile", "a.aou", "--format", "json", "-o", out]) == EXIT_USAGE
        assert "not a regular file" in capsys.readouterr().err
    assert Path("fifo.json").is_fifo() and Path("null").is_char_device()


def test_synth_variants_and_robot_keep_a_hand_written_file_unless_forced(ws, capsys):
    mine = "# my own\nbehaviour keep : curious\npause 2s\napproach\n"
    Path("keep.aou").write_text(mine)
    assert main(["synth", "--state", "curious", "--no-verify", "-o", "keep.aou"]) == EXIT_USAGE
    assert " I506 " in capsys.readouterr().err and Path("keep.aou").read_text() == mine
    assert main(["synth", "--state", "curious", "--no-verify", "-o", "keep.aou",
                 "--force"]) == EXIT_OK
    assert Path("keep.aou").read_text() != mine
    # ...and what synth wrote, it may write again without --force
    assert main(["synth", "--state", "hesitant", "--no-verify", "-o", "keep.aou"]) == EXIT_OK
    assert "hesitant" in Path("keep.aou").read_text().splitlines()[0]
    Path("arm.json").write_text('{"mine": true}\n')
    assert main(["robot", "panda", "--format", "json", "-o", "arm.json"]) == EXIT_USAGE
    assert main(["robot", "panda", "--format", "json", "-o", "arm.json", "--force"]) == EXIT_OK
    assert main(["robot", "panda", "--format", "json", "-o", "arm.json"]) == EXIT_OK
    capsys.readouterr()


def test_a_bag_beside_other_files_and_into_a_missing_folder(ws, capsys):
    """`--format mcap -o bags/` makes the folder, as every format does; `-o proj/` with
    the user's files in it adds the bag beside them and changes none."""
    Path("proj").mkdir()
    Path("proj/notes.txt").write_text("mine")
    before = _hashes(ws)
    for out in ("bags/", "proj/"):
        assert main(["compile", str(BEHAVIOURS / "inactive.aou"), "--no-check", "--format",
                     "mcap", "-o", out]) == EXIT_OK, capsys.readouterr().err
        assert sorted(os.listdir(Path(out) / "inactive")) == ["inactive.mcap",
                                                              "metadata.yaml"]
    after = _hashes(ws)
    assert {k: v for k, v in after.items() if "/inactive/" not in k} == before
    # ...and the bag aou wrote may be written again; with a file of the user's, not
    Path("proj/inactive/mine.txt").write_text("mine")
    assert main(["compile", str(BEHAVIOURS / "inactive.aou"), "--no-check", "--format",
                 "mcap", "-o", "proj/"]) == EXIT_USAGE
    assert Path("proj/inactive/mine.txt").read_text() == "mine"
    capsys.readouterr()


# --- killed and interrupted ---------------------------------------------------------------

#: Runs ``aouc ARGV`` with one step of the write held (``link``: naming the written
#: file; ``replace``: renaming it over the output), told by a marker file, so that the
#: test kills it there, mid-write, every time. ``named`` makes it write as on a file
#: system without unnamed files (a named temporary file).
HOLD = textwrap.dedent("""
    import os, sys, time
    from pathlib import Path
    import aou_dsl.core.files as files
    marker, where, named, argv = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
    def hold(real):
        def held(*a, **k):
            Path(marker).write_text(str(os.getpid()))
            time.sleep(600)
            return real(*a, **k)
        return held
    if where == "link":
        files._link = hold(files._link)
    else:
        class Os:
            def __getattr__(self, name):
                return getattr(os, name)
        files.os = Os()
        files.os.replace = hold(os.replace)
    if named == "named":
        files._write_unnamed = lambda *a: False
    from aou_dsl.cli.commands import main
    raise SystemExit(main(argv))
""")


def _held(tmp_path: Path, where: str, argv: list[str], tmp: Path, named: bool = False
          ) -> subprocess.Popen:
    marker = tmp_path / "marker"
    proc = subprocess.Popen([sys.executable, "-c", HOLD, str(marker), where,
                             "named" if named else "unnamed", *argv], cwd=tmp_path,
                            env=_env(tmp), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    deadline = time.monotonic() + HUNG
    while not marker.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "never reached the write"
        time.sleep(0.05)
    return proc


def _env(tmp: Path) -> dict:
    return {**os.environ, "TMPDIR": str(tmp), "PYTHONPATH": str(ROOT)}


def test_a_compile_killed_mid_write_leaves_no_partial_file(tmp_path):
    """Killed with the whole file written but not yet named: it has no name, so nothing
    is left."""
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    out = tmp_path / "out"
    proc = _held(tmp_path, "link", ["compile", str(BEHAVIOURS / "inactive.aou"),
                                    "--no-check", "-o", f"{out}/"], tmp)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=HUNG)
    assert os.listdir(out) == []


def test_a_temporary_file_a_killed_write_left_is_removed_by_the_next(tmp_path):
    """Where a file is written under a temporary name (a video; any file where the file
    system has no unnamed files), a process killed before the rename leaves it: the
    next write into that folder removes it (its process is gone)."""
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    out = tmp_path / "out"
    proc = _held(tmp_path, "replace", ["compile", str(BEHAVIOURS / "inactive.aou"),
                                       "--no-check", "-o", f"{out}/"], tmp, named=True)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=HUNG)
    (left,) = os.listdir(out)
    assert left.startswith(f".aouc-{proc.pid}-")
    assert main(["compile", str(BEHAVIOURS / "inactive.aou"), "--no-check", "-o",
                 f"{out}/"]) == EXIT_OK
    assert os.listdir(out) == ["inactive.json"]


@pytest.mark.slow
def test_the_checks_temporary_folder_of_a_killed_process_is_removed(tmp_path):
    """The copy of the robot PyBullet loads lives in ``aou-robots-PID-*`` in $TMPDIR,
    removed at exit; a killed process cannot, so the next one that needs one does."""
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    traj = tmp_path / "t.json"
    assert main(["compile", str(BEHAVIOURS / "inactive.aou"), "--no-check", "-o",
                 str(traj)]) == EXIT_OK
    proc = subprocess.Popen([sys.executable, "-m", "aou_dsl", "check", str(traj),
                             "--no-dynamic"], env=_env(tmp), stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.monotonic() + HUNG
    while not any(n.startswith("aou-robots-") for n in os.listdir(tmp)):
        assert proc.poll() is None and time.monotonic() < deadline
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=HUNG)
    assert [n for n in os.listdir(tmp) if n.startswith("aou-robots-")]  # left by the kill
    done = subprocess.run([sys.executable, "-m", "aou_dsl", "check", str(traj),
                           "--no-dynamic"], env=_env(tmp), capture_output=True, text=True,
                          timeout=HUNG)
    assert done.returncode == EXIT_OK, done.stderr
    assert os.listdir(tmp) == []


def test_ctrl_c_exits_130_and_leaves_nothing(tmp_path):
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    out = tmp_path / "out"
    proc = _held(tmp_path, "link", ["compile", str(BEHAVIOURS / "inactive.aou"),
                                    "--no-check", "-o", f"{out}/"], tmp)
    os.kill(proc.pid, signal.SIGINT)  # time.sleep is interrupted: KeyboardInterrupt
    _, err = proc.communicate(timeout=HUNG)
    assert proc.returncode == EXIT_INTERRUPTED, err
    assert "aouc: interrupted" in err.decode() and "Traceback" not in err.decode()
    assert not out.exists() or os.listdir(out) == []
    assert os.listdir(tmp) == []


def test_plot_leaves_no_temporary_file_and_repeats_its_bytes(tmp_path, monkeypatch):
    """A figure is drawn in memory and written whole: nothing but it appears in its
    folder, and the same figure gives the same bytes in every format."""
    monkeypatch.chdir(tmp_path)
    _workspace(tmp_path)
    before = set(os.listdir(tmp_path))
    for ext in ("png", "svg", "pdf"):
        assert main(["plot", "t.json", "-o", f"one.{ext}"]) == EXIT_OK
        assert main(["plot", "t.json", "-o", f"two.{ext}"]) == EXIT_OK
        assert Path(f"one.{ext}").read_bytes() == Path(f"two.{ext}").read_bytes(), ext
    assert set(os.listdir(tmp_path)) - before == {f"{n}.{e}" for n in ("one", "two")
                                                  for e in ("png", "svg", "pdf")}


# --- what a command reads ------------------------------------------------------------------


def test_the_files_a_command_reads_follow_the_chain_and_never_block(ws):
    """aou file -> its robot file (and --robot's) -> the URDF it names -> every mesh,
    package:// ones too; a FIFO or a missing file on the way is listed, not opened."""
    from aou_dsl.robot.files_read import files_read
    from tests.generated.test_fuzz_outputs import _deadline

    got = [os.path.relpath(p) for p in files_read(["y.aou"])]
    assert got[:3] == ["y.aou", "arm/arm.toml", "arm/arm.urdf"]
    assert sorted(got[3:]) == ["arm/armpkg/meshes/l2.stl", "arm/meshes/base.stl",
                               "arm/meshes/l1.stl"]
    os.mkfifo("arm/fifo.toml")
    Path("f.aou").write_text('robot "arm/fifo.toml"\napproach\n')
    with _deadline(20):
        got = [os.path.relpath(p) for p in files_read(["f.aou", "gone.aou"],
                                                      robot="arm/arm.urdf")]
    assert got[:3] == ["f.aou", "gone.aou", "arm/arm.urdf"]
    assert "arm/fifo.toml" in got and "arm/meshes/l1.stl" in got


# --- every robot line the grammar accepts; --write-fitted ---------------------------------

#: A behaviour naming its robot file in the forms the grammar accepts besides one
#: statement a line at the left margin.
ROBOT_FORMS = {
    "one line of statements": 'behaviour h : hesitant; robot "arm.toml"; pause 1s; approach\n',
    "a form feed before it": 'behaviour h : hesitant\n\frobot "arm.toml"\npause 1s\napproach\n',
    "a tab, CRLF line ends": 'behaviour h : hesitant\r\n\trobot "arm.toml"\r\npause 1s\r\n'
                             'approach\r\n',
    "no blanks around it": 'behaviour h : hesitant;robot"arm.toml";pause 1s;approach\n',
    "after a comment line": 'behaviour h : hesitant # robot panda\n  robot   "arm.toml"  \n'
                            'pause 1s\napproach\n',
}


@pytest.mark.parametrize("form", list(ROBOT_FORMS))
def test_the_robot_file_of_every_form_of_robot_line_is_an_input(form, tmp_path,
                                                                monkeypatch, capsys):
    """The robot file is the parsed file's: the one-line form and a form feed before
    the line hid it from a scan of the text, and -o wrote the trajectory over it."""
    monkeypatch.chdir(tmp_path)
    Path("arm.toml").write_text('robot = "panda"\n')  # a description that compiles
    Path("b.aou").write_text(ROBOT_FORMS[form])
    from aou_dsl.lang.linter import lint_file

    lint = lint_file("b.aou")
    assert lint.behaviour is not None and lint.behaviour.settings.robot.endswith("arm.toml")
    before = _hashes(tmp_path)
    assert main(["compile", "b.aou", "--format", "json", "--no-check", "-o",
                 "arm.toml"]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert " I502 [error]" in err and "arm.toml" in err, err
    assert _hashes(tmp_path) == before


@pytest.fixture
def fit_ws(tmp_path, monkeypatch):
    """A behaviour that needs fitting, naming a description of a built-in arm whose URDF
    is a file of the folder, with a mesh; and a trajectory compiled from it."""
    monkeypatch.chdir(tmp_path)
    _workspace(tmp_path)
    # a wrist that follows fearful's shiver, made 4 Hz, at 2.8 Hz (still a tremor)
    Path("arm.toml").write_text('robot = "ur5"\njoint_accel = [5, 5, 5, 5, 5, 18]\n')
    Path("b.aou").write_text((BEHAVIOURS / "fearful.aou").read_text().replace(
        "behaviour fearful : fearful", 'behaviour fearful : fearful\nrobot "arm.toml"')
        .replace("shiver 6deg for 1.25s", "shiver 6deg f=4Hz for 0.8s"))
    return tmp_path


@pytest.mark.parametrize("argv", [
    ["compile", "b.aou", "--fit", "--no-check", "--write-fitted", "arm.toml", "-o",
     "out.json"],
    ["compile", "b.aou", "--fit", "--no-check", "--write-fitted", "out.json", "-o",
     "out.json"],
    ["compile", "b.aou", "--fit", "--no-check", "--write-fitted", "./out.json", "-o",
     "out.json"],
    ["compile", "b.aou", "--fit", "--no-check", "--write-fitted", "b.aou", "-o", "o.json"],
    ["compile", "a.aou", "--robot", "arm/arm.toml", "--fit", "--no-check",
     "--write-fitted", "arm/arm.urdf", "-o", "o.json"],
    ["compile", "a.aou", "--robot", "arm/arm.toml", "--fit", "--no-check",
     "--write-fitted", "arm/meshes/l1.stl", "-o", "o.json"],
    ["compile", "a.aou", "--robot", "arm/arm.toml", "--fit", "--no-check",
     "--write-fitted", "arm/armpkg/meshes/l2.stl", "-o", "o.json"],
    ["check", "b.aou", "--fit", "--no-dynamic", "--write-fitted", "arm.toml"],
    ["check", "b.aou", "--fit", "--no-dynamic", "--write-fitted", "link.aou"],
])
def test_write_fitted_obeys_the_output_rule_before_any_work(fit_ws, argv, capsys,
                                                            monkeypatch):
    """--write-fitted onto an input, a link to one or the -o output: I502 before the
    build starts, every file as it was."""
    os.symlink("b.aou", "link.aou")
    Path("out.json").write_text('{"generator": "aouc 0.2.0"}\n')  # an earlier output
    import aou_dsl.driver.builder as builder

    def no_build(*a, **k):
        raise AssertionError("built before the output rule was checked")

    monkeypatch.setattr(builder, "build_file", no_build)
    before = _hashes(fit_ws)
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err
    assert " I502 [error]" in err and "Traceback" not in err, err
    assert _hashes(fit_ws) == before


def test_write_fitted_beside_its_inputs_still_writes(fit_ws, capsys):
    """The rule refuses only what it must: a new path is written, the -o output too."""
    assert main(["compile", "b.aou", "--fit", "--no-check", "--write-fitted",
                 "fitted.aou", "-o", "out.json"]) == EXIT_OK, capsys.readouterr().err
    assert "f=" in Path("fitted.aou").read_text() and Path("out.json").exists()
