"""A robot file edited while a warm tool runs: the next build plans and checks on the
robot as the files now say, as a new process would; and every cache of the process is
in the registry, where clearing it makes a build a new process's, byte for byte.

The robot here is the Panda with ``joint_velocity`` pinned in a description: fearful's
shiver fits 2.0 rad/s, and a new process refuses it (C308) at 0.5 rad/s."""

from __future__ import annotations

import ast
import importlib
import multiprocessing
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from aou_dsl.core import memo
from aou_dsl.driver.session import Session
from tests.conftest import BEHAVIOURS, ROOT
from tests.integration.test_robots import small_arm

FAST = 'robot = "panda"\njoint_velocity = 2.0\n'
SLOW = 'robot = "panda"\njoint_velocity = 0.5\n'  # the same size: a stat may not tell


def _fearful(folder, name: str = "f.aou", pause: str = "1.25s") -> str:
    text = (BEHAVIOURS / "fearful.aou").read_text().replace(
        "behaviour fearful : fearful\n", 'behaviour fearful : fearful\nrobot "arm.toml"\n'
    ).replace("pause 1.25s", f"pause {pause}")
    path = folder / name
    path.write_text(text)
    return str(path)


def _codes(res) -> set[str]:
    return {d.code for d in res.diagnostics if d.severity.value == "error"}


def _fresh_compile(aou: str, out: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aou_dsl", "compile", aou, "-o", out],
                          capture_output=True, text=True, cwd=ROOT, check=False)


def test_a_session_builds_and_checks_on_the_robot_file_as_edited(tmp_path):
    """A session that built on 2.0 rad/s refuses the shiver once the file says 0.5 (as
    a new process does), and a trajectory made at 2.0 then fails the velocity check."""
    from aou_dsl.safety.replay import replay

    (tmp_path / "arm.toml").write_text(FAST)
    path = _fearful(tmp_path)
    session = Session()
    first = session.build_file(path)
    assert first.ok, [d.message for d in first.diagnostics]
    fast = first.compiled.trajectory
    peak = float(np.max(np.abs(fast.qd)))
    assert 0.5 < peak < 2.0 * 0.9  # planned at the scaled 2.0 rad/s, above 0.5
    assert all(c.ok for c in replay(fast).checks)

    (tmp_path / "arm.toml").write_text(SLOW)  # at once: the same size, maybe the same mtime
    again = session.build_file(path)
    assert "C308" in _codes(again), [d.message for d in again.diagnostics]
    (velocity,) = [c for c in replay(fast).checks if c.name == "joint-velocity"]
    assert not velocity.ok and velocity.limit == pytest.approx(0.5)
    assert "the robot description's velocity limits" in velocity.detail  # not the URDF's

    fresh = _fresh_compile(path, str(tmp_path / "fresh.json"))
    assert fresh.returncode == 1 and "C308" in fresh.stderr, fresh.stderr

    (tmp_path / "arm.toml").write_text(FAST)  # and back: built again, the same motion
    back = session.build_file(path)
    assert back.ok and np.array_equal(back.compiled.trajectory.q, fast.q)


def test_an_edited_urdf_and_mesh_make_a_new_arm_and_scene(tmp_path):
    """The URDF a description names, and a mesh that URDF names, are in the key: a
    changed velocity limit in the URDF reaches the arm, a changed mesh the check's
    scene; a file written again with the same bytes keeps what was made."""
    from aou_dsl.core.options import SceneOptions
    from aou_dsl.robot.load import load_arm
    from aou_dsl.safety.replay import check_scene

    mesh = "solid m\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex {s} 0 0\n" \
           "vertex 0 {s} 0\nendloop\nendfacet\nendsolid m\n"
    (tmp_path / "tip.stl").write_text(mesh.format(s="0.01"))
    urdf = small_arm().replace(
        '<link name="tool"/>', '<link name="tool"><collision><geometry>'
        '<mesh filename="tip.stl"/></geometry></collision></link>')
    (tmp_path / "small.urdf").write_text(urdf)
    toml = tmp_path / "small.toml"
    toml.write_text('urdf = "small.urdf"\njoint_accel = 7.0\njoint_jerk = 900.0\n')
    robot = str(toml)
    arm = load_arm(robot)
    assert list(arm.vmax) == [2.0] * 6
    scene = check_scene(robot, SceneOptions())

    (tmp_path / "small.urdf").write_text(urdf.replace('velocity="2.0"', 'velocity="1.0"'))
    assert list(load_arm(robot).vmax) == [1.0] * 6
    assert check_scene(robot, SceneOptions()) is not scene  # the URDF is the scene's too
    scene = check_scene(robot, SceneOptions())
    (tmp_path / "tip.stl").write_text(mesh.format(s="0.02"))
    assert check_scene(robot, SceneOptions()) is not scene
    scene, arm = check_scene(robot, SceneOptions()), load_arm(robot)
    time.sleep(0.01)
    (tmp_path / "tip.stl").write_text(mesh.format(s="0.02"))  # the same bytes again
    assert check_scene(robot, SceneOptions()) is scene and load_arm(robot) is arm
    from aou_dsl.robot.load import robot_key

    assert [os.path.basename(p) for p, _ in robot_key(robot)] == [
        "small.toml", "small.urdf", "tip.stl"]


