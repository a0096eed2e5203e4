"""What the speed-ups must not change.

The fast safety replay measures distances only where they can change; these tests hold
it to a replay that measures every distance at every sample (written out here, the
straightforward way): the same verdicts, the same first sample of contact, the same
clearances, on random motions that do and do not collide. Also checked directly: the
motion bound the replay skips samples with is never beaten by the distances PyBullet
measures between consecutive samples.

The compiler's shortcuts (the end-effector accelerations of every instant at once, a
leaner TOPP-RA loop) are held to the straightforward computation, bit for bit; the bound
that spares the dense joint-limit check never passes a segment that overshoots.

Lint keeps at most a hundred diagnostics per file and counts the rest; the parser's
tables are cached on disk, and a cache that cannot be written changes nothing."""

import math
import subprocess

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from aou_dsl.core.trajectory import Trajectory
from aou_dsl.robot.load import load_arm
from aou_dsl.robot.scene import Scene
from aou_dsl.safety import replay as replay_module
from aou_dsl.safety.replay import CLEARANCE_RATE, replay
from aou_dsl.safety.sweep import Sweep
from tests.conftest import BEHAVIOURS

RATE = 250.0
#: PyBullet's distances are this repeatable [m] (see the last test).
NOISE = 1e-5


def _pairs_and_base(scene: Scene, allowed) -> tuple[list[tuple[int, int]], set[int]]:
    """Link pairs that must not touch and the links the robot stands on, from PyBullet's
    joint table: not joined directly or through links without a shape; not allowed."""
    pb, c, body = scene.pb, scene.client, scene.body
    n = pb.getNumJoints(body, physicsClientId=c)
    info = [pb.getJointInfo(body, j, physicsClientId=c) for j in range(n)]
    shaped = [j for j in range(-1, n) if pb.getCollisionShapeData(body, j, physicsClientId=c)]

    def shaped_parent(j: int) -> int:
        p = info[j][16] if j >= 0 else -1
        while p != -1 and p not in shaped:
            p = info[p][16]
        return p

    allowed_ids = {frozenset((scene.link_index[a], scene.link_index[b])) for a, b in allowed}
    pairs = [(a, b) for i, a in enumerate(shaped) for b in shaped[i + 1:]
             if shaped_parent(a) != b and shaped_parent(b) != a
             and frozenset((a, b)) not in allowed_ids]
    base = {-1}
    for j in range(n):
        if info[j][2] == pb.JOINT_FIXED and info[j][16] in base:
            base.add(j)
    return pairs, base


def _every_sample(robot: str, goal, q: np.ndarray, stride: int) -> dict:
    """Every distance at every sample: first contacts and clearances."""
    arm = load_arm(robot)
    out = {"self": None, "target": None, "table": None,
           "clear": {"self": math.inf, "target": math.inf, "table": math.inf}}
    with Scene(robot, goal, visuals=False) as scene:
        pb, c, body = scene.pb, scene.client, scene.body
        pairs, base = _pairs_and_base(scene, arm.spec.allowed_contacts)
        for i, qi in enumerate(q):
            scene.set_arm(qi)
            d_self = [min((p[8] for p in pb.getClosestPoints(body, body, 1.0, a, b,
                                                             physicsClientId=c)),
                          default=math.inf) for a, b in pairs]
            d_target = [p[8] for p in pb.getClosestPoints(body, scene.target, 1.0,
                                                          physicsClientId=c)]
            d_table = [p[8] for p in pb.getClosestPoints(body, scene.table, 1.0,
                                                         physicsClientId=c)
                       if p[3] not in base]
            if out["self"] is None and min(d_self, default=math.inf) < 0:
                out["self"] = i
            if out["target"] is None and min(d_target, default=math.inf) <= 0:
                out["target"] = i
            if out["table"] is None and min(d_table, default=math.inf) <= 0:
                out["table"] = i
            clear = out["clear"]
            clear["target"] = min(clear["target"], *d_target, math.inf)
            clear["table"] = min(clear["table"], *d_table, math.inf)
            if i % stride == 0 or i == len(q) - 1:
                clear["self"] = min(clear["self"], *[d for d in d_self if d <= 0.1], math.inf)
    return out


