"""What a URDF does not say, derived from its kinematics (Pinocchio).

- **Forward axis** of the end-effector frame: the frame's axis (x, y or z, either sign)
  nearest the last arm joint's axis, signed to point away from the wrist. When no axis
  is within 25 deg of it, the frame's axis nearest the direction from the wrist to the
  end-effector.
- **Shiver joint**: the last revolute joint whose axis is within 10 deg of the forward
  axis and passes within 2 cm of the end-effector: turning it rolls the hand about its
  line of sight without moving it.
- **Reach** (goal, start direction, posture): the compiler's own inverse kinematics is
  run on the default reach (start 0.30 m from the goal, approach to the 0.10 m standoff,
  retreat to 0.36 m, horizontal gazes of +-20 deg at 0.10 m and 0.23 m, rolls of
  +-20 deg; vertical gazes of +-20 deg count when they pass too) from seeds spread over
  the joint ranges. Goals lie
  in front of the base (+x) at half the arm's length and a quarter of it above the table
  (then nearer, farther, higher); start directions look down at the goal from above and
  behind (as the built-in arms do), then more level. The first goal and direction where
  some seed passes every path wins (else the best that passes the needed ones), and among
  its seeds the one whose whole reach stays farthest from joint limits and singularities
  (and free of self-collision and of the table): its start configuration becomes the
  posture. When no goal of this grid passes (an arm whose front is not +x), reaches are
  read off sampled configurations: each looks down at a goal 0.30 m ahead of its hand.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .kinematics import ArmModel

__all__ = ["Reach", "find_reach", "forward_axis", "shiver_joint"]

Collides = Callable[[np.ndarray], bool] | None

#: A joint's axis is the forward axis when within this angle [deg] of it.
AXIS_TOLERANCE = 25.0
SHIVER_TOLERANCE = 10.0
#: The shiver joint's axis passes this close [m] to the end-effector.
SHIVER_OFFSET = 0.02
#: Start directions tried, in order: from above and behind the goal, then more level.
DIRECTIONS = ((-0.6, 0.0, 0.8), (-0.8, 0.0, 0.6), (-1.0, 0.0, 0.0))
#: Seeds tried per goal and direction: those of :data:`POOL` configurations spread over
#: the joint ranges whose hand is nearest the start pose.
SEEDS = 8
POOL = 400
#: Reaches read off the pool when no goal of the grid passes.
POOL_REACHES = 60
#: Most default reaches tried for one robot, over every goal, direction, seed and turn of
#: the hand: the built-in arms' URDFs need 8 to 16; an arm that no reach fits stops here
#: instead of trying hundreds (minutes of IK).
MAX_PROBES = 64


class Budget:
    """How many more reaches the search may try (:data:`MAX_PROBES` at first)."""

    def __init__(self, left: int = MAX_PROBES):
        self.left = left

    def take(self) -> bool:
        """One more try, when any is left."""
        self.left -= 1
        return self.left >= 0
#: Every joint origin past the second stays this high above the table [m].
TABLE_CLEARANCE = 0.02
_AXES = ("x", "y", "z")


@dataclass(frozen=True)
class Reach:
    """A default reach: where the goal is, where the start looks from, the posture.

    ``ok`` is False when no candidate passed every probe (the values are then the first
    goal and direction with the middle of the joint ranges; compiling will say what fails).
    """

    goal: tuple[float, float, float]
    start_direction: tuple[float, float, float]
    posture: tuple[float, ...]
    ok: bool
    score: float
    how: str


def _pin():
    import pinocchio as pin

    return pin


def _local(model: Any, q: np.ndarray, frame_id: int) -> tuple[Any, np.ndarray]:
    """The frame's placement and its LOCAL Jacobian, shape (6, n)."""
    pin = _pin()
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    jac = pin.computeFrameJacobian(model, data, q, frame_id, pin.LOCAL)
    # one joint: Pinocchio's binding gives a vector of 6, not a (6, 1) matrix
    return data.oMf[frame_id].copy(), np.asarray(jac).reshape(6, model.nv)


def _signed_axis(v: np.ndarray) -> str:
    i = int(np.argmax(np.abs(v)))
    return ("+" if v[i] >= 0 else "-") + _AXES[i]