def _small_with_mesh(folder) -> str:
    """Hesitant on the small arm, whose tool has a collision mesh ``tip.stl`` (not
    written here)."""
    urdf = small_arm().replace(
        '<link name="tool"/>', '<link name="tool"><collision><geometry>'
        '<mesh filename="tip.stl"/></geometry></collision></link>')
    (folder / "small.urdf").write_text(urdf)
    (folder / "small.toml").write_text(
        'urdf = "small.urdf"\njoint_accel = 7.0\njoint_jerk = 900.0\n')
    path = folder / "hesitant.aou"
    path.write_text((BEHAVIOURS / "hesitant.aou").read_text().replace(
        "robot panda\n", 'robot "small.toml"\n'))
    return str(path)


def test_a_mesh_missing_then_written_is_said_and_then_read(tmp_path):
    """A session (as the editor and the studio hold one) builds on a robot whose mesh is
    missing: the result carries V109, nothing is raised; once the mesh is written the
    next build reads it and passes, as a new process would, though no file the session
    had read changed."""
    path = _small_with_mesh(tmp_path)
    session = Session()
    missing = session.build_file(path)
    assert not missing.ok and "V109" in _codes(missing)
    assert any("tip.stl" in d.message for d in missing.diagnostics)
    (tmp_path / "tip.stl").write_text(
        "solid m\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.01 0 0\n"
        "vertex 0 0.01 0\nendloop\nendfacet\nendsolid m\n")
    present = session.build_file(path)
    assert present.ok, [d.message for d in present.diagnostics]


def test_a_copy_that_puts_the_old_mtime_back_is_still_seen(tmp_path):
    """``cp -p`` or ``rsync -t`` writes new bytes of the same size and gives the file
    its old modification time: the status change time still tells the file changed."""
    (tmp_path / "arm.toml").write_text(FAST)
    hour_ago = time.time_ns() - 3600 * 10**9  # long since written: hashed once, trusted
    os.utime(tmp_path / "arm.toml", ns=(hour_ago, hour_ago))
    path = _fearful(tmp_path)
    session = Session()
    assert session.build_file(path).ok
    old = os.stat(tmp_path / "arm.toml")
    time.sleep(0.02)
    (tmp_path / "arm.toml").write_text(SLOW)
    os.utime(tmp_path / "arm.toml", ns=(old.st_atime_ns, old.st_mtime_ns))
    new = os.stat(tmp_path / "arm.toml")
    assert (new.st_size, new.st_mtime_ns, new.st_ino) == (
        old.st_size, old.st_mtime_ns, old.st_ino)
    assert "C308" in _codes(session.build_file(path))


def test_the_live_regulator_plans_on_the_robot_file_as_edited(tmp_path, monkeypatch):
    """A regulator that planned fearful at 2.0 rad/s plans it again within 0.5 once the
    file says 0.5, the very plan a new regulator makes, and its transitions read the
    new limits."""
    from aou_dsl.lang.ir import State
    from aou_dsl.live.regulator import Regulator

    monkeypatch.chdir(tmp_path)
    (tmp_path / "arm.toml").write_text(FAST)
    reg = Regulator(robot="arm.toml")
    fast = reg.plan(State.FEARFUL, 1.0)
    assert float(np.max(np.abs(fast.qd))) > 0.5
    (tmp_path / "arm.toml").write_text(SLOW)
    slow = reg.plan(State.FEARFUL, 1.0)
    assert float(np.max(np.abs(slow.qd))) <= 0.5
    assert list(reg.arm.vmax) == [0.5] * reg.arm.n
    new = Regulator(robot="arm.toml").plan(State.FEARFUL, 1.0)
    assert np.array_equal(slow.q, new.q) and np.array_equal(slow.t, new.t)