def _motion(robot: str, seed: int, n: int, reach: float) -> np.ndarray:
    """A smooth random joint motion from the robot's posture: a few random waypoints
    ``reach`` rad apart per joint at most, joined by smoothstep segments."""
    rng = np.random.default_rng(seed)
    arm = load_arm(robot)
    way = [np.array(arm.spec.posture)]
    for _ in range(3):
        way.append(np.clip(way[-1] + rng.uniform(-reach, reach, arm.n), arm.lower, arm.upper))
    seg = n // (len(way) - 1)
    parts = []
    for a, b in zip(way, way[1:], strict=False):
        s = np.linspace(0.0, 1.0, seg, endpoint=False)
        parts.append(a + np.outer(3 * s**2 - 2 * s**3, b - a))
    parts.append(way[-1][None, :])
    return np.vstack(parts)


def _goal_on_path(robot: str, q: np.ndarray, seed: int, offset: float) -> tuple:
    """A goal near the end-effector's path: the cube may or may not be touched."""
    rng = np.random.default_rng(seed + 1000)
    pos, _ = load_arm(robot).fk(q)
    p = pos[rng.integers(len(q))] + rng.uniform(-offset, offset, 3)
    return tuple(float(x) for x in p)


def _check_against_every_sample(robot: str, q: np.ndarray, goal: tuple) -> None:
    t = np.arange(len(q)) / RATE
    arm = load_arm(robot)
    tr = Trajectory(t, q, arm.joint_names, robot, None, goal)
    report = replay(tr)
    stride = max(1, int(round(RATE / CLEARANCE_RATE)))
    want = _every_sample(robot, goal, q, stride)
    by_name = {c.name: c for c in report.checks}
    for kind, name in (("self", "self-collision"), ("target", "target-contact"),
                       ("table", "table-contact")):
        check = by_name[name]
        assert check.ok == (want[kind] is None), (name, want[kind], check)
        if want[kind] is not None:
            assert check.time == pytest.approx(t[want[kind]]), name
    for kind in ("self", "target", "table"):
        w = want["clear"][kind]
        got = report.clearances[kind]
        if math.isinf(w) or w >= 1.0:
            assert got is None, kind
        else:
            assert got == pytest.approx(w, abs=NOISE), kind


@pytest.mark.slow
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), reach=st.sampled_from([0.4, 1.0, 1.8]),
       offset=st.sampled_from([0.0, 0.05, 0.15]), robot=st.sampled_from(["panda", "ur5"]))
# a UR5 deep in the target cube: its penetration depth changed faster than the motion
# bound allows, and the sweep read -0.0424 m where every sample reads -0.0431 m
@example(seed=2048, reach=1.8, offset=0.0, robot="ur5")
def test_fast_replay_finds_what_every_sample_finds(seed, reach, offset, robot):
    q = _motion(robot, seed, 240, reach)
    _check_against_every_sample(robot, q, _goal_on_path(robot, q, seed, offset))


@pytest.mark.parametrize("seed", [3, 11])
def test_fast_replay_matches_on_a_colliding_and_a_clear_motion(seed):
    """One quick pair of examples in the default run (the random search is slow)."""
    q = _motion("panda", seed, 160, 1.8 if seed == 3 else 0.3)
    _check_against_every_sample("panda", q, _goal_on_path("panda", q, seed, 0.02))


@pytest.mark.parametrize("robot", ["panda", "ur5"])
def test_no_distance_changes_faster_than_its_bound(robot):
    """Between consecutive samples, every followed distance (self pairs, target, table)
    changes by no more than the replay's bound allows (up to the engine's noise)."""
    q = _motion(robot, 7, 300, 1.5)
    goal = _goal_on_path(robot, q, 7, 0.05)
    tr = Trajectory(np.arange(len(q)) / RATE, q, load_arm(robot).joint_names, robot, None,
                    goal)
    replay(tr)  # builds and keeps the scene
    scene, geo = replay_module.check_scene(robot, replay_module.SceneOptions())
    scene.pb.resetBasePositionAndOrientation(scene.target, goal, (0, 0, 0, 1),
                                             physicsClientId=scene.client)
    sweep = Sweep(scene, geo, q, None)
    d = np.array([[sweep.measure(p, j) for j in range(len(q))]
                  for p in range(len(sweep.items))])
    bound = np.array([np.asarray(sweep.bound(p)) for p in range(len(sweep.items))])
    near = d < 1.0  # beyond the query range only "at least 1 m" is known
    both = near[:, 1:] & near[:, :-1]
    change = np.abs(np.diff(d, axis=1))[both]
    allowed = np.diff(bound, axis=1)[both]
    # PyBullet's distances jitter by a few micrometres from pose to pose (even between
    # links that do not move relative to each other); the replay's 1 mm contact margin
    # covers that a thousand times over.
    assert np.all(change <= allowed + NOISE), float((change - allowed).max())
    assert both.sum() > len(q)  # the test looked at many distances


