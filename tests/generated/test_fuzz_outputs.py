"""Output paths against everything a command reads: generated from the output rule.

The promises (README, "Commands"; docs/compiler.md, docs/media.md): every command that
writes refuses an output that is, or links to (symbolic or hard link, through any
spelling of the path), a file it reads (the ``.aou`` file, the robot file it names or
``--robot`` gives, that file's URDF, the URDF's meshes, the trajectory); refuses a
device, a FIFO or a socket; writes a bag only into a new or empty folder or over a bag
aou wrote. A refusal is exit 2 with an I code, before any work: no input changes, no
file appears (no temporary file either, in the folder or in $TMPDIR), nothing hangs, no
traceback.

The scenarios are built here from those promises: a workspace with a user's arm (a
URDF with meshes beside it, a robot description naming it), behaviours naming it, a
trajectory; every writing command; every file it reads; every way to point an output
at one. The default run covers each (command, input, way) once; the slow run adds
random chains of links and spellings from a seeded generator.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import random
import signal
import socket
import stat
import tempfile
from pathlib import Path

import pytest

from aou_dsl.cli.commands import main

#: Seconds one refused command may take before it counts as a hang.
HANG = 60

ARM_URDF = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><collision><geometry><mesh filename="meshes/base.stl"/></geometry>
    </collision></link>
  <link name="l1"><collision><geometry><mesh filename="meshes/l1.stl"/></geometry>
    </collision></link>
  <link name="l2"><collision><geometry><mesh filename="package://armpkg/meshes/l2.stl"/>
    </geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="2" effort="50"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" velocity="2" effort="50"/></joint>
</robot>
"""


def _workspace(root: Path) -> dict[str, str]:
    """A user's folder: an arm (URDF, meshes, a package mesh, a description), behaviours
    naming it, a trajectory and a recording. Returns the role of each input by path."""
    (root / "arm" / "meshes").mkdir(parents=True)
    (root / "arm" / "armpkg" / "meshes").mkdir(parents=True)
    (root / "arm" / "arm.urdf").write_text(ARM_URDF)
    (root / "arm" / "meshes" / "base.stl").write_bytes(b"solid base\nendsolid base\n")
    (root / "arm" / "meshes" / "l1.stl").write_bytes(b"solid l1\nendsolid l1\n")
    (root / "arm" / "armpkg" / "meshes" / "l2.stl").write_bytes(b"solid l2\nendsolid\n")
    (root / "arm" / "arm.toml").write_text('urdf = "arm.urdf"\narm_joints = ["j1", "j2"]\n')
    (root / "y.aou").write_text('behaviour y : confident\nrobot "arm/arm.toml"\napproach\n')
    (root / "a.aou").write_text("behaviour a : hesitant\npause 1s\napproach\n")
    n = 20
    t = [i * 0.05 for i in range(n)]
    q = [[0.0, -0.3, 0.0, -2.0, 0.0, 1.8, 0.8] for _ in t]
    # the robot line in the other forms the grammar accepts
    (root / "z.aou").write_text('behaviour z : confident; robot "arm/arm.toml"; approach\n')
    (root / "f.aou").write_text('behaviour f : confident\n\frobot "arm/arm.toml"\n'
                                'approach\n')
    # a URDF whose package mesh is found only through --package-dir
    (root / "arm" / "pkgs" / "otherpkg" / "meshes").mkdir(parents=True)
    (root / "arm" / "pkgs" / "otherpkg" / "meshes" / "m.stl").write_bytes(b"solid m\n")
    (root / "arm" / "arm2.urdf").write_text(ARM_URDF.replace(
        "package://armpkg/meshes/l2.stl", "package://otherpkg/meshes/m.stl"))
    (root / "prev.json").write_text('{"generator": "aouc 0.2.0"}\n')  # an earlier output
    (root / "t.json").write_text(json.dumps(
        {"format": "aou-trajectory/1", "robot": "panda", "joint_names": [
            f"panda_joint{k}" for k in range(1, 8)], "t": t, "q": q}))
    (root / "rec.csv").write_text("t," + ",".join(f"panda_joint{k}" for k in range(1, 8))
                                  + "\n" + "".join(f"{x}," + ",".join(map(str, q[0])) + "\n"
                                                   for x in t))
    return {"aou": "y.aou", "robot": "arm/arm.toml", "urdf": "arm/arm.urdf",
            "mesh": "arm/meshes/l1.stl", "package mesh": "arm/armpkg/meshes/l2.stl",
            "plain aou": "a.aou", "trajectory": "t.json", "recording": "rec.csv",
            "one-line aou": "z.aou", "form-feed aou": "f.aou", "urdf2": "arm/arm2.urdf",
            "package-dir mesh": "arm/pkgs/otherpkg/meshes/m.stl", "-o output": "prev.json"}


