"""The studio poses its arm from two threads (the player's, and the build's when it draws
a new motion at t = 0). The first two poses at once must not both add the line of sight:
viser replaces a node added twice under one name and marks the first handle removed, and
a later pose writing to that handle raised in the player's thread."""

import threading
from types import SimpleNamespace

import numpy as np

from aou_dsl.studio.view3d import Arm, Track


class _Handle:
    def __init__(self) -> None:
        self.removed = False
        self._points = None

    @property
    def points(self):
        return self._points

    @points.setter
    def points(self, value) -> None:
        if self.removed:  # as viser says it
            raise RuntimeError("Cannot assign to 'points' on a removed LineSegmentsHandle.")
        self._points = value


class _Scene:
    """viser's rule for a name added twice, and a first add slow enough for a second
    thread to arrive meanwhile (when nothing stops it)."""

    def __init__(self) -> None:
        self.live: dict[str, _Handle] = {}
        self.adds = 0
        self.second = threading.Event()

    def add_line_segments(self, name, *args, **kwargs) -> _Handle:
        self.adds += 1
        first = self.adds == 1
        handle = _Handle()
        if name in self.live:
            self.live[name].removed = True
        self.live[name] = handle
        if first:
            self.second.wait(0.5)
        else:
            self.second.set()
        return handle


def _arm(scene: _Scene) -> Arm:
    n = 50
    t = np.linspace(0.0, 1.0, n)
    hand = np.column_stack([np.linspace(0.3, 0.5, n), np.zeros(n), np.full(n, 0.4)])
    forward = np.tile([1.0, 0.0, 0.0], (n, 1))
    arm = Arm.__new__(Arm)  # the scene without a browser or a URDF
    arm.server, arm.root, arm.ghost = SimpleNamespace(scene=scene), "/arm", False
    arm.urdf = SimpleNamespace(update_cfg=lambda cfg: None)
    arm.track = Track(t, np.zeros((n, 7)), hand, forward, np.array([0.8, 0.0, 0.4]), ())
    arm._sight = None
    arm._posing = threading.Lock()
    return arm


def test_two_first_poses_at_once_add_one_line_of_sight_and_keep_it_live():
    scene = _Scene()
    arm = _arm(scene)
    threads = [threading.Thread(target=arm.pose, args=(t,)) for t in (0.0, 0.5)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert scene.adds == 1
    assert not arm._sight.removed
    arm.pose(0.9)  # a later tick of the player
    assert arm._sight.points is not None
