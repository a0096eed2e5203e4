"""Contacts and clearances over a whole trajectory, with exact PyBullet distance queries
only where the answer can change.

**Why skipping a sample is safe.** Between two samples the arm's joints move by
``|dq|``. Turning joint ``m`` by ``dq_m`` moves no point of a link below it further than
``|dq_m|`` times the point's distance to the joint's axis, and that distance is at most
the lengths of the links in between plus the link's own radius (a constant per joint and
link, :class:`Geometry`). Summed over the joints, this bounds how far a link can have
moved relative to the world (target, table) or to another link (only the joints between
the two count); a distance between two shapes changes no faster than they move. So the
distance ``d_j`` at sample ``j`` is at least ``d_i - (C_j - C_i)``, ``C`` the cumulative
motion bound, from every sample ``i`` where it was measured.

**The search** (per link pair, link and target, link and table): measure at the middle
sample; between two measured samples the bound is lowest where the two cones meet (before
the first and after the last, at the ends).
The clearance (the minimum distance) is found by measuring there, smallest bound first,
until no bound is below the smallest distance measured (Piyavskii's Lipschitz
minimisation): the same minimum a query at every sample finds. Contact is then ruled out
where the bound exceeds :data:`CONTACT_MARGIN`, and searched for, earliest first, where it
does not: the same first sample of contact.
"""

from __future__ import annotations

import heapq
import math
from array import array
from bisect import bisect_left
from dataclasses import dataclass, field

import numpy as np

from ..robot.scene import Scene

__all__ = ["CONTACT_MARGIN", "Geometry", "Sweep", "geometry"]

#: A sample whose distance bound is within this of contact is measured [m] (room for
#: the collision engine's own numerical tolerance).
CONTACT_MARGIN = 1e-3
#: Clearances are exact to this [m] (reported to 1e-6 m).
CLEARANCE_TOL = 1e-7
#: Distances are queried up to this [m]; beyond, only "at least this far" is known.
QUERY_RANGE = 1.0
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
    plan: tuple | None = None  # made by the first sweep: see _plan

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


def _plan(scene: Scene, geo: Geometry) -> tuple[list[tuple[str, int, int]], np.ndarray]:
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


@dataclass
class _Item:
    """One distance followed over the trajectory: a link pair, or a link and an object."""

    kind: str  # "self", "target" or "table"
    a: int
    b: int  # a link (self) or the object's body
    js: list[int] = field(default_factory=list)  # measured samples, sorted
    ds: list[float] = field(default_factory=list)  # their distances