#: Each writing command: (name, argv with OUT for the output, the inputs it reads by role,
#: the extension its output needs).
COMMANDS = [
    ("compile .aou naming its robot", ["compile", "y.aou", "--format", "json", "-o", "OUT"],
     ("aou", "robot", "urdf", "mesh", "package mesh"), "json"),
    ("compile --robot description", ["compile", "a.aou", "--robot", "arm/arm.toml",
                                     "--format", "csv", "-o", "OUT"],
     ("plain aou", "robot", "urdf", "mesh", "package mesh"), "csv"),
    ("compile --robot urdf", ["compile", "a.aou", "--robot", "arm/arm.urdf", "--format",
                              "yaml", "-o", "OUT"], ("plain aou", "urdf", "mesh"), "yaml"),
    ("compile a bag", ["compile", "y.aou", "--format", "mcap", "-o", "OUT"],
     ("aou", "robot", "urdf", "mesh"), ""),
    ("robot -o", ["robot", "arm/arm.toml", "--format", "toml", "-o", "OUT"],
     ("robot", "urdf", "mesh", "package mesh"), "toml"),
    ("robot urdf -o", ["robot", "arm/arm.urdf", "--format", "json", "-o", "OUT", "--force"],
     ("urdf", "mesh"), "json"),
    ("synth --robot", ["synth", "--state", "confident", "--robot", "arm/arm.toml",
                       "--no-verify", "-o", "OUT", "--force"], ("robot", "urdf", "mesh"),
     "aou"),
    ("plot a trajectory", ["plot", "t.json", "-o", "OUT"], ("trajectory",), "png"),
    ("plot a recording", ["plot", "rec.csv", "--robot", "panda", "-o", "OUT"],
     ("recording",), "svg"),
    ("plot --cv", ["plot", "--cv", "y.aou", "a.aou", "-o", "OUT"],
     ("aou", "plain aou", "robot", "urdf", "mesh"), "pdf"),
    ("render", ["render", "t.json", "-o", "OUT"], ("trajectory",), "gif"),
    ("compile a one-line .aou", ["compile", "z.aou", "--format", "json", "-o", "OUT"],
     ("one-line aou", "robot", "urdf", "mesh", "package mesh"), "json"),
    ("compile a form-feed .aou", ["compile", "f.aou", "--format", "json", "-o", "OUT"],
     ("form-feed aou", "robot", "urdf", "mesh", "package mesh"), "json"),
    ("compile --write-fitted", ["compile", "y.aou", "--fit", "--no-check", "--write-fitted",
                                "OUT", "-o", "prev.json"],
     ("aou", "robot", "urdf", "mesh", "package mesh", "-o output"), "aou"),
    ("check --write-fitted", ["check", "z.aou", "--fit", "--no-dynamic", "--write-fitted",
                              "OUT"], ("one-line aou", "robot", "urdf", "mesh"), "aou"),
    ("robot --package-dir -o", ["robot", "arm/arm2.urdf", "--package-dir", "arm/pkgs",
                                "--format", "json", "-o", "OUT", "--force"],
     ("urdf2", "package-dir mesh", "mesh"), "json"),
    ("plot --package-dir", ["plot", "t.json", "--robot", "arm/arm2.urdf", "--package-dir",
                            "arm/pkgs", "-o", "OUT"], ("urdf2", "package-dir mesh"), "png"),
    ("render a side-by-side", ["render", "--side-by-side", "t.json", "rec.csv", "--robot",
                               "panda", "-o", "OUT"], ("trajectory", "recording"), "mp4"),
]


def _link_ways(target: str, ext: str) -> dict[str, tuple[str, list]]:
    """Ways to point an output at ``target``: (the path to give, what to make first:
    ("symlink", link, to) or ("hardlink", link, to))."""
    name = f"out.{ext}" if ext else "out"
    folder, base = os.path.split(target)
    return {
        "the file itself": (target, []),
        "a ./ path": (f"./{target}", []),
        "an absolute path": ("ABS/" + target, []),
        "a path through ..": (f"{folder}/../{os.path.basename(folder)}/{base}"
                              if folder else f"arm/../{base}", []),
        "a symbolic link": (name, [("symlink", name, target)]),
        "a chain of links": (name, [("symlink", "l1", target), ("symlink", "l2", "l1"),
                                    ("symlink", name, "l2")]),
        "a relative link in a folder": (f"sub/{name}", [("symlink", f"sub/{name}",
                                                         f"../{target}")]),
        "a link to the folder": (f"lnk/{base}", [("symlink", "lnk", folder or ".")]),
        "a hard link": (name, [("hardlink", name, target)]),
    }