# --- the compiler's shortcuts: the same numbers, to the last bit --------------------------


def _pinocchio_accelerations(arm, q, qd, qdd) -> np.ndarray:
    """The end-effector's classical acceleration by Pinocchio, one sample at a time."""
    import pinocchio as pin

    data = arm.model.createData()
    out = np.empty((len(q), 3))
    for k in range(len(q)):
        pin.forwardKinematics(arm.model, data, q[k], qd[k], qdd[k])
        pin.updateFramePlacements(arm.model, data)
        out[k] = pin.getFrameClassicalAcceleration(arm.model, data, arm.frame_id,
                                                   pin.LOCAL_WORLD_ALIGNED).linear
    return out


@pytest.mark.parametrize("robot", ["panda", "ur5", "z1", "kinova", "xarm7"])
def test_the_vectorised_accelerations_are_pinocchios(robot):
    arm = load_arm(robot)
    rng = np.random.default_rng(5)
    q = rng.uniform(arm.lower, arm.upper, (300, arm.n))
    qd, qdd = rng.normal(0, 2, (300, arm.n)), rng.normal(0, 10, (300, arm.n))
    fast = arm.accelerations(q, qd, qdd)
    assert fast is not None
    want = _pinocchio_accelerations(arm, q, qd, qdd)
    assert np.abs(fast - want).max() <= 1e-10 * max(1.0, np.abs(want).max())


def test_a_turn_about_any_axis_is_rodrigues():
    from scipy.spatial.transform import Rotation

    from aou_dsl.robot.kinematics import rotate_columns as _rotate

    rng = np.random.default_rng(8)
    base = Rotation.random(50, random_state=1).as_matrix()  # (N, 3, 3)
    angle = rng.uniform(-3, 3, 50)
    for axis in (np.array([0.0, 0.0, 1.0]), np.array([0.0, -1.0, 0.0]),
                 np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])):
        want = base @ Rotation.from_rotvec(axis * angle[:, None]).as_matrix()
        cols = np.ascontiguousarray(base.transpose(2, 1, 0))  # cols[k, i] = row i of col k
        got = _rotate(cols, axis, angle).transpose(2, 1, 0)
        assert np.abs(got - want).max() < 1e-12


def test_the_cartesian_peak_is_pinocchios_peak_over_every_instant():
    """The compiler computes every instant at once and only the top ones by Pinocchio:
    the peak is the one Pinocchio finds at every instant, bit for bit."""
    from aou_dsl.compiler.pipeline import compile_behaviour
    from aou_dsl.compiler.timing import PEAK_RATE, PathSegment, cartesian_peak
    from aou_dsl.lang.linter import lint_file

    for name in ("hesitant", "confident"):
        lint = lint_file(str(BEHAVIOURS / f"{name}.aou"))
        res = compile_behaviour(lint.behaviour, timeline=lint.timeline)
        arm = load_arm(lint.behaviour.settings.robot)
        segs = [s for s in res.segments if isinstance(s, PathSegment)]
        assert segs
        for seg in segs:
            n = max(100, math.ceil(seg.duration * PEAK_RATE) + 1)
            acc = _pinocchio_accelerations(arm, *seg.sample(np.linspace(0, seg.duration, n)))
            want = max(0.0, *(float(np.linalg.norm(a)) for a in acc))
            assert cartesian_peak(arm, seg) == want


