"""``aouc render``: stimulus videos from PyBullet's headless renderer (TinyRenderer).

Frames are drawn at ``fps`` from the trajectory interpolated at each frame time, so the
video lasts as long as the motion (real time). What stands still (the table, the target
and its pedestal, the robot's base) is drawn once; each frame draws only the links the
arm moves and lays them over it by depth, which gives PyBullet's picture of the whole
scene pixel for pixel in half the time. A frame whose configuration is exactly the
previous one's (the arm holds still) reuses its image; the others are drawn by several
processes at once (one per core by default), which can be started before the motion is
compiled (:func:`start_workers`). MP4 goes through imageio with
imageio-ffmpeg (which ships its own ffmpeg); GIF through Pillow, with frame delays that
add up to the exact duration (GIF delays are whole centiseconds). Nothing here needs a
display.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.files import atomic
from ..core.files import check_output as _check_output
from ..core.memo import cached
from .annotate import progress_bar

__all__ = ["Camera", "frame_configurations", "frame_times", "render_configurations",
           "render_video", "start_workers", "Workers"]


@dataclass(frozen=True)
class Camera:
    """Where the virtual camera looks from. Defaults: a three-quarter view from the
    robot's side, 30 deg off the side view, so the approach and retreat read clearly and
    horizontal gazes (across the line of sight) still show depth; it looks at ``target``
    (None: halfway between the base and the goal, at the goal's height)."""

    distance: float = 1.2  # m
    yaw: float = 30.0  # deg
    pitch: float = -15.0  # deg
    target: tuple[float, float, float] | None = None
    width: int = 640
    height: int = 480
    fov: float = 50.0  # deg


def frame_times(duration: float, fps: float) -> np.ndarray:
    """Times of the frames [s]: ``k / fps`` for every whole frame of the motion."""
    return np.arange(int(math.floor(duration * fps + 1e-9)) + 1) / fps


def frame_configurations(traj, fps: float) -> np.ndarray:
    """The arm's joint positions at every frame time, interpolated, shape (F, n)."""
    from ..robot.load import load_robot

    t = np.asarray(traj.t, float)
    joints = load_robot(traj.robot, traj.package_dirs).spec.arm_joints
    q = np.asarray(traj.q, float)[:, traj.columns(joints)]
    times = frame_times(float(t[-1] - t[0]), fps) + t[0]
    return np.column_stack([np.interp(times, t, q[:, j]) for j in range(q.shape[1])])




@dataclass
class _Stage:
    """What a drawing process keeps per video: the robot alone in a scene of its own,
    only the links the arm moves drawn; the camera's matrices; and the picture of
    everything that stands still (the table, the target, its pedestal, the robot's base)
    with its depth, drawn once."""

    scene: object  # a Scene holding the robot only, visual meshes loaded
    view: list
    proj: list
    rgb: np.ndarray  # (h * w, 3) the still things, pixel by pixel
    depth: np.ndarray  # (h * w) their depth (1: nothing there)


def _stage(robot: str, goal: tuple, options, camera: Camera) -> _Stage:
    """The stage of a video, kept for the next one: loading the meshes takes a second
    (kept by the robot's files' content too: an edited mesh is loaded again)."""
    from ..robot.load import robot_key

    return _kept_stage(robot, goal, options, camera, robot_key(robot, options.package_dirs))


@cached(maxsize=4)
def _kept_stage(robot: str, goal: tuple, options, camera: Camera, key: tuple) -> _Stage:
    from ..core.options import SceneOptions
    from ..robot.scene import Scene

    arm = Scene(robot, None, SceneOptions(target_size=0, table_height=None,
                                            package_dirs=options.package_dirs))
    pb, c = arm.pb, arm.client
    target = camera.target or (goal[0] / 2, goal[1] / 2, goal[2])
    view = pb.computeViewMatrixFromYawPitchRoll(
        cameraTargetPosition=list(target), distance=camera.distance, yaw=camera.yaw,
        pitch=camera.pitch, roll=0, upAxisIndex=2, physicsClientId=c)
    proj = pb.computeProjectionMatrixFOV(
        fov=camera.fov, aspect=camera.width / camera.height, nearVal=0.05, farVal=10.0,
        physicsClientId=c)
    # The still things: the target, its pedestal, the table and the links no arm
    # joint moves (the base), drawn once; the arm's scene hides those links.
    try:
        still = Scene(robot, goal, options)
    except BaseException:
        arm.close()
        raise
    try:
        _pedestal(still, goal, options)
        moving = _moving_links(still)
        _hide(still, moving)
        rgb, depth = _draw(still, camera, view, proj)
    finally:
        still.close()
    _hide(arm, _drawn_links(arm) - moving)
    return _Stage(arm, view, proj, rgb.copy(), depth.copy())


def _drawn_links(scene) -> set[int]:
    """The robot's links that have a visual shape (-1: the base)."""
    return {v[1] for v in scene.pb.getVisualShapeData(scene.body,
                                                      physicsClientId=scene.client)}


def _moving_links(scene) -> set[int]:
    """The robot's links an arm joint moves: the arm joints' and everything below."""
    pb, c = scene.pb, scene.client
    parent = {j: pb.getJointInfo(scene.body, j, physicsClientId=c)[16]
              for j in range(pb.getNumJoints(scene.body, physicsClientId=c))}
    arm = set(scene.arm)

    def moves(j: int) -> bool:
        while j != -1:
            if j in arm:
                return True
            j = parent[j]
        return False

    return {j for j in parent if moves(j)}


def _hide(scene, links: set[int]) -> None:
    """Leave ``links`` out of the robot's drawing (fully transparent: TinyRenderer skips
    them, colour and depth)."""
    for link in sorted(links & _drawn_links(scene)):
        scene.pb.changeVisualShape(scene.body, link, rgbaColor=[0, 0, 0, 0],
                                   physicsClientId=scene.client)


def _draw(scene, camera: Camera, view, proj) -> tuple[np.ndarray, np.ndarray]:
    """PyBullet's TinyRenderer image of ``scene``, pixel by pixel: RGB (h * w, 3) and
    depth (h * w), views of PyBullet's own arrays (no segmentation mask asked for)."""
    pb, w, h = scene.pb, camera.width, camera.height
    _, _, rgba, depth, _ = pb.getCameraImage(w, h, view, proj, renderer=pb.ER_TINY_RENDERER,
                                             flags=pb.ER_NO_SEGMENTATION_MASK,
                                             physicsClientId=scene.client)
    return (np.asarray(rgba, dtype=np.uint8).reshape(h * w, 4)[:, :3],
            np.asarray(depth, dtype=np.float32).reshape(h * w))


def render_configurations(robot: str, goal: tuple, options, camera: Camera,
                          qs: np.ndarray) -> np.ndarray:
    """RGB images (k, h, w, 3) of the scene with the arm at each row of ``qs`` (k, n).

    The still things are drawn once (:func:`_stage`); each image draws the arm alone and
    lays it over them wherever it is nearer the camera, by depth, as one depth-buffered
    drawing of the whole scene does (the pixels are the same: ``tests/integration/test_media.py``
    holds it to PyBullet drawing everything at once).
    """
    st = _stage(robot, goal, options, camera)
    out = np.empty((len(qs), camera.height, camera.width, 3), dtype=np.uint8)
    pixels = out.reshape(len(qs), -1, 3)
    for k, qk in enumerate(qs):
        st.scene.set_arm(qk)  # type: ignore[attr-defined]
        rgb, depth = _draw(st.scene, camera, st.view, st.proj)
        pixels[k] = st.rgb
        arm = np.flatnonzero(depth < st.depth)
        pixels[k, arm] = rgb[arm]
    return out


#: Frames per task handed to a drawing process: a second or so of work, so that at the
#: end no process waits long for the last one.
_CHUNK = 12
#: Tasks handed out ahead of the one the video needs, per process: every process stays
#: busy, and the images waiting for their turn stay few.
_AHEAD = 3


@dataclass
class _Clip:
    """One trajectory's frames: the configurations to draw (each run of identical
    frames once) and, per frame, which drawn image it shows."""

    robot: str
    goal: tuple
    qs: np.ndarray  # (D, n) configurations drawn
    owner: np.ndarray  # (F,) frame -> index into qs
    title: str = ""  # its caption, side by side

    @classmethod
    def of(cls, traj, fps: float) -> _Clip:
        qk = frame_configurations(traj, fps)
        new = np.ones(len(qk), dtype=bool)
        new[1:] = np.any(qk[1:] != qk[:-1], axis=1)
        if traj.goal is None:  # a recording without a goal: the target where the hand ends
            from ..measuring.recording import final_goal

            goal = final_goal(traj)
        else:
            goal = traj.goal
        return cls(traj.robot, tuple(float(x) for x in goal), qk[new], np.cumsum(new) - 1,
                   traj.title or os.path.basename(traj.path))


@dataclass
class Workers:
    """Processes started to draw a video (:func:`start_workers`)."""

    pool: Any  # a concurrent.futures.ProcessPoolExecutor
    jobs: int

    def close(self) -> None:
        self.pool.shutdown(wait=False, cancel_futures=True)


def start_workers(jobs: int | None = None) -> Workers | None:
    """Start the processes that draw a video (``jobs``, None: one per core), to hand to
    :func:`render_video` as ``workers``: started before the motion is compiled or read,
    they import PyBullet meanwhile. None for one job (drawn in this process)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    jobs = jobs or _cores()
    if jobs <= 1:
        return None
    pool = ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_warm_worker)
    for _ in range(jobs):  # a task each makes the pool start every process at once
        pool.submit(int)
    return Workers(pool, jobs)


def _warm_worker() -> None:
    from ..robot.bullet import import_pybullet

    import_pybullet()


class _Drawer:
    """Draws the clips' configurations in chunks of :data:`_CHUNK`, in ``jobs`` processes
    (or here), and hands back the image of any (clip, drawn index) in frame order:
    chunks are handed out in the order the video needs them, a few ahead, and dropped
    once passed."""

    def __init__(self, clips: list[_Clip], camera: Camera, options, jobs: int, progress,
                 pool=None):
        self.clips, self.camera, self.options, self.progress = clips, camera, options, progress
        self.total = sum(len(c.qs) for c in clips)
        self.done = 0
        self.ready: dict[tuple[int, int], object] = {}
        # The chunks in the order the video first shows them.
        self.order = [(i, k) for _, i, k in sorted(
            (int(np.argmax(c.owner == k * _CHUNK)), i, k)
            for i, c in enumerate(clips) for k in range(-(-len(c.qs) // _CHUNK)))]
        self.next = 0
        self.pool = pool
        if jobs > 1 and self.total >= 2 * _CHUNK:
            if pool is None:  # two chunks at least: two processes at least
                pool = start_workers(min(jobs, len(self.order))).pool  # type: ignore[union-attr]
            self.pool = pool
            self.ahead = jobs * _AHEAD + len(clips)
            self._hand_out()
        elif pool is not None:  # too few frames to be worth it
            pool.shutdown(wait=False, cancel_futures=True)
            self.pool = None

    def _chunk(self, i: int, k: int) -> np.ndarray:
        return self.clips[i].qs[k * _CHUNK:(k + 1) * _CHUNK]

    def _hand_out(self) -> None:
        while self.next < len(self.order) and len(self.ready) < self.ahead:
            i, k = self.order[self.next]
            self.next += 1
            c = self.clips[i]
            self.ready[(i, k)] = self.pool.submit(  # type: ignore[union-attr]
                render_configurations, c.robot, c.goal, self.options, self.camera,
                self._chunk(i, k))

    def image(self, clip: int, index: int) -> np.ndarray:
        key = (clip, index // _CHUNK)
        got = self.ready.get(key)
        if not isinstance(got, np.ndarray):
            c = self.clips[clip]
            got = got.result() if got is not None else render_configurations(  # type: ignore[attr-defined]
                c.robot, c.goal, self.options, self.camera, self._chunk(*key))
            for old in [k for k in self.ready if k[0] == clip and k[1] < key[1]]:
                del self.ready[old]  # frames only move forward
            self.ready[key] = got
            self.done += len(got)
            self.progress(self.done, self.total)
            if self.pool is not None:
                self._hand_out()
        return got[index % _CHUNK]  # type: ignore[index]

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=True)


def _video_frames(clips: list[_Clip], drawer: _Drawer):
    """The video's frames in order, the clips side by side, each captioned with its
    behaviour's name (a shorter clip holds its last frame)."""
    from .annotate import side_by_side

    n = max(len(c.owner) for c in clips)
    for k in range(n):
        parts = [drawer.image(i, int(c.owner[min(k, len(c.owner) - 1)]))
                 for i, c in enumerate(clips)]
        yield parts[0] if len(parts) == 1 else side_by_side(parts, [c.title for c in clips])


def _pedestal(scene, goal, options) -> None:
    """A grey column from the table up to the target, drawn only (no collision shape), so
    that the target reads as standing on something rather than floating."""
    if options.table_height is None or options.target_size <= 0:
        return
    bottom = goal[2] - options.target_size / 2
    height = bottom - options.table_height
    if height <= 0.005:
        return
    pb, c = scene.pb, scene.client
    half = [options.target_size / 3, options.target_size / 3, height / 2]
    visual = pb.createVisualShape(pb.GEOM_BOX, halfExtents=half, rgbaColor=[0.6, 0.6, 0.6, 1],
                                  physicsClientId=c)
    pb.createMultiBody(0, -1, visual, basePosition=[goal[0], goal[1],
                                                    options.table_height + height / 2],
                       physicsClientId=c)


def render_video(trajs: list, path: str, *, fps: float = 30.0, camera: Camera = Camera(),
                 scene_options=None, quiet: bool = False, jobs: int | None = None,
                 workers=None, inputs=()) -> dict:
    """Render one trajectory, or several side by side, into ``path`` (.mp4 or .gif).

    Trajectories of different lengths are padded with their last frame. Written to a
    temporary file and renamed when complete. Frames are drawn in ``jobs`` processes
    (None: one per core), or by the ``workers`` of :func:`start_workers` (closed here).

    Returns:
        ``{"frames": N, "drawn": D, "fps": fps, "duration": seconds, "size": [w, h]}``:
        D of the N frames are drawn, the others repeat one (the arm holding still).
    """
    from ..core.options import SceneOptions

    try:
        fmt = check_output(path, inputs)
        # Import the encoder first: a missing one should fail before minutes of drawing.
        if fmt == "mp4":
            import imageio.v2 as imageio
            import imageio_ffmpeg  # noqa: F401  (imageio's ffmpeg plugin needs it)
        else:
            from PIL import Image
        opts = scene_options or SceneOptions(package_dirs=trajs[0].package_dirs)
        clips = [_Clip.of(tr, fps) for tr in trajs]
    except BaseException:
        if workers is not None:
            workers.close()
        raise
    label = "rendering" if len(trajs) == 1 else f"rendering {len(trajs)} side by side"
    drawer = _Drawer(clips, camera, opts, workers.jobs if workers else jobs or _cores(),
                     (lambda d, t: None) if quiet else progress_bar(label),
                     workers.pool if workers else None)
    n = max(len(c.owner) for c in clips)
    try:
        with atomic(path, inputs=inputs) as tmp:  # frames go to the encoder as they are drawn
            if fmt == "mp4":
                with imageio.get_writer(tmp, format="FFMPEG", fps=fps, codec="libx264",
                                        quality=8, macro_block_size=8,
                                        ffmpeg_log_level="error") as w:
                    for f in _video_frames(clips, drawer):
                        w.append_data(f)  # type: ignore[attr-defined]
                        size = f.shape
            else:  # Pillow keeps the frames it needs (in its palette), not these
                cs = [round((k + 1) * 100 / fps) - round(k * 100 / fps) for k in range(n)]
                images = (Image.fromarray(f) for f in _video_frames(clips, drawer))
                first = next(images)
                size = (first.height, first.width)
                first.save(tmp, format="GIF", save_all=True, append_images=images,
                           duration=[10 * d for d in cs], loop=0, optimize=False)
    finally:
        drawer.close()
    return {"frames": n, "drawn": drawer.total, "fps": fps, "duration": n / fps,
            "size": [size[1], size[0]]}


def _cores() -> int:
    from ..driver.parallel import default_jobs

    return default_jobs()


def check_output(path: str, reads=()) -> str:
    """Check a video path before rendering: .mp4 or .gif, its folder writable or makeable,
    not one of the files the command ``reads``."""
    return _check_output(path, ("mp4", "gif"), reads=reads)