def _make(root: Path, steps: list) -> None:
    for kind, link, to in steps:
        p = root / link
        p.parent.mkdir(parents=True, exist_ok=True)
        if kind == "symlink":
            p.symlink_to(to)
        else:
            os.link(root / to, p)


def _snapshot(root: Path) -> dict[str, str]:
    """Every entry under ``root``: a file's hash, a link's target, a folder's mark; and
    the special files' kinds (they must stay what they were)."""
    out = {}
    for dirpath, dirs, files in os.walk(root):
        for name in dirs + files:
            p = Path(dirpath) / name
            rel = str(p.relative_to(root))
            st = p.lstat()
            if stat.S_ISLNK(st.st_mode):
                out[rel] = "-> " + os.readlink(p)
            elif stat.S_ISREG(st.st_mode):
                out[rel] = hashlib.sha256(p.read_bytes()).hexdigest()
            else:
                out[rel] = f"mode {stat.S_IFMT(st.st_mode):o}"
    return out


class Hang(Exception):
    pass


@contextlib.contextmanager
def _deadline(seconds: int):
    def hang(*_):
        raise Hang(f"no answer in {seconds} s")

    old = signal.signal(signal.SIGALRM, hang)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def refused(root: Path, argv: list[str], capsys, tmp: Path) -> str:
    """Run ``argv`` in ``root``; check the promises of a refusal; its stderr."""
    before = _snapshot(root)
    cwd = os.getcwd()
    os.chdir(root)
    try:
        with _deadline(HANG):
            code = main([a.replace("ABS/", str(root) + "/") for a in argv])
    finally:
        os.chdir(cwd)
    err = capsys.readouterr().err
    assert code == 2, (argv, code, err)
    assert "Traceback" not in err and "internal error" not in err, err
    assert any(f" {c} [error]" in err for c in ("I502", "I506")), (argv, err)
    assert _snapshot(root) == before, argv  # inputs unchanged, nothing new, nothing left
    assert os.listdir(tmp) == [], os.listdir(tmp)  # nothing left in $TMPDIR
    return err


@pytest.fixture
def fresh_tmp(tmp_path, monkeypatch):
    """$TMPDIR (and Python's tempfile) pointed at a new empty folder for the test."""
    tmp = tmp_path / "tmpdir"
    tmp.mkdir()
    monkeypatch.setenv("TMPDIR", str(tmp))
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    return tmp


def _scenarios():
    """Every (command, input, way); the default run takes two ways of each (command,
    input), turning through the ways so that each is taken by every command; the rest
    run in the slow run."""
    ways = list(_link_ways("ROLE", "x"))
    k = 0
    for name, argv, roles, ext in COMMANDS:
        for role in roles:
            for i, way in enumerate(ways):
                slow = (i - k) % len(ways) >= 2
                yield pytest.param(name, argv, role, way, ext, id=f"{name}|{role}|{way}",
                                   marks=[pytest.mark.slow] if slow else [])
            k += 2


@pytest.mark.parametrize("command,argv,role,way,ext", list(_scenarios()))
def test_an_output_never_lands_on_an_input(command, argv, role, way, ext, tmp_path,
                                           capsys, fresh_tmp):
    root = tmp_path / "ws"
    root.mkdir()
    roles = _workspace(root)
    target = roles[role]
    out, steps = _link_ways(target, ext)[way]
    _make(root, steps)
    err = refused(root, [out if a == "OUT" else a for a in argv], capsys, fresh_tmp)
    assert os.path.basename(target) in err or "extension" in err or "expected a file" in err