def test_the_joint_limit_bound_never_passes_a_segment_that_overshoots():
    """The timing stage skips its dense joint-limit check where a bound over the whole
    path is within the limits: on the shipped motions under ever tighter limits, every
    segment the bound passes is within them at the check's instants."""
    from dataclasses import replace

    from aou_dsl.compiler.peak_limits import limit_ratios, within_limits
    from aou_dsl.compiler.pipeline import compile_behaviour
    from aou_dsl.compiler.timing import PathSegment
    from aou_dsl.lang.linter import lint_file

    passed = over = 0
    for path in sorted(BEHAVIOURS.glob("*.aou")):
        lint = lint_file(str(path))
        res = compile_behaviour(lint.behaviour, timeline=lint.timeline)
        arm = load_arm(lint.behaviour.settings.robot)
        for scale in (1.0, 0.3, 0.15, 0.1):
            tight = replace(arm, vmax=arm.vmax * scale, amax=arm.amax * scale * scale)
            for seg in res.segments:
                if not isinstance(seg, PathSegment):
                    continue
                rv, ra = limit_ratios(tight, seg)
                if within_limits(tight, seg):
                    passed += 1
                    assert rv.max() <= 1.0 and ra.max() <= 1.0
                over += bool(rv.max() > 1.0 or ra.max() > 1.0)
    assert passed > 10 and over > 10  # both cases were seen


def test_the_lean_toppra_gives_the_stock_law():
    """Random joint paths, limits that bind and limits that do not: every array of the
    parametrisation is the stock TOPPRA's, bit for bit."""
    from aou_dsl.compiler import topp

    toppra = topp.import_toppra()
    rng = np.random.default_rng(2)
    arm = load_arm("panda")
    for k in range(8):
        s_way = np.linspace(0.0, rng.uniform(0.02, 0.3), rng.integers(8, 40))
        q_way = arm.lower * 0.3 + np.cumsum(rng.normal(0, 0.02, (len(s_way), arm.n)), axis=0)
        a, vmax = rng.uniform(0.02, 3.0), rng.uniform(0.05, 0.5)
        jv, ja = arm.plan_vmax * (0.05 if k % 3 == 0 else 1.0), arm.plan_amax
        path = toppra.SplineInterpolator(s_way, np.column_stack([q_way, s_way]))
        grid = topp.grid(s_way, 80, a, vmax)
        # at rest at both ends (aou's case); and ends no law can reach, so that both
        # refusals (a final speed beyond control, a start speed beyond it) are compared
        for ends in ((0.0, 0.0), (0.0, 1e3), (1e3, 0.0)):
            outs, codes = [], []
            for cls in (toppra.algorithm.TOPPRA, topp._lean_toppra()):
                inst = cls(list(topp._constraints(tuple(jv), tuple(ja), a, vmax)), path,
                           gridpoints=grid, solver_wrapper="seidel")
                outs.append(inst.compute_parameterization(*ends, return_data=True))
                codes.append(inst.problem_data.return_code)
            assert codes[0] == codes[1], ends
            assert (codes[0] == toppra.algorithm.ParameterizationReturnCode.Ok) == (
                ends == (0.0, 0.0)), (ends, codes)
            for stock, lean in zip(*outs, strict=True):
                assert (stock is None) == (lean is None), ends
                assert stock is None or np.array_equal(stock, lean, equal_nan=True), ends


# --- lint: long files, the cap on diagnostics, the parser's cache ---------------------------


def test_a_file_with_many_errors_keeps_a_hundred_and_counts_the_rest():
    from aou_dsl.cli.report import format_suppressed
    from aou_dsl.core.diagnostics import Severity
    from aou_dsl.lang.linter import MAX_DIAGNOSTICS, lint_source, severity_counts

    # Every `pause` after the first is a duplicate primitive (an error of its own line).
    n = 3 * MAX_DIAGNOSTICS
    r = lint_source("approach\n" + "pause 1s\n" * n, "many.aou")
    assert len(r.diagnostics) == MAX_DIAGNOSTICS
    assert r.suppressed == {Severity.ERROR: n - 1 - MAX_DIAGNOSTICS}
    assert not r.ok
    # The kept ones are the first in the file, in file order.
    assert [d.span.line for d in r.diagnostics] == list(range(3, 3 + MAX_DIAGNOSTICS))
    assert severity_counts([r])[Severity.ERROR] == n - 1
    assert r.to_json()["suppressed"] == {"error": n - 1 - MAX_DIAGNOSTICS}
    note = format_suppressed(r.path, r.suppressed)
    assert note.startswith(f"many.aou: {n - 1 - MAX_DIAGNOSTICS} more diagnostics not shown")