def test_a_file_written_twice_in_one_clock_tick_is_hashed_again(tmp_path):
    """Two writes of the same size that leave the same stat (size, mtime, inode) are
    told apart: a file written lately is hashed again until its stat is old enough."""
    f = tmp_path / "a.toml"
    f.write_text("x = 1\n")
    first = memo.file_digest(str(f))
    st = os.stat(f)
    f.write_text("x = 2\n")
    os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns))  # the same mtime, as a coarse clock
    assert os.stat(f).st_mtime_ns == st.st_mtime_ns and os.stat(f).st_size == st.st_size
    assert memo.file_digest(str(f)) != first
    assert memo.file_digest(str(tmp_path / "none")) == ""


# --- The registry --------------------------------------------------------------------

def _package_modules() -> list[str]:
    names = []
    for p in sorted((ROOT / "aou_dsl").rglob("*.py")):
        parts = list(p.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__main__":
            continue
        names.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return names


def _caches_in(module) -> list[tuple[str, object]]:
    """Every cache a module holds at its top level: functions made by
    :func:`memo.cached`, tables, ``functools`` caches."""
    import functools

    found = []
    for name, obj in vars(module).items():
        if getattr(obj, "__module__", None) != module.__name__ and not isinstance(
                obj, memo.Table):
            continue
        if isinstance(getattr(obj, "cache", None), memo.Table):
            found.append((f"{module.__name__}.{name}", obj.cache))
        elif isinstance(obj, memo.Table):
            found.append((f"{module.__name__}.{name}", obj))
        elif isinstance(obj, functools._lru_cache_wrapper):
            found.append((f"{module.__name__}.{name}", obj))
    return found


def test_every_cache_of_the_package_is_in_the_registry():
    """Each module of the package imported, each cache it holds is one the registry
    reaches (so :meth:`Session.clear` empties it and :meth:`Session.stats` counts it),
    and the registry holds every ``cached`` function of the source, about forty."""
    for name in _package_modules():
        try:
            importlib.import_module(name)  # safe: a name from the package's own walk
        except ImportError:  # an optional extra not installed: its caches are not made
            continue
    registered = {id(t) for t in memo.caches().values()}
    found = [c for name in _package_modules() if name in sys.modules
             for c in _caches_in(sys.modules[name])]
    assert len(found) >= 35, found
    assert [n for n, c in found if id(c) not in registered] == []
    written = sum(len([d for n in ast.walk(ast.parse(p.read_text()))
                       if isinstance(n, ast.FunctionDef) for d in n.decorator_list
                       if isinstance(d, ast.Call) and getattr(d.func, "id", "") == "cached"])
                  for p in (ROOT / "aou_dsl").rglob("*.py"))
    assert written >= 35 and len(memo.caches()) >= written


def test_stats_count_and_clear_empties_every_cache(tmp_path):
    session = Session()
    text = (BEHAVIOURS / "hesitant.aou").read_text()
    session.build(text, "h.aou")
    session.build(text.replace("a=0.05", "a=0.06"), "h.aou")
    stats = session.stats()
    assert set(memo.caches()) <= set(stats)
    episodes = stats["aou_dsl.compiler.reuse._solved"]
    assert episodes.entries > 0 and episodes.hits > 0 and episodes.bytes > 0
    assert stats["session.build"].entries == 2
    assert stats["aou_dsl.robot.load._load"].bytes > 0
    assert all(s.entries <= s.maxsize for s in stats.values())
    session.clear()
    assert {n: s.entries for n, s in session.stats().items() if s.entries} == {}


def test_a_build_after_clear_is_a_new_process_s_byte_for_byte(tmp_path):
    """Builds of other values first, then every cache cleared: hesitant's document is
    the very bytes ``aouc compile`` writes in a new process."""
    from aou_dsl.compiler.output import encode

    path = tmp_path / "hesitant.aou"
    text = (BEHAVIOURS / "hesitant.aou").read_text()
    path.write_text(text)
    session = Session()
    for a in ("0.04", "0.06"):
        session.build(text.replace("a=0.05", f"a={a}"), str(path))
    session.clear()
    ours = encode(session.build(text, str(path)).document, "json")
    fresh = _fresh_compile(str(path), str(tmp_path / "fresh.json"))
    assert fresh.returncode == 0, fresh.stderr
    assert ours == (tmp_path / "fresh.json").read_bytes()


# --- Pool workers --------------------------------------------------------------------

forking = pytest.mark.skipif(
    not sys.platform.startswith("linux") or "fork" not in multiprocessing.get_all_start_methods(),
    reason="workers are spawned here")


@forking
def test_pool_workers_started_after_an_edit_build_on_the_edited_robot(tmp_path):
    """This process built on 2.0 rad/s; the workers of a ``--jobs 2`` run after the file
    says 0.5 are forked from it, with its caches, and refuse as a new process does."""
    from aou_dsl.core.options import BuildOptions
    from aou_dsl.driver import pool
    from aou_dsl.driver.parallel import build_many

    if not pool.can_fork():  # another thread runs here (pytest-xdist): a new pytest
        name = "test_pool_workers_started_after_an_edit_build_on_the_edited_robot"
        proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "0", "-p",
                               "no:cacheprovider", f"{__file__}::{name}"],
                              capture_output=True, text=True, cwd=ROOT, check=False)
        assert proc.returncode == 0 and "1 passed" in proc.stdout, proc.stdout[-3000:]
        return
    opts = BuildOptions(rate=100.0)
    (tmp_path / "arm.toml").write_text(FAST)
    paths = [_fearful(tmp_path, f"f{k}.aou", f"1.{25 + k}s") for k in range(3)]
    assert all(r.ok for r in build_many(paths, opts, jobs=1))
    (tmp_path / "arm.toml").write_text(SLOW)
    forked = []
    real = pool.BuildPool.__init__

    def counted(self, *args, **kwargs):
        forked.append(1)
        real(self, *args, **kwargs)

    pool.BuildPool.__init__ = counted
    try:
        got = list(build_many(paths, opts, jobs=2))
    finally:
        pool.BuildPool.__init__ = real
    assert forked  # a worker built some of them
    assert [("C308" in _codes(r)) for r in got] == [True] * 3