def forward_axis(model: Any, q: np.ndarray, frame_id: int) -> tuple[str, str]:
    """The end-effector frame's forward axis (``"+z"``, ``"-x"``, ...) and how it was found.

    ``model`` is the arm (its joints only), ``q`` a configuration inside the limits.
    """
    pin = _pin()
    m, jac = _local(model, q, frame_id)
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    n = model.njoints - 1
    wrist = None
    for j in range(n, 0, -1):  # the nearest joint origin at least 1 cm from the hand
        offset = m.rotation.T @ (m.translation - data.oMi[j].translation)
        if np.linalg.norm(offset) > 0.01:
            wrist = offset
            break
    axis = jac[3:, n - 1]
    last = model.names[n]
    if model.joints[n].nv == 1 and np.linalg.norm(axis) > 0.5:
        axis = axis / np.linalg.norm(axis)
        i = int(np.argmax(np.abs(axis)))
        if abs(axis[i]) >= math.cos(math.radians(AXIS_TOLERANCE)):
            sign = 1.0 if wrist is None or wrist[i] >= 0 else -1.0
            got = ("+" if sign > 0 else "-") + _AXES[i]
            return got, f"derived: the frame axis along {last}'s axis, away from the wrist"
    if wrist is None:
        return "+z", "derived: no wrist offset and no aligned joint; z assumed"
    return _signed_axis(wrist), f"derived: the frame axis nearest the wrist-to-hand line " \
                                f"({last}'s axis is not along any frame axis)"


def shiver_joint(model: Any, q: np.ndarray, frame_id: int, forward: str
                 ) -> tuple[str, str]:
    """The joint that rolls the hand about its forward axis, and how it was found."""
    _, jac = _local(model, q, frame_id)
    f = np.zeros(3)
    f[_AXES.index(forward[1])] = 1.0
    best = None
    for j in range(model.njoints - 2, -1, -1):
        if model.joints[j + 1].nv != 1 or np.linalg.norm(jac[3:, j]) < 0.5:
            continue  # prismatic (no angular part) or not a one-axis joint
        ang = jac[3:, j] / np.linalg.norm(jac[3:, j])
        off = float(np.linalg.norm(jac[:3, j]))  # ee speed per rad: the axis' distance
        angle = math.degrees(math.acos(min(1.0, abs(float(ang @ f)))))
        if angle <= SHIVER_TOLERANCE and off <= SHIVER_OFFSET:
            return model.names[j + 1], "derived: the last joint turning about the forward axis"
        if best is None or angle < best[1]:
            best = (model.names[j + 1], angle)
    if best is None:
        return model.names[model.njoints - 1], "derived: no revolute joint; the last joint"
    return best[0], (f"derived: no joint turns about the forward axis; the nearest "
                     f"({best[1]:.0f} deg off) moves the hand when it shivers")


def _origins(arm: ArmModel, q: np.ndarray) -> np.ndarray:
    pin = _pin()
    data = arm.model.createData()
    pin.framesForwardKinematics(arm.model, data, q)
    pts = [data.oMi[j].translation.copy() for j in range(1, arm.model.njoints)]
    return np.array([*pts, data.oMf[arm.frame_id].translation])


def _length(arm: ArmModel, q: np.ndarray) -> tuple[float, float]:
    """The arm's length (joint origin to joint origin to the hand) and its shoulder
    height (the second joint's origin) [m]."""
    pts = _origins(arm, q)
    return float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1))), float(pts[1][2])


def _goals(arm: ArmModel, q_mid: np.ndarray) -> list[tuple[float, float, float]]:
    length, _ = _length(arm, q_mid)
    z = min(0.30, max(0.10, 0.25 * length))
    out = [(0.5 * length, 0.0, z), (0.4 * length, 0.0, z), (0.6 * length, 0.0, z),
           (0.7 * length, 0.0, z), (0.5 * length, 0.0, z + 0.1)]
    return [tuple(round(c, 3) for c in g) for g in out]  # type: ignore[misc]


def _sweep(d: float, key: int) -> list[tuple[float, float, float, float]]:
    """At distance ``d``, one angle of the pose (1: h, 2: v, 3: roll) from 0 to +20 deg,
    then to -20 deg."""
    a = math.radians(20.0)
    out = []
    for x in [a * k / 4 for k in range(1, 5)] + [a - a * k / 4 for k in range(1, 9)]:
        pose = [d, 0.0, 0.0, 0.0]
        pose[key] = x
        out.append((pose[0], pose[1], pose[2], pose[3]))
    return out