def test_the_cap_keeps_errors_before_notes():
    """Notes early in a file do not push a later error out of the kept diagnostics."""
    from aou_dsl.core.diagnostics import Severity, Span, diag
    from aou_dsl.lang.linter import MAX_DIAGNOSTICS, FileResult, _cap

    notes = [diag("M204", "a note", Span("f.aou", i + 1, 1, i + 1, 2))
             for i in range(MAX_DIAGNOSTICS + 5)]
    error = diag("V101", "an error", Span("f.aou", 999, 1, 999, 2))
    r = FileResult("f.aou", [*notes, error])
    _cap(r)
    assert error in r.diagnostics and len(r.diagnostics) == MAX_DIAGNOSTICS
    assert r.suppressed == {Severity.NOTE: 6}
    assert r.diagnostics == sorted(r.diagnostics, key=lambda d: (d.span.line, d.span.col))


def test_a_vector_spans_its_parentheses():
    from aou_dsl.lang.parse import parse

    text = "goal (  0.5 ,0, 0.2 )  # there\n"
    (stmt,) = parse(text, "v.aou").items
    span = stmt.args[0].span
    assert (span.line, span.col) == (1, text.index("(") + 1)
    assert (span.end_line, span.end_col) == (1, text.index(")") + 2)
    assert stmt.span.end_col == span.end_col


def _lint_in_fresh_process(cache: str, tmp_path) -> subprocess.CompletedProcess:
    import os
    import sys

    env = dict(os.environ, AOU_CACHE_DIR=cache)
    return subprocess.run([sys.executable, "-m", "aou_dsl", "lint", str(BEHAVIOURS)],
                          capture_output=True, text=True, env=env, cwd=tmp_path)


def test_the_parser_tables_are_cached_and_a_cache_that_cannot_be_written_is_no_error(
        tmp_path):
    cache = tmp_path / "cache"
    first = _lint_in_fresh_process(str(cache), tmp_path)
    assert first.returncode == 0, first.stderr
    (saved,) = cache.glob("grammar-*.lark-cache")
    assert not list(cache.glob("*.tmp"))  # written whole, then renamed
    again = _lint_in_fresh_process(str(cache), tmp_path)
    assert (again.returncode, again.stdout) == (0, first.stdout)
    assert saved.stat().st_mtime == next(cache.glob("grammar-*")).stat().st_mtime
    # A cache folder that cannot exist (its parent is a file): lint works the same.
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    blocked = _lint_in_fresh_process(str(blocker / "cache"), tmp_path)
    assert (blocked.returncode, blocked.stdout) == (0, first.stdout)
    assert blocked.stderr.splitlines()[-1] == first.stderr.splitlines()[-1]


@pytest.mark.slow
def test_a_video_drawn_by_several_processes_is_the_one_drawn_by_one():
    """Frame for frame, side by side clips of different lengths included; held frames
    (drawn once) are the same image as drawing them again."""
    from aou_dsl.core.options import SceneOptions
    from aou_dsl.driver.builder import build_file
    from aou_dsl.media.annotate import caption
    from aou_dsl.media.render import Camera, _Clip, _Drawer, _video_frames, render_configurations

    trs = [build_file(str(BEHAVIOURS / f"{n}.aou"), check=False).trajectory
           for n in ("confident", "inactive")]
    cam = Camera(width=96, height=72)
    videos = []
    for jobs in (1, 2):
        clips = [_Clip.of(tr, 30.0) for tr in trs]
        drawer = _Drawer(clips, cam, SceneOptions(), jobs, lambda done, total: None)
        videos.append(list(_video_frames(clips, drawer)))
        drawer.close()
    assert len(videos[0]) == len(videos[1]) == len(_Clip.of(trs[0], 30.0).owner)
    assert all(np.array_equal(a, b) for a, b in zip(*videos, strict=True))
    clip = _Clip.of(trs[0], 30.0)
    held = int(np.flatnonzero(np.diff(clip.owner) == 0)[0])  # a frame shown twice
    again = render_configurations(clip.robot, clip.goal, SceneOptions(), cam,
                                  clip.qs[[clip.owner[held]] * 2])
    assert np.array_equal(again[0], again[1])
    # the video's half is that picture under its caption
    assert np.array_equal(caption(again[0], clip.title), videos[0][held + 1][:, :96])