# --- The studio ----------------------------------------------------------------------

def test_the_studio_s_watcher_and_engine_see_an_edited_robot_file(tmp_path):
    """The studio's watcher reports a write of the robot description the file names,
    and its engine's next build refuses the shiver the new limit cannot give."""
    pytest.importorskip("watchfiles")
    from aou_dsl.studio.engine import Engine
    from aou_dsl.studio.watch import Watcher

    (tmp_path / "arm.toml").write_text(FAST)
    path = _fearful(tmp_path)
    engine = Engine()
    assert engine.build((tmp_path / "f.aou").read_text(), path).ok
    seen = threading.Event()
    watcher = Watcher(path, seen.set)
    try:
        time.sleep(0.3)  # the watch is set up
        (tmp_path / "arm.toml").write_text(SLOW)
        assert seen.wait(10)
    finally:
        watcher.close()
    seen = {"aou": threading.Event(), "robot": threading.Event()}
    watcher = Watcher(path, seen["aou"].set, on_robot_change=seen["robot"].set)
    try:
        time.sleep(0.3)
        (tmp_path / "arm.toml").write_text(FAST)
        assert seen["robot"].wait(10) and not seen["aou"].is_set()
        (tmp_path / "f.aou").write_text((tmp_path / "f.aou").read_text() + "\n")
        assert seen["aou"].wait(10)
    finally:
        watcher.close()
    (tmp_path / "arm.toml").write_text(SLOW)
    m = engine.build((tmp_path / "f.aou").read_text(), path)
    assert not m.ok and "C308" in {d.code for d in m.diagnostics}


def test_the_studio_page_shows_the_refusal_after_the_robot_file_changes(tmp_path):
    """``aouc studio`` on the file, watching: the robot file edited on disk, the page's
    diagnostics show the shiver's refusal (the motion shown stays the last good one)."""
    pytest.importorskip("viser", reason="the studio extra is missing")
    pytest.importorskip("watchfiles")
    from aou_dsl.studio.app import Studio

    (tmp_path / "arm.toml").write_text(FAST)
    studio = Studio(_fearful(tmp_path), port=0).start()
    try:
        assert 'data-code="C308"' not in studio.diags.content
        time.sleep(0.3)  # the watch is set up
        (tmp_path / "arm.toml").write_text(SLOW)
        for _ in range(300):
            if 'data-code="C308"' in studio.diags.content:
                break
            time.sleep(0.1)
        assert 'data-code="C308"' in studio.diags.content, studio.diags.content
        assert studio.shown is not None and studio.shown.ok
    finally:
        studio.close()
