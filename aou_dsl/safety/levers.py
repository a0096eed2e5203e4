"""What the replay's distance bounds need of a robot in a scene, computed once per scene:
the link pairs that must not touch, the base links, and each link's lever arm about
every joint above it (how far a unit turn can move any point of the link).

:mod:`.sweep` explains how these bound the change of a distance between samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..robot.scene import Scene

__all__ = ["Geometry", "geometry", "plan", "set_joints"]

#: Random configurations that bound each link's radius about its frame (seeded).
_RADIUS_POSES = 24


@dataclass
class Geometry:
    """What the bounds need of a robot in a scene, computed once per scene.

    Attributes:
        pairs: link pairs that must not touch (PyBullet link indices, -1 the base).
        base: the root link and links welded to it (they stand on the table).
        shaped: links with a collision shape.
        free: movable joints that are not arm joints (held at zero during a replay).
        lever: per link, ``{joint: L}``: no point of the link is further than ``L`` from
            the axis of ``joint`` (an ancestor joint, or the link's own), in any pose.
        arm_pos: PyBullet joint index -> column of the arm's ``q``.
        ancestors: per link, the link and its ancestors up to (not including) the base.
        world_axis: arm joints below no other arm joint -> their axis in the world
            (constant): a turn about a vertical axis moves nothing up or down.
    """

    pairs: list[tuple[int, int]]
    base: set[int]
    shaped: list[int]
    free: list[int]
    lever: dict[int, dict[int, float]]
    arm_pos: dict[int, int]
    ancestors: dict[int, list[int]] = field(default_factory=dict)
    world_axis: dict[int, np.ndarray] = field(default_factory=dict)
    plan: tuple | None = None  # made by the first sweep: see plan

    def weights(self, a: int, b: int | None, normal: np.ndarray | None = None
                ) -> np.ndarray:
        """Per arm joint, how far a unit turn can move link ``a`` relative to link ``b``
        (None: the world; then ``normal``: only motion along it counts) [m/rad]. Only
        the joints below the links' common ancestor count."""
        chains = [(x, self.ancestors.get(x, [])) for x in (a, b) if x is not None]
        shared = set(chains[0][1]) & set(chains[1][1]) if len(chains) == 2 else set()
        w = np.zeros(len(self.arm_pos))
        for x, chain in chains:
            for m in chain:  # from the link up: the shared part is the top of the chain
                if m in shared:
                    break
                if m in self.arm_pos:
                    axis = self.world_axis.get(m)
                    # turning about u moves a point along u x (point - axis): its
                    # component along the normal is at most |normal x u| of it
                    f = 1.0 if normal is None or axis is None else float(
                        np.linalg.norm(np.cross(normal, axis)))
                    w[self.arm_pos[m]] += f * self.lever[x][m]
        return w


def geometry(scene: Scene, allowed: tuple[tuple[str, str], ...]) -> Geometry:
    """The pairs, base links and lever arms of ``scene``'s robot (see :class:`Geometry`).
    Leaves the arm in some pose: a replay sets every joint it relies on."""
    pb, c, body = scene.pb, scene.client, scene.body
    n = pb.getNumJoints(body, physicsClientId=c)
    info = [pb.getJointInfo(body, j, physicsClientId=c) for j in range(n)]
    parent = {j: info[j][16] for j in range(n)}
    shaped = [j for j in range(-1, n) if pb.getCollisionShapeData(body, j, physicsClientId=c)]
    ancestors = {}
    for j in range(n):
        chain, x = [], j
        while x != -1:
            chain.append(x)
            x = parent[x]
        ancestors[j] = chain
    base = {-1}
    for j in range(n):
        if info[j][2] == pb.JOINT_FIXED and info[j][16] in base:
            base.add(j)
    arm_pos = {j: k for k, j in enumerate(scene.arm)}
    free = [j for j in range(n) if info[j][2] != pb.JOINT_FIXED and j not in arm_pos]
    geo = Geometry(_pairs(scene, parent, shaped, allowed), base, shaped, free, {}, arm_pos,
                   ancestors)
    radius, offset = _radii(scene, info, shaped, free)
    slides = {j for j in scene.arm if info[j][2] == pb.JOINT_PRISMATIC}
    geo.world_axis = {m: _world_axis(scene, m) for m in scene.arm
                      if m not in slides and not any(x in arm_pos for x in ancestors[m][1:])}
    for x in range(n):
        lever, reach = {}, radius.get(x, 0.0)
        for m in ancestors[x]:  # x first, then up: the reach grows by each link's offset
            lever[m] = 1.0 if m in slides else reach  # a slide moves every point as far
            reach += offset[m]
        geo.lever[x] = lever
    return geo


def _pairs(scene: Scene, parent: dict[int, int], shaped: list[int],
           allowed: tuple[tuple[str, str], ...]) -> list[tuple[int, int]]:
    """Link pairs that must not touch: not adjacent (through shapeless links) and not
    allowed by the robot table."""
    shaped_set = set(shaped)

    def shaped_parent(j: int) -> int:
        p = parent.get(j, -1)
        while p != -1 and p not in shaped_set:
            p = parent.get(p, -1)
        return p

    allowed_ids = {frozenset((scene.link_index[a], scene.link_index[b])) for a, b in allowed}
    out = []
    for i, a in enumerate(shaped):
        for b in shaped[i + 1:]:
            if shaped_parent(b) == a or shaped_parent(a) == b:
                continue
            if frozenset((a, b)) not in allowed_ids:
                out.append((a, b))
    return out


def _radii(scene: Scene, info: list, shaped: list[int], free: list[int]
           ) -> tuple[dict[int, float], dict[int, float]]:
    """Per link, a radius about its frame's origin that holds its collision shapes (the
    farthest corner of PyBullet's bounding box, at its smallest over seeded random
    poses); per link, the distance from its parent's frame origin to its own (constant:
    a joint turns about its child's origin; free joints are at zero)."""
    pb, c, body = scene.pb, scene.client, scene.body
    rng = np.random.default_rng(0)
    lo = np.array([info[j][8] for j in scene.arm])
    hi = np.array([info[j][9] for j in scene.arm])
    lo, hi = np.where(hi > lo, lo, -math.pi), np.where(hi > lo, hi, math.pi)
    radius: dict[int, float] = {}
    offset: dict[int, float] = {}
    links = [j for j in shaped if j >= 0]
    for k in range(_RADIUS_POSES):
        q = (lo + hi) / 2 if k == 0 else rng.uniform(lo, hi)
        set_joints(scene, scene.arm, q)
        set_joints(scene, free, np.zeros(len(free)))
        origin = {j: np.array(pb.getLinkState(body, j, computeForwardKinematics=True,
                                              physicsClientId=c)[4])
                  for j in range(len(info))}
        for j in links:
            box = np.array(pb.getAABB(body, j, physicsClientId=c))
            corners = np.array([[box[a][0], box[b][1], box[d][2]]
                                for a in (0, 1) for b in (0, 1) for d in (0, 1)])
            r = float(np.linalg.norm(corners - origin[j], axis=1).max())
            radius[j] = min(radius.get(j, math.inf), r)
        if k == 0:  # arm joints in the middle of their ranges; a slide's offset varies
            for j in range(len(info)):
                p = info[j][16]
                offset[j] = float(np.linalg.norm(origin[j] - origin[p])) if p >= 0 else 0.0
                if info[j][2] == pb.JOINT_PRISMATIC and j in scene.arm:
                    offset[j] += float(hi[scene.arm.index(j)] - lo[scene.arm.index(j)]) / 2
    return radius, offset


def plan(scene: Scene, geo: Geometry) -> tuple[list[tuple[str, int, int]], np.ndarray]:
    """The distances a replay follows (kind, link, link or body) and their weights."""
    kinds = [("self", a, b) for a, b in geo.pairs]
    w = [geo.weights(a, b) for a, b in geo.pairs]
    if scene.target is not None:
        kinds += [("target", a, scene.target) for a in geo.shaped]
        w += [geo.weights(a, None) for a in geo.shaped]
    if scene.table is not None:
        movers = [a for a in geo.shaped if a not in geo.base]
        kinds += [("table", a, scene.table) for a in movers]
        w += [geo.weights(a, None, np.array([0.0, 0.0, 1.0])) for a in movers]
    return kinds, np.array(w).reshape(len(w), len(geo.arm_pos))


def _world_axis(scene: Scene, m: int) -> np.ndarray:
    """The world axis of joint ``m``, from how its link turns when the joint does."""
    pb, c, body = scene.pb, scene.client, scene.body
    rots = []
    for x in (0.0, 0.5):
        pb.resetJointState(body, m, x, physicsClientId=c)
        quat = pb.getLinkState(body, m, computeForwardKinematics=True, physicsClientId=c)[5]
        rots.append(np.reshape(pb.getMatrixFromQuaternion(quat), (3, 3)))
    turn = rots[1] @ rots[0].T
    axis = np.array([turn[2, 1] - turn[1, 2], turn[0, 2] - turn[2, 0], turn[1, 0] - turn[0, 1]])
    return axis / np.linalg.norm(axis)


def set_joints(scene: Scene, joints: list[int], q) -> None:
    """Put ``joints`` at ``q``, kinematically."""
    if joints:
        scene.pb.resetJointStatesMultiDof(scene.body, joints, [[float(v)] for v in q],
                                          physicsClientId=scene.client)