def _probe_paths() -> tuple[list, list]:
    """The default reach as (d, h, v, roll) paths, each from the end of the approach:
    the ones every reach must pass (approach from 0.30 m to the 0.10 m standoff, retreat
    to 0.36 m, horizontal gazes of +-20 deg at 0.10 m and 0.23 m, rolls of +-20 deg) and
    the one a better reach passes too (vertical gazes of +-20 deg)."""
    approach = [(0.30 - 0.04 * k, 0.0, 0.0, 0.0) for k in range(6)]
    retreat = [(0.10 + 0.03 * k, 0.0, 0.0, 0.0) for k in range(1, 10)]
    farther = [(0.10 + 0.0325 * k, 0.0, 0.0, 0.0) for k in range(1, 5)]
    need = [approach, retreat, _sweep(0.10, 1), farther + _sweep(0.23, 1), _sweep(0.10, 3)]
    return need, [_sweep(0.10, 2)]


def _probe(arm: ArmModel, goal: tuple, direction: tuple, collides: Collides
           ) -> tuple[int, float, np.ndarray]:
    """Run the default reach: (-1 when a needed path fails or a configuration on it
    collides, else how many of the extra paths pass; the score; the start configuration)."""
    from ..lang.timeline import Pose
    from .geometry import reach_frame
    from .ik import solve_path

    frame = reach_frame(goal, direction)
    need, extra = _probe_paths()
    first = solve_path(arm, [frame.target(Pose(*p)) for p in need[0]])
    if not first.ok:
        return -1, 0.0, np.zeros(arm.n)
    qs, passed = [first.q], 0
    for k, path in enumerate(need[1:] + extra):
        res = solve_path(arm, [frame.target(Pose(*p)) for p in path], first.q[-1])
        ok = res.ok and not (collides and any(collides(q) for q in res.q[::2]))
        if ok:
            qs.append(res.q)
            passed += k >= len(need) - 1
        elif k < len(need) - 1:
            return -1, 0.0, first.q[0]
    if collides and any(collides(q) for q in first.q[::2]):
        return -1, 0.0, first.q[0]
    return passed, _score(arm, np.vstack(qs)), first.q[0]


def _score(arm: ArmModel, q_all: np.ndarray) -> float:
    """Distance from limits (fraction of each range) times distance from singularities
    (the smallest singular value of the pose Jacobian, saturating at 0.1), at worst."""
    if np.any(_origins_low(arm, q_all)):
        return 0.0
    span = arm.upper - arm.lower
    room = float(np.min(np.minimum(q_all - arm.lower, arm.upper - q_all) / span))
    sigma = min(float(np.linalg.svd(_local(arm.model, q, arm.frame_id)[1],
                                    compute_uv=False)[-1]) for q in q_all[::3])
    return max(0.0, room) * min(sigma, 0.1) / 0.1


def _origins_low(arm: ArmModel, q_all: np.ndarray) -> list[bool]:
    return [bool(np.any(_origins(arm, q)[2:, 2] < TABLE_CLEARANCE)) for q in q_all[::3]]


def _pool(arm: ArmModel, posture: tuple[float, ...] | None) -> np.ndarray:
    """Configurations spread over the joint ranges (the middle first), shape (K, n)."""
    if posture is not None:
        return np.asarray([posture], float)
    mid = (arm.lower + arm.upper) / 2
    wide = arm.upper - arm.lower > 2 * math.pi  # one turn around the middle is enough
    lo = np.where(wide, mid - math.pi, arm.lower + arm.spec.limit_margin)
    hi = np.where(wide, mid + math.pi, arm.upper - arm.spec.limit_margin)
    rng = np.random.default_rng(0)
    return np.vstack([(lo + hi) / 2, rng.uniform(lo, hi, size=(POOL - 1, arm.n))])


