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
minimisation): the same minimum a query at every sample finds. A penetration depth (a
distance below zero) gives no bound: next to it every sample is measured. Contact is
then ruled out where the bound exceeds :data:`CONTACT_MARGIN`, and searched for,
earliest first, where it does not: the same first sample of contact.
"""

from __future__ import annotations

import heapq
import math
from bisect import bisect_left
from dataclasses import dataclass, field

import numpy as np

from ..robot.scene import Scene
from .levers import Geometry, geometry, plan, set_joints

__all__ = ["CONTACT_MARGIN", "Geometry", "Memo", "Sweep", "geometry"]

#: A sample whose distance bound is within this of contact is measured [m] (room for
#: the collision engine's own numerical tolerance).
CONTACT_MARGIN = 1e-3
#: Clearances are exact to this [m] (reported to 1e-6 m).
CLEARANCE_TOL = 1e-7
#: Distances are queried up to this [m]; beyond, only "at least this far" is known.
QUERY_RANGE = 1.0
#: ``getClosestPoints``' arguments between the links and the client, at their defaults
#: (no collision shapes, whose poses PyBullet then never reads). PyBullet's calls take
#: every argument by position here: a keyword argument has CPython look up each of the
#: function's keyword names before it, each made a new string and hashed, which cost
#: more than the call's own Python around a query (thousands of look-ups a replay).
_NO_SHAPES = (-1, -1, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0),
              (0.0, 0.0, 0.0, 1.0))


@dataclass
class Memo:
    """What a sweep measured, by the joint values it measured at, for the next sweep in
    the same scene (the same robot, options and goal): PyBullet's answers depend on the
    pose alone, so a recompilation whose samples repeat asks PyBullet only about the new
    ones. Bounded: it starts again empty past :attr:`size` entries."""

    distances: dict[tuple[int, bytes], float] = field(default_factory=dict)
    poses: dict[tuple[int, bytes], tuple] = field(default_factory=dict)
    size: int = 100_000

    def trim(self) -> None:
        """Forget everything once over :attr:`size` (called between sweeps)."""
        if len(self.distances) + len(self.poses) > self.size:
            self.distances.clear()
            self.poses.clear()


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
                 *, target: bool = True, memo: Memo | None = None):
        self.scene, self.geo, self.q = scene, geo, q
        self.ee_link = ee_link
        self.at = -1
        self.visited: dict[int, tuple] = {}  # sample -> PyBullet's end-effector pose
        self.queries = 0
        self.memo = memo if memo is not None else Memo()
        self._keys: list[bytes] | None = None  # per sample, its joint values as bytes
        set_joints(scene, geo.free, np.zeros(len(geo.free)))
        if geo.plan is None:
            geo.plan = plan(scene, geo)
        kinds, w = geo.plan
        keep = [k for k, (kind, _, _) in enumerate(kinds) if target or kind != "target"]
        self.planned = keep  # item -> its place in the plan (what the memo knows it by)
        items = [_Item(*kinds[k]) for k in keep]
        w = w[keep]
        self.items = items
        # The cumulative motion bound of an item is its weights (constant) times the
        # cumulative joint travel; made for an item when it is first needed, and read
        # through a memoryview: its items are Python floats, as the search compares them,
        # without copying the row (an item's row is as long as the motion).
        self.weights = w
        self.travel = np.ascontiguousarray(np.vstack([
            np.zeros(q.shape[1]), np.cumsum(np.abs(np.diff(q, axis=0)), axis=0)]).T)
        self._bounds: list[memoryview | None] = [None] * len(items)

    def bound(self, p: int) -> memoryview:
        """Item ``p``'s cumulative motion bound at every sample [m] (nondecreasing)."""
        row = self._bounds[p]
        if row is None:
            row = self._bounds[p] = memoryview(self.weights[p] @ self.travel)
        return row

    # --- measuring ---

    def key(self, j: int) -> bytes:
        """Sample ``j``'s joint values as bytes (what the memo knows a pose by)."""
        if self._keys is None:
            from ..robot.rows import row_keys

            self._keys = row_keys(self.q)
        return self._keys[j]

    def _put(self, j: int) -> None:
        """Put PyBullet's arm at sample ``j``."""
        if j != self.at:
            scene = self.scene
            scene.pb.resetJointStatesMultiDof(scene.body, scene.arm,
                                              [[v] for v in self.q[j].tolist()], [],
                                              scene.client)  # no velocities: by position
            self.at = j

    def visit(self, j: int) -> None:
        """Note PyBullet's end-effector pose at sample ``j`` (the replay compares it
        with its own kinematics): from the memo, else with PyBullet's arm put there."""
        if self.ee_link is None or j in self.visited:
            return
        key = (self.ee_link, self.key(j))
        pose = self.memo.poses.get(key)
        if pose is None:
            self._put(j)
            st = self.scene.pb.getLinkState(self.scene.body, self.ee_link, 0, 1,
                                            self.scene.client)  # forward kinematics
            pose = self.memo.poses[key] = (st[4], st[5])
        self.visited[j] = pose

    def measure(self, p: int, j: int) -> float:
        """The distance of item ``p`` at sample ``j`` (at most :data:`QUERY_RANGE`)."""
        return self._take(p, j)[0]

    def _take(self, p: int, j: int) -> tuple[float, int]:
        """:meth:`measure`, and where ``j`` is among the item's measured samples."""
        it = self.items[p]
        js = it.js
        k = bisect_left(js, j)
        if k < len(js) and js[k] == j:
            return it.ds[k], k
        if j not in self.visited:
            self.visit(j)
        key = (self.planned[p], self._keys[j] if self._keys is not None else self.key(j))
        memo = self.memo.distances
        d = memo.get(key)
        if d is None:
            d = memo[key] = self._query(it, j)
        js.insert(k, j)
        it.ds.insert(k, d)
        return d, k

    def _query(self, it: _Item, j: int) -> float:
        """PyBullet's distance of ``it`` at sample ``j`` (the nearest of its points, at
        most :data:`QUERY_RANGE`)."""
        if j != self.at:
            self._put(j)
        pb, body = self.scene.pb, self.scene.body
        if it.kind == "self":
            pts = pb.getClosestPoints(body, body, QUERY_RANGE, it.a, it.b, *_NO_SHAPES,
                                      self.scene.client)
        else:  # a link and an object (-2: any of its links)
            pts = pb.getClosestPoints(body, it.b, QUERY_RANGE, it.a, -2, *_NO_SHAPES,
                                      self.scene.client)
        d = QUERY_RANGE
        for pt in pts:
            if pt[8] < d:
                d = pt[8]
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
        js = it.js
        if k < 0 or k + 1 >= len(js):  # an open end: the bound is lowest at the end
            j, x = (js[0], 0) if k < 0 else (js[-1], len(cum) - 1)
            if j == x:
                return None
            d = it.ds[k + 1 if k < 0 else k]
            return (-math.inf if d < 0.0 else d - abs(cum[x] - cum[j])), x
        ja, jb = js[k], js[k + 1]
        if jb - ja <= 1:
            return None
        ds = it.ds
        da, db = ds[k], ds[k + 1]
        if da < 0.0 or db < 0.0:  # no cone from inside: every sample there is measured
            return _inside(ja, jb, members, len(cum) - 1)
        ca, cb = cum[ja], cum[jb]
        j = bisect_left(cum, (da - db + ca + cb) / 2, ja, jb + 1)
        # the cones meet between j - 1 and j: the lower bound there, the larger of the
        # two cones' (each a float of the same arithmetic as ``max`` would compare)
        if members == 1:
            candidates: tuple[int, ...] = (j - 1, j)
        else:
            last = len(cum) - 1
            down, up = j // members * members, -(-j // members) * members
            candidates = (down if down < last else last, up if up < last else last,
                          (j - 1) // members * members)
        best = None
        for x in candidates:
            if ja < x < jb:
                cx = cum[x]
                lb, other = da - (cx - ca), db - (cb - cx)
                if other > lb:
                    lb = other
                if best is None or lb < best[0]:
                    best = (lb, x)
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
        lowest, heappush, heappop, take = (self._lowest, heapq.heappush, heapq.heappop,
                                           self._take)
        for p in ps:
            for k in range(-1, len(self.items[p].js)):
                lo = lowest(p, k, members)
                if lo is not None:
                    heappush(heap, (lo[0], p, lo[1]))
        while heap and heap[0][0] < best - CLEARANCE_TOL:
            _, p, j = heappop(heap)
            d, k = take(p, j)
            if d < best:
                best = d
            left, right = lowest(p, k - 1, members), lowest(p, k, members)
            if left is not None:
                heappush(heap, (left[0], p, left[1]))
            if right is not None:
                heappush(heap, (right[0], p, right[1]))
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


def _inside(ja: int, jb: int, members: int, last: int) -> tuple[float, int] | None:
    """The middle sample between ``ja`` and ``jb`` that counts (a multiple of ``members``,
    or the last), with no lower bound, or None when none lies between them. Once two
    shapes overlap, the negative distance PyBullet gives is a penetration depth, which
    is not bounded by the motion as a distance between apart shapes is (a UR5 reaching
    into the target cube read -0.0424 m where a query at every sample finds -0.0431 m),
    so next to a sample measured inside, the samples are measured, not bounded."""
    mid = (ja + jb) // 2
    for x in (mid // members * members, -(-mid // members) * members, last):
        if ja < min(x, last) < jb:
            return -math.inf, min(x, last)
    return None