def _special(root: Path, kind: str, name: str) -> None:
    p = root / name
    if kind == "fifo":
        os.mkfifo(p)
    elif kind == "socket":
        s = socket.socket(socket.AF_UNIX)
        s.bind(str(p))
        s.close()
    elif kind == "device":
        try:
            os.mknod(p, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        except PermissionError:
            pytest.skip("making a device needs root")
    else:  # a link to the null device
        p.symlink_to(os.devnull)


SPECIAL = ["fifo", "socket", "device", "link to /dev/null"]


@pytest.mark.parametrize("command,argv,ext,kind", [
    pytest.param(c, a, e, kind, id=f"{c}|{kind}",
                 marks=[] if (i + j) % 2 == 0 else [pytest.mark.slow])
    for i, (c, a, _, e) in enumerate(COMMANDS) for j, kind in enumerate(SPECIAL)])
def test_an_output_is_never_a_device_fifo_or_socket(command, argv, ext, kind, tmp_path,
                                                    capsys, fresh_tmp):
    root = tmp_path / "ws"
    root.mkdir()
    _workspace(root)
    name = f"special.{ext}" if ext else "special"
    _special(root, kind, name)
    err = refused(root, [name if a == "OUT" else a for a in argv], capsys, fresh_tmp)
    assert "regular file" in err or "a file, and a bag" in err, err


def _bag(folder: Path, name: str) -> None:
    """A bag as aou writes one (its two files, on aou's topic)."""
    folder.mkdir(parents=True)
    (folder / "metadata.yaml").write_text(
        "rosbag2_bagfile_information:\n  topics_with_message_count:\n  - topic_metadata:\n"
        "      name: /joint_trajectory_controller/joint_trajectory\n"
        f"  relative_file_paths:\n  - {name}.mcap\n")
    (folder / f"{name}.mcap").write_bytes(b"\x89MCAP0\r\n")


BAG_CASES = {
    "a bag folder that also holds the robot files": (
        lambda r: (_bag(r / "b", "b"), os.replace(r / "arm", r / "b" / "arm")),
        ["compile", "y2.aou", "--format", "mcap", "-o", "b"]),
    "a bag folder holding notes": (
        lambda r: (_bag(r / "b", "b"), (r / "b" / "notes.txt").write_text("mine")),
        ["compile", "y.aou", "--format", "mcap", "-o", "b"]),
    "a folder of outputs whose bag's place holds files": (
        lambda r: ((r / "proj" / "y").mkdir(parents=True),
                   (r / "proj" / "y" / "keep.txt").write_text("mine")),
        ["compile", "y.aou", "--format", "mcap", "-o", "proj/"]),
    "a bag that is a file": (
        lambda r: (r / "b.txt").write_text("mine"),
        ["compile", "y.aou", "--format", "mcap", "-o", "b.txt"]),
    "a bag whose place links to the arm's folder": (
        lambda r: ((r / "proj").mkdir(), (r / "proj" / "y").symlink_to("../arm")),
        ["compile", "y.aou", "--format", "mcap", "-o", "proj/"]),
}


@pytest.mark.parametrize("case", list(BAG_CASES))
def test_a_bag_goes_only_into_a_new_empty_or_aou_folder(case, tmp_path, capsys, fresh_tmp):
    root = tmp_path / "ws"
    root.mkdir()
    _workspace(root)
    (root / "y2.aou").write_text('behaviour y : confident\nrobot "b/arm/arm.toml"\n'
                                 'approach\n')
    make, argv = BAG_CASES[case]
    make(root)
    refused(root, argv, capsys, fresh_tmp)


@pytest.mark.parametrize("command,argv", [
    ("synth", ["synth", "--state", "curious", "--no-verify", "-o", "OUT"]),
    ("robot", ["robot", "panda", "--format", "toml", "-o", "OUT"]),
    ("variants", ["variants", "a.aou", "--vary", "pause_duration=1,2", "-o", "v"]),
])
@pytest.mark.parametrize("existing", ["a hand-written behaviour", "notes", "empty",
                                      "JSON of another program"])
def test_an_existing_file_aou_did_not_write_needs_force(command, argv, existing, tmp_path,
                                                        capsys, fresh_tmp):
    root = tmp_path / "ws"
    root.mkdir()
    _workspace(root)
    text = {"a hand-written behaviour": "# mine\nbehaviour k : curious\npause 2s\n",
            "notes": "written by hand, about aouc\n", "empty": "",
            "JSON of another program": '{"generator": "not aou"}\n'}[existing]
    out = "v/a-pause_duration-low.aou" if command == "variants" else (
        "keep.aou" if command == "synth" else "keep.toml")
    (root / out).parent.mkdir(exist_ok=True)
    (root / out).write_text(text)
    err = refused(root, [out if a == "OUT" else a for a in argv], capsys, fresh_tmp)
    assert "I506" in err and "--force" in err


VARIANT_ROLES = ("variant base", "robot", "urdf", "mesh", "package mesh", "trajectory")


@pytest.mark.parametrize("role", VARIANT_ROLES)
@pytest.mark.parametrize("way", ["a symbolic link", "a relative link", "a hard link",
                                 "a link to the folder"])
def test_variants_never_write_onto_an_input(role, way, tmp_path, capsys, fresh_tmp):
    """`variants -o DIR` writes DIR/STEM-NAME-low.aou and -high.aou: where either name
    is, or links to, a file the command reads, it is refused and nothing is written."""
    root = tmp_path / "ws"
    root.mkdir()
    roles = _workspace(root)
    (root / "v.aou").write_text(f'behaviour v : confident\nrobot "{root}/arm/arm.toml"\n'
                                'approach a=0.5\n')  # absolute: the variants lint in vd/
    roles["variant base"] = "v.aou"
    target = roles[role]
    name = "v-approach_acceleration-high.aou"
    out = "vd"
    if way == "a symbolic link":
        steps = [("symlink", f"vd/{name}", str(root / target))]
    elif way == "a relative link":
        steps = [("symlink", f"vd/{name}", f"../{target}")]
    elif way == "a hard link":
        steps = [("hardlink", f"vd/{name}", target)]
    else:  # the output folder links to the input's folder, named as the variant
        folder, base = os.path.split(target)
        steps = [("symlink", "lnk", folder or ".")]
        out = "lnk"
        if base != name:
            steps.append(("symlink", f"{folder or '.'}/{name}", base))
    _make(root, steps)
    refused(root, ["variants", "v.aou", "--vary", "approach_acceleration=0.2,0.8", "-o",
                   out], capsys, fresh_tmp)


# --- the slow run: random chains and spellings -------------------------------------------


def _random_way(rng: random.Random, target: str, ext: str) -> tuple[str, list]:
    """A random chain of 1 to 5 links, relative or absolute, some through folders, ending
    at ``target``; the output named with the command's extension."""
    steps: list = []
    prev = target
    for k in range(rng.randint(1, 5)):
        folder = rng.choice(["", "d1/", "d1/d2/"])
        link = f"{folder}c{k}"
        depth = folder.count("/")
        to = prev if rng.random() < 0.3 else "../" * depth + prev
        if rng.random() < 0.3:
            to = "ABS/" + prev
        steps.append(("symlink", link, to))
        prev = link
    name = f"o.{ext}" if ext else "o"
    steps.append(("symlink", name, prev))
    return name, steps


@pytest.mark.slow
def test_random_chains_of_links_never_reach_an_input(tmp_path, capsys, fresh_tmp):
    rng = random.Random(20261125)
    for n in range(300):
        name, argv, roles, ext = rng.choice(COMMANDS)
        role = rng.choice(roles)
        root = tmp_path / f"ws{n}"
        root.mkdir()
        target = _workspace(root)[role]
        out, steps = _random_way(rng, target, ext)
        steps = [(k, link, to.replace("ABS/", str(root) + "/")) for k, link, to in steps]
        _make(root, steps)
        if not (root / out).exists():  # a chain the generator broke: not a scenario
            continue
        refused(root, [out if a == "OUT" else a for a in argv], capsys, fresh_tmp)


def _limited() -> None:
    """In the child: at most 2 GB of memory (the promise: no process over 2 GB)."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))


@pytest.mark.slow
@pytest.mark.parametrize("command,argv,roles,ext", COMMANDS, ids=[c for c, *_ in COMMANDS])
def test_as_a_process_a_refusal_ends_at_once_small_and_clean(command, argv, roles, ext,
                                                            tmp_path):
    """The same refusals by ``aouc`` as its own process: within :data:`HANG` seconds,
    under 2 GB, exit 2 with an I code, and $TMPDIR (fresh) left empty; a FIFO output
    and a link to each input."""
    import subprocess
    import sys

    from tests.conftest import ROOT

    for k, make in enumerate(["fifo", *roles]):
        root = tmp_path / f"ws{k}"
        root.mkdir()
        found = _workspace(root)
        tmp = tmp_path / f"tmp{k}"
        tmp.mkdir()
        out = f"o.{ext}" if ext else "o"
        if make == "fifo":
            os.mkfifo(root / out)
        else:
            (root / out).symlink_to(found[make])
        before = _snapshot(root)
        done = subprocess.run(
            [sys.executable, "-m", "aou_dsl", *[out if a == "OUT" else a for a in argv]],
            cwd=root, env={**os.environ, "TMPDIR": str(tmp), "PYTHONPATH": str(ROOT)},
            capture_output=True, text=True, timeout=HANG, preexec_fn=_limited)
        assert done.returncode == 2, (argv, make, done.stderr)
        assert "Traceback" not in done.stderr and " I50" in done.stderr, done.stderr
        assert _snapshot(root) == before and os.listdir(tmp) == []