def _seeds(arm: ArmModel, pool: np.ndarray, goal: tuple, direction: tuple
           ) -> list[np.ndarray]:
    """The :data:`SEEDS` configurations of ``pool`` whose hand is nearest the start pose
    of the reach (position, and orientation at 0.3 m per rad), every joint origin above
    the table."""
    from ..lang.timeline import Pose
    from .geometry import reach_frame

    if len(pool) <= SEEDS:
        return list(pool)
    p, r = reach_frame(goal, direction).target(Pose(0.30))
    pos, rot = arm.fk(pool)
    cos = (np.einsum("kij,ij->k", rot, r) - 1.0) / 2.0
    cost = np.linalg.norm(pos - p, axis=1) + 0.3 * np.arccos(np.clip(cos, -1.0, 1.0))
    cost[[bool(np.any(_origins(arm, q)[2:, 2] < TABLE_CLEARANCE)) for q in pool]] = np.inf
    return [pool[i] for i in np.argsort(cost, kind="stable")[:SEEDS]]


def find_reach(arm: ArmModel, goal: tuple[float, float, float] | None = None,
               start_direction: tuple[float, float, float] | None = None,
               posture: tuple[float, ...] | None = None, collides: Collides = None,
               budget: Budget | None = None) -> Reach:
    """The default reach of ``arm`` (see the module's docstring); pinned values are kept.

    ``arm`` is the robot with its limits; its ``spec.posture`` is ignored. ``collides``
    tells a configuration that touches itself or the table (None: joint origins must stay
    above the table instead). ``budget`` bounds the reaches tried (shared by the calls
    of one robot's search).
    """
    budget = budget or Budget()
    pool = _pool(arm, posture)
    goals = [goal] if goal is not None else _goals(arm, pool[0])
    dirs = [start_direction] if start_direction is not None else list(DIRECTIONS)
    if arm.n < 6:
        return Reach(goals[0], dirs[0], tuple(float(x) for x in pool[0]), False, 0.0,
                     f"not searched: {arm.n} arm joints cannot hold the position, the "
                     "line of sight and the roll of the hand at once (6 are needed)")
    best = _grid(arm, pool, goals, dirs, collides, budget)
    if best is None and goal is None and start_direction is None:
        best = _from_pool(arm, pool, collides, budget)
    if best is None:
        return Reach(goals[0], dirs[0], tuple(float(x) for x in pool[0]), False, 0.0,
                     "derived: no goal, direction and seed tried passes the default reach")
    passed, score, q0, g, u = best
    vertical = "" if passed == 1 else " (not the vertical gazes)"
    return Reach(g, u, tuple(round(float(x), 4) for x in q0), True, score,
                 f"derived: the default reach{vertical} passes from this posture "
                 f"(score {score:.3f} of 1)")


_Best = tuple[int, float, np.ndarray, tuple, tuple]


def _grid(arm: ArmModel, pool: np.ndarray, goals: list, dirs: list, collides: Collides,
          budget: Budget) -> _Best | None:
    """The best reach over the goals and directions, stopping at the first goal and
    direction where every path passes."""
    best: _Best | None = None
    for g in goals:
        for u in dirs:
            for seed in _seeds(arm, pool, g, u):
                if not budget.take():
                    return best
                trial = replace(arm, spec=replace(arm.spec, posture=tuple(seed)))
                passed, score, q0 = _probe(trial, g, u, collides)
                if passed >= 0 and (best is None or (passed, score) > best[:2]):
                    best = (passed, score, q0, g, u)
            if best is not None and best[0] == 1:  # every path passes: take this reach
                return best
    return best


def _from_pool(arm: ArmModel, pool: np.ndarray, collides: Collides, budget: Budget
               ) -> _Best | None:
    """For an arm whose front is not +x, or whose reach the grid misses: reaches read
    off the pool's configurations, each looking down at a goal 0.30 m ahead of its hand
    (at least 8 cm above the table), tried from that very configuration."""
    pos, rot = arm.fk(pool)
    best: _Best | None = None
    tried = 0
    for q, p, r in zip(pool, pos, rot, strict=True):
        f = r[:, 2]
        g = p + 0.30 * f
        if g[2] < 0.08 or f[2] > -0.1 or (collides is not None and collides(q)):
            continue
        if not budget.take():
            break
        goal = tuple(round(float(c), 3) for c in g)
        u = tuple(round(float(c), 3) for c in -f)
        trial = replace(arm, spec=replace(arm.spec, posture=tuple(q)))
        passed, score, q0 = _probe(trial, goal, u, collides)
        if passed >= 0 and (best is None or (passed, score) > best[:2]):
            best = (passed, score, q0, goal, u)
        tried += 1
        if tried >= POOL_REACHES or (best is not None and best[0] == 1):
            break
    return best