class Sweep:
    """The distances of one trajectory in one scene, measured on demand."""

    def __init__(self, scene: Scene, geo: Geometry, q: np.ndarray, ee_link: int | None,
                 *, target: bool = True):
        self.scene, self.geo, self.q = scene, geo, q
        self.ee_link = ee_link
        self.at = -1
        self.visited: dict[int, tuple] = {}  # sample -> PyBullet's end-effector pose
        self.queries = 0
        set_joints(scene, geo.free, np.zeros(len(geo.free)))
        if geo.plan is None:
            geo.plan = _plan(scene, geo)
        kinds, w = geo.plan
        keep = [k for k, (kind, _, _) in enumerate(kinds) if target or kind != "target"]
        items = [_Item(*kinds[k]) for k in keep]
        w = w[keep]
        self.items = items
        # The cumulative motion bound of an item is its weights (constant) times the
        # cumulative joint travel; made for an item when it is first needed.
        self.weights = w
        self.travel = np.ascontiguousarray(np.vstack([
            np.zeros(q.shape[1]), np.cumsum(np.abs(np.diff(q, axis=0)), axis=0)]).T)
        self._bounds: list[array | None] = [None] * len(items)

    def bound(self, p: int) -> array:
        """Item ``p``'s cumulative motion bound at every sample [m] (nondecreasing)."""
        row = self._bounds[p]
        if row is None:
            row = array("d")
            row.frombytes((self.weights[p] @ self.travel).tobytes())
            self._bounds[p] = row
        return row

    # --- measuring ---

    def visit(self, j: int) -> None:
        """Put PyBullet's arm at sample ``j``, and note PyBullet's end-effector pose
        there (the replay compares it with its own kinematics)."""
        if j != self.at:
            scene = self.scene
            scene.pb.resetJointStatesMultiDof(scene.body, scene.arm,
                                              [[v] for v in self.q[j].tolist()],
                                              physicsClientId=scene.client)
            self.at = j
        if self.ee_link is not None and j not in self.visited:
            st = self.scene.pb.getLinkState(self.scene.body, self.ee_link,
                                            computeForwardKinematics=True,
                                            physicsClientId=self.scene.client)
            self.visited[j] = (st[4], st[5])

    def measure(self, p: int, j: int) -> float:
        """The distance of item ``p`` at sample ``j`` (at most :data:`QUERY_RANGE`)."""
        it = self.items[p]
        k = bisect_left(it.js, j)
        if k < len(it.js) and it.js[k] == j:
            return it.ds[k]
        self.visit(j)
        pb, c, body = self.scene.pb, self.scene.client, self.scene.body
        if it.kind == "self":
            pts = pb.getClosestPoints(body, body, QUERY_RANGE, it.a, it.b, physicsClientId=c)
        else:
            pts = pb.getClosestPoints(body, it.b, QUERY_RANGE, linkIndexA=it.a,
                                      physicsClientId=c)
        d = min((pt[8] for pt in pts), default=QUERY_RANGE)
        d = min(d, QUERY_RANGE)
        it.js.insert(k, j)
        it.ds.insert(k, d)
        self.queries += 1
        return d

    def seed(self, samples: list[int]) -> None:
        for j in samples:
            for p in range(len(self.items)):
                self.measure(p, j)

    # --- bounds ---

    def _lowest(self, p: int, k: int, members: int) -> tuple[float, int] | None:
        """The smallest bound between the item's k-th and (k+1)-th measured samples (k = -1:
        before the first, k = last: after the last), and where; only samples that are
        multiples of ``members`` (or the last sample) count."""
        it = self.items[p]
        cum = self._bounds[p]
        if cum is None:
            cum = self.bound(p)
        last = len(cum) - 1
        if k < 0 or k + 1 >= len(it.js):  # an open end: the bound is lowest at the end
            j, x = (it.js[0], 0) if k < 0 else (it.js[-1], last)
            if j == x:
                return None
            return float(it.ds[k + 1 if k < 0 else k] - abs(cum[x] - cum[j])), x
        ja, jb = it.js[k], it.js[k + 1]
        if jb - ja <= 1:
            return None
        da, db = it.ds[k], it.ds[k + 1]
        ca, cb = cum[ja], cum[jb]
        meet = (da - db + ca + cb) / 2
        j = bisect_left(cum, meet, ja, jb + 1)
        cands: tuple[int, ...] = (j - 1, j)  # the cones meet between j - 1 and j
        if members > 1:
            cands = (min(j // members * members, last), min(-(-j // members) * members, last),
                     (j - 1) // members * members)
        best = None
        for x in cands:
            if ja < x < jb:
                cx = cum[x]
                lb = max(da - (cx - ca), db - (cb - cx))
                if best is None or lb < best[0]:
                    best = (float(lb), x)
        return best

    def _of(self, kind: str) -> list[int]:
        return [p for p, it in enumerate(self.items) if it.kind == kind]

    def minimum(self, kind: str, members: int = 1) -> float:
        """The smallest distance of ``kind`` over the samples that are multiples of
        ``members`` (and the last), exactly (within :data:`CLEARANCE_TOL`)."""
        ps = self._of(kind)
        last = len(self.q) - 1
        best = min((d for p in ps for j, d in zip(self.items[p].js, self.items[p].ds,
                                                  strict=True)
                    if j % members == 0 or j == last), default=math.inf)
        heap: list[tuple[float, int, int]] = []

        def push(p: int, k: int) -> None:
            lo = self._lowest(p, k, members)
            if lo is not None:
                heapq.heappush(heap, (lo[0], p, lo[1]))

        for p in ps:
            for k in range(-1, len(self.items[p].js)):
                push(p, k)
        while heap and heap[0][0] < best - CLEARANCE_TOL:
            _, p, j = heapq.heappop(heap)
            best = min(best, self.measure(p, j))
            k = bisect_left(self.items[p].js, j)
            push(p, k - 1)
            push(p, k)
        return best

    def first_contact(self, kind: str, touching) -> tuple[int, int] | None:
        """The first sample where an item of ``kind`` is ``touching`` (a predicate of the
        distance), and the item; None when none is, at any sample."""
        ps = self._of(kind)
        first: tuple[int, int] | None = None
        for p in ps:
            it = self.items[p]
            for j, d in zip(it.js, it.ds, strict=True):
                if touching(d) and (first is None or j < first[0]):
                    first = (j, p)
                    break
        for p in ps:
            first = self._earliest(p, touching, first)
        return first

    def _earliest(self, p: int, touching, first: tuple[int, int] | None
                  ) -> tuple[int, int] | None:
        """Search item ``p`` for a contact before ``first``, left to right."""
        it = self.items[p]
        cum = self.bound(p)
        ends = [cum[0], *(cum[j] for j in it.js), cum[-1]]
        gap = max(b - a for a, b in zip(ends, ends[1:], strict=False))
        if min(it.ds) - gap > CONTACT_MARGIN:
            return first  # no interval's bound comes near contact
        k = -1
        while k < len(it.js):
            if first is not None and k >= 0 and it.js[k] >= first[0]:
                break
            lo = self._lowest(p, k, 1)
            if lo is None or lo[0] > CONTACT_MARGIN:
                k += 1
                continue
            j = lo[1]
            if touching(self.measure(p, j)) and (first is None or j < first[0]):
                first = (j, p)
            # the interval is now two: the loop looks at the left one first
        return first
