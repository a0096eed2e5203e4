"""Collision tests for the reach search: is a configuration free of self-collision and
above the table? PyBullet, on the URDF's collision shapes.

The replay's checks (:mod:`aou_dsl.safety.replay`) are the authority on a trajectory;
this is the search's filter, so that the posture it picks passes them. Links joined
directly (or through links without a shape) may touch, as may the pairs the robot file
allows; the links welded to the root stand on the table.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence

import numpy as np

from .urdf import Urdf, scene_xml

__all__ = ["CollisionTest", "collision_test"]

#: Penetration [m] below which two shapes are taken to touch (mesh contact noise).
TOUCH = -1e-4
#: Configurations sampled to find link pairs that touch everywhere.
SAMPLES = 40


def _parents(pb, body: int, c: int) -> dict[int, int]:
    return {j: pb.getJointInfo(body, j, physicsClientId=c)[16]
            for j in range(pb.getNumJoints(body, physicsClientId=c))}


def _excluded(pb, body: int, c: int, names: dict[str, int],
              allowed: Sequence[tuple[str, str]]) -> set[frozenset[int]]:
    """Pairs that may touch: adjacent through shapeless links, or allowed."""
    parent = _parents(pb, body, c)
    shaped = {j for j in range(-1, len(parent))
              if pb.getCollisionShapeData(body, j, physicsClientId=c)}

    def up(j: int) -> int:
        p = parent.get(j, -1)
        while p != -1 and p not in shaped:
            p = parent.get(p, -1)
        return p

    out = {frozenset((j, up(j))) for j in shaped if j != -1}
    out |= {frozenset((names[a], names[b])) for a, b in allowed if a in names and b in names}
    return out


class CollisionTest:
    """Whether the arm at ``q`` touches itself or the table (z = 0). Holds a PyBullet
    client until :meth:`close`.

    Attributes:
        overlapping: link pairs that touch in every one of :data:`SAMPLES` configurations
            spread over the joint ranges (meshes that overlap by design); they are not
            counted as collisions.
    """

    def __init__(self, pb, c: int, body: int, index: list[int], names: dict[str, int],
                 excluded: set[frozenset[int]], base: set[int]):
        self.pb, self.c, self.body, self.index = pb, c, body, index
        self.names = {v: k for k, v in names.items()}
        self.excluded, self.base = excluded, base
        self.plane = pb.createMultiBody(
            0, pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=c), physicsClientId=c)
        self.overlapping: tuple[tuple[str, str], ...] = ()

    def _touching(self, q: np.ndarray) -> set[frozenset[int]]:
        pb, c = self.pb, self.c
        for j, v in zip(self.index, q, strict=True):
            pb.resetJointState(self.body, j, float(v), physicsClientId=c)
        pb.performCollisionDetection(physicsClientId=c)
        return {frozenset((cp[3], cp[4]))
                for cp in pb.getContactPoints(self.body, self.body, physicsClientId=c)
                if cp[8] < TOUCH} - self.excluded

    def learn_overlaps(self, lower: np.ndarray, upper: np.ndarray) -> None:
        """Find the pairs touching everywhere (see :attr:`overlapping`) and exclude them."""
        mid = (lower + upper) / 2
        lo = np.maximum(lower, mid - np.pi)
        hi = np.minimum(upper, mid + np.pi)
        rng = np.random.default_rng(1)
        always = None
        for q in rng.uniform(lo, hi, size=(SAMPLES, len(self.index))):
            pairs = self._touching(q)
            always = pairs if always is None else always & pairs
            if not always:
                break
        self.excluded |= always or set()
        names = [sorted(self.names.get(j, "<root>") for j in p) for p in always or ()]
        self.overlapping = tuple(sorted((a, b) for a, b in names))

    def __call__(self, q: np.ndarray) -> bool:
        if self._touching(q):
            return True
        return any(p[8] < TOUCH and p[3] not in self.base
                   for p in self.pb.getClosestPoints(self.body, self.plane, 0.0,
                                                     physicsClientId=self.c))

    def close(self) -> None:
        self.pb.disconnect(physicsClientId=self.c)


def collision_test(urdf: Urdf, arm: Sequence[str], package_dirs: Sequence[str],
                   allowed: Sequence[tuple[str, str]] = ()) -> CollisionTest | None:
    """A :class:`CollisionTest` of the robot; None when its collision meshes cannot all
    be found (or PyBullet cannot load it)."""
    from .bullet import import_pybullet, quiet

    text, missing = scene_xml(urdf, package_dirs, None, visuals=False)
    if missing:
        return None
    pb = import_pybullet()
    with quiet():
        c = pb.connect(pb.DIRECT)
    with tempfile.TemporaryDirectory(prefix="aou-search-") as tmp:
        path = os.path.join(tmp, "robot.urdf")
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(text)
        try:
            with quiet():
                body = pb.loadURDF(path, useFixedBase=True, physicsClientId=c,
                                   flags=pb.URDF_USE_SELF_COLLISION)
        except pb.error:
            pb.disconnect(physicsClientId=c)
            return None
    info = [pb.getJointInfo(body, j, physicsClientId=c)
            for j in range(pb.getNumJoints(body, physicsClientId=c))]
    names = {inf[12].decode(): j for j, inf in enumerate(info)}
    joints = {inf[1].decode(): j for j, inf in enumerate(info)}
    base = {-1}  # the root and the links welded to it: they stand on the table
    for j, inf in enumerate(info):
        if inf[16] in base and inf[2] == pb.JOINT_FIXED:
            base.add(j)
    excluded = _excluded(pb, body, c, names, allowed)
    return CollisionTest(pb, c, body, [joints[n] for n in arm], names, excluded, base)
