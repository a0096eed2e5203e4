"""Generators of valid `.aou` files over the whole surface language, each with the
descriptors it declares, computed here from the language contract and the model's
definitions (never from the compiler).

Two front ends share one generator:

- ``aou_cases()``: a Hypothesis strategy of :class:`Case` (shrinks well, for property tests);
- ``random_case(rng)`` / ``random_cases(n, seed)``: plain seeded ``random`` for bulk runs.

Canonical units of an expectation (the model's descriptor table): m/s^2, count, s, m, deg,
deg/s. A descriptor the file does not express is ``None``.

Where the contracts leave a case open, the case is still generated, but the descriptor is
listed in ``Expectation.uncertain`` with the reason; a disagreement on it is reported as
uncertain rather than as a failure.
"""

from __future__ import annotations

import math
import random
import statistics
from dataclasses import dataclass, field
from decimal import Decimal
from typing import Any

from hypothesis import strategies as st

DESCRIPTORS = (
    "approach_acceleration",
    "pause_count",
    "pause_duration",
    "retreat_count",
    "retreat_distance",
    "retreat_acceleration",
    "horizontal_gaze",
    "vertical_gaze",
    "tilt_angle",
    "tilt_velocity",
    "shiver_amplitude",
)
COUNTS = ("pause_count", "retreat_count")
STATES = ("confident", "curious", "hesitant", "fearful", "inactive")

# Documented defaults (the language leaves these to the project's documentation).
DEFAULT_ACCEL = 0.1  # m/s^2, approach and retreat
DEFAULT_ANG_SPEED = 20.0  # deg/s, gaze and tilt
DEFAULT_SHIVER_F = 2.5  # Hz
DEFAULT_SHIVER_FOR = 1.0  # s
DEFAULT_START = 0.30
DEFAULT_STANDOFF = 0.10
ROBOT_GOALS = {"panda": (0.55, 0.0, 0.25), "ur5": (0.45, 0.15, 0.15)}

# unit name -> factor to the canonical unit of its dimension
UNITS: dict[str, dict[str, float]] = {
    "length": {"m": 1.0, "cm": 0.01, "mm": 0.001},
    "duration": {"s": 1.0, "ms": 0.001},
    "angle": {"deg": 1.0, "rad": 180.0 / math.pi},
    "accel": {"m/s^2": 1.0, "cm/s^2": 0.01, "mm/s^2": 0.001},
    "speed": {"m/s": 1.0, "cm/s": 0.01, "mm/s": 0.001},
    "angspeed": {"deg/s": 1.0, "rad/s": 180.0 / math.pi},
    "freq": {"Hz": 1.0},
}
# A bare keyword value takes the contract's unit: SI, except angular speeds (deg/s).
BARE_UNIT = {"accel": "m/s^2", "speed": "m/s", "angspeed": "deg/s", "freq": "Hz"}
UNIT_WEIGHTS = {
    "length": {"m": 5, "cm": 3, "mm": 2},
    "duration": {"s": 4, "ms": 2},
    "angle": {"deg": 4, "rad": 2},
    "accel": {"m/s^2": 4, "cm/s^2": 2, "mm/s^2": 1},
    "speed": {"m/s": 4, "cm/s": 2, "mm/s": 1},
    "angspeed": {"deg/s": 4, "rad/s": 2},
    "freq": {"Hz": 1},
}


@dataclass
class Expectation:
    """The eleven descriptors a file declares, with the descriptors the contracts leave open."""

    values: dict[str, float | int | None]
    uncertain: dict[str, str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        return {"values": self.values, "uncertain": self.uncertain, "notes": self.notes}


@dataclass
class Case:
    """One generated file: its text, the stem it must be saved under, its expectation."""

    stem: str
    text: str
    expectation: Expectation
    robot: str
    form: str
    features: set[str] = field(default_factory=set)


# --------------------------------------------------------------------------------------
# choosers: one interface over `random.Random` and Hypothesis' `draw`


class RandomChooser:
    """Random choices from a seeded ``random.Random``."""

    def __init__(self, rng: random.Random):
        self.rng = rng

    def integer(self, lo: int, hi: int) -> int:
        return self.rng.randint(lo, hi)

    def choice(self, seq):
        return seq[self.rng.randrange(len(seq))]

    def uniform(self, lo: float, hi: float) -> float:
        return self.rng.uniform(lo, hi)

    def chance(self, p: float) -> bool:
        return self.rng.random() < p


class DrawChooser:
    """The same choices drawn through Hypothesis, so that failures shrink."""

    def __init__(self, draw):
        self.draw = draw

    def integer(self, lo: int, hi: int) -> int:
        return self.draw(st.integers(lo, hi))

    def choice(self, seq):
        return seq[self.draw(st.integers(0, len(seq) - 1))]

    def uniform(self, lo: float, hi: float) -> float:
        k = self.draw(st.integers(0, 1000))
        return lo + (hi - lo) * k / 1000.0

    def chance(self, p: float) -> bool:
        return self.draw(st.integers(0, 999)) < int(p * 1000)


def _weighted(ch, weights: dict[str, int]) -> str:
    names = [n for n, w in weights.items() for _ in range(w)]
    return ch.choice(names)


# --------------------------------------------------------------------------------------
# quantities


def _fmt_number(x: float, sig: int, ch, feats: set[str], sign: bool) -> str:
    """A decimal rendering of x with `sig` significant digits, sometimes with an exponent."""
    if x == 0:
        return "0"
    d = Decimal(repr(x))
    q = round(d, sig - 1 - d.adjusted())
    text = format(q.normalize(), "f")
    if ch.chance(0.06):
        mant, exp = f"{float(text):e}".split("e")
        mant = mant.rstrip("0").rstrip(".")
        text = f"{mant}e{int(exp)}"
        feats.add("unit:exponent")
    if sign and not text.startswith("-") and ch.chance(0.05):
        text = "+" + text
        feats.add("sign:plus")
    return text


def quantity(
    ch,
    value: float,
    dim: str,
    feats: set[str],
    *,
    bare_ok: bool = False,
    sig: int = 3,
    sign: bool = True,
) -> tuple[str, float]:
    """Render `value` (canonical unit of `dim`) with a random unit; return (text, value read).

    The returned value is the one the written text means, so the expectation follows the
    file exactly whatever the rounding.
    """
    if bare_ok and ch.chance(0.25):
        unit = ""
        factor = UNITS[dim][BARE_UNIT[dim]]
        feats.add(f"bare:{dim}")
    else:
        unit = _weighted(ch, UNIT_WEIGHTS[dim])
        factor = UNITS[dim][unit]
        feats.add(f"unit:{unit}")
    shown = value / factor
    s = 4 if unit == "rad" or unit == "rad/s" else sig
    text = _fmt_number(shown, s, ch, feats, sign)
    return text + unit, float(text) * factor


# --------------------------------------------------------------------------------------
# settings and header


@dataclass
class _Settings:
    robot: str = "panda"
    start: float = DEFAULT_START
    standoff: float = DEFAULT_STANDOFF
    lines: list[str] = field(default_factory=list)


def _robot(ch) -> str | None:
    """The robot line's name, or None for no line (panda)."""
    return ch.choice(["panda", "panda", "ur5"]) if ch.chance(0.55) else None


def _settings(ch, feats: set[str], robot: str | None, *, min_span: float) -> _Settings:
    s = _Settings()
    if robot:
        s.robot = robot
        s.lines.append(f"robot {s.robot}")
        feats.add(f"setting:robot-{s.robot}")
    else:
        feats.add("setting:robot-default")
    if ch.chance(0.25):
        gx, gy, gz = ROBOT_GOALS[s.robot]
        g = [gx + ch.uniform(-0.04, 0.04), gy + ch.uniform(-0.04, 0.04),
             gz + ch.uniform(-0.03, 0.04)]
        parts = [f"{v:.3f}".rstrip("0").rstrip(".") for v in g]
        if ch.chance(0.3):
            parts[ch.integer(0, 2)] += "m"
        s.lines.append(f"goal ({', '.join(parts)})")
        feats.add("setting:goal")
    if ch.chance(0.25):
        base = ch.choice([(-0.6, 0.0, 0.8), (-3, 0, 4), (-0.55, 0.1, 0.83), (-0.65, -0.1, 0.75)])
        s.lines.append("from (" + ", ".join(f"{v:g}" for v in base) + ")")
        feats.add("setting:from")
    if ch.chance(0.35):
        text, s.start = quantity(ch, ch.uniform(0.26, 0.36), "length", feats, sign=False)
        s.lines.append(f"start {text}")
        feats.add("setting:start")
    if ch.chance(0.35):
        text, s.standoff = quantity(ch, ch.uniform(0.08, 0.12), "length", feats, sign=False)
        s.lines.append(f"standoff {text}")
        feats.add("setting:standoff")
    if s.start - s.standoff < min_span:
        # keep the reach long enough for the primitives; drop the user's start line
        s.lines = [x for x in s.lines if not x.startswith("start ")]
        s.start = max(DEFAULT_START, s.standoff + min_span)
        s.lines.append(f"start {s.start:.3f}m")
    if ch.chance(0.2):
        vals = [ch.choice(["-1", "-0.5", "0", "0.5", "1", "0.25", "-0.75"]) for _ in range(4)]
        s.lines.append("effort " + " ".join(f"{k}={v}" for k, v in zip("WTSF", vals, strict=True)))
        feats.add("setting:effort")
    return s


def _header(ch, feats: set[str]) -> list[str]:
    if not ch.chance(0.6):
        feats.add("header:none")
        return []
    name = ch.choice(["probe", "Peek_2", "_shy", "hesitant-a", "x", "reach_it-3"])
    if ch.chance(0.7):
        feats.add("header:state")
        return [f"behaviour {name} : {ch.choice(STATES)}"]
    feats.add("header:nostate")
    return [f"behaviour {name}"]


def _count(ch, feats: set[str], n: int, *, explicit: float = 0.15) -> str:
    if n == 1 and not ch.chance(explicit):
        return ""
    feats.add("count:x0" if n == 0 else ("count:x1" if n == 1 else "count:xN"))
    return f" x{n}"


# --------------------------------------------------------------------------------------
# the descriptor form


def _descriptor_counts(ch) -> tuple[dict[str, bool], dict[str, int]]:
    """Which kinds are written and how many episodes each has (0 when written `x0`)."""
    kinds = {
        "approach": ch.chance(0.8),
        "pause": ch.chance(0.85),
        "retreat": ch.chance(0.4),
        "gaze-h": ch.chance(0.3),
        "gaze-v": ch.chance(0.25),
        "tilt": ch.chance(0.25),
        "shiver": ch.chance(0.25),
    }
    if not any(kinds.values()):
        kinds["pause"] = True
    top = {"pause": 5, "retreat": 3, "gaze-h": 2, "gaze-v": 2, "tilt": 2, "shiver": 2}
    n = {"approach": int(kinds["approach"])}
    for k, hi in top.items():
        n[k] = ch.integer(1, hi) if kinds[k] and not ch.chance(0.05) else 0
    # realisability under the model: each retreat starts and ends at a pause, a gaze is
    # read at a pause that ends it, and two pauses need a motion between them. A pause
    # that ends a retreat cannot also end a gaze (the retreat would not end at a pause),
    # so each gaze plane needs a pause of its own.
    planes = (n["gaze-h"] > 0) + (n["gaze-v"] > 0)
    need = max(n["retreat"] + 1 if n["retreat"] else 0, n["retreat"] + planes)
    if not kinds["approach"]:
        motions = n["retreat"] + n["gaze-h"] + n["gaze-v"] + n["tilt"] + n["shiver"]
        n["pause"] = min(n["pause"], motions + 1)
    n["pause"] = max(n["pause"], need)
    if not kinds["approach"] and not any(n[k] for k in top):
        n["pause"] = 1  # a behaviour that does something
    kinds["pause"] = kinds["pause"] or n["pause"] > 0
    return kinds, n


def _accel_key(ch, feats: set[str], bases: list[float], p: float = 0.8) -> tuple[str, float]:
    """An ` a=...` key (or nothing: the documented default) and the value it means."""
    if not ch.chance(p):
        return "", DEFAULT_ACCEL
    t, acc = quantity(ch, ch.choice(bases) * ch.uniform(0.8, 1.2), "accel", feats,
                      bare_ok=True, sign=False)
    return f" a={t}", acc


def _speed_cap(ch, feats: set[str], p: float) -> str:
    if not ch.chance(p):
        return ""
    feats.add("cap:v")
    t, _ = quantity(ch, ch.uniform(0.1, 0.3), "speed", feats, bare_ok=True, sign=False)
    return f" v={t}"


def _ang_speed_key(ch, feats: set[str], p: float) -> str:
    if not ch.chance(p):
        return ""
    t, _ = quantity(ch, ch.uniform(10, 40), "angspeed", feats, bare_ok=True, sign=False)
    return f" v={t}"


def _tilt_stmt(ch, feats: set[str], angle: float) -> tuple[str, float, float]:
    """`tilt ANGLE [v=]`; a tilt lasts at least 0.7 s: a slow roll, not a tremor's half
    cycle. Returns the text, the angle and the velocity it declares."""
    t, ang = quantity(ch, angle, "angle", feats, sign=angle > 0)
    text, vel = f"tilt {t}", DEFAULT_ANG_SPEED
    if ch.chance(0.7) or abs(ang) / DEFAULT_ANG_SPEED < 0.7:
        t, vel = quantity(ch, ch.uniform(5, min(40.0, abs(ang) / 0.7)), "angspeed", feats,
                          bare_ok=True, sign=False)
        text += f" v={t}"
    feats.add("prim:tilt")
    return text, ang, vel


def _descriptor_form(ch, feats: set[str], robot: str) -> tuple[list[str], Expectation, float]:
    """Top-level primitives; returns statements, expectation and the minimal reach span."""
    vals: dict[str, Any] = dict.fromkeys(DESCRIPTORS)
    vals["pause_count"] = vals["retreat_count"] = 0
    stmts: list[str] = []
    kinds, n = _descriptor_counts(ch)
    if kinds["approach"]:
        feats.add("prim:approach")
        key, acc = _accel_key(ch, feats, [0.05, 0.09, 0.1, 0.2, 0.5, 1.0], 0.85)
        stmts.append("approach" + key + _speed_cap(ch, feats, 0.3))
        vals["approach_acceleration"] = acc
    else:
        feats.add("no-approach")
    if kinds["pause"]:
        feats.add("prim:pause")
        t, dur = quantity(ch, ch.uniform(0.3, 2.0), "duration", feats, sign=False)
        stmts.append(f"pause {t}" + _count(ch, feats, n["pause"]))
        vals["pause_count"] = n["pause"]
        vals["pause_duration"] = dur if n["pause"] else None
    if kinds["retreat"]:
        feats.add("prim:retreat")
        t, dist = quantity(ch, ch.uniform(0.02, 0.08), "length", feats, sign=False)
        key, acc = _accel_key(ch, feats, [0.1, 0.12, 0.3, 1.0, 2.0])
        stmts.append(f"retreat {t}{key}" + _count(ch, feats, n["retreat"]))
        vals["retreat_count"] = n["retreat"]
        if n["retreat"]:
            vals["retreat_distance"], vals["retreat_acceleration"] = dist, acc
    for kind, name, plane in (("gaze-h", "horizontal_gaze", "horizontal"),
                              ("gaze-v", "vertical_gaze", "vertical")):
        if kinds[kind]:
            feats.add(f"prim:{kind}")
            t, ang = quantity(ch, ch.uniform(5, 30), "angle", feats, sign=False)
            stmts.append(f"gaze {plane} {t}" + _ang_speed_key(ch, feats, 0.4)
                         + _count(ch, feats, n[kind]))
            vals[name] = ang if n[kind] else None
    if kinds["tilt"]:
        text, ang, vel = _tilt_stmt(ch, feats, ch.uniform(8, 45))
        stmts.append(text + _count(ch, feats, n["tilt"]))
        if n["tilt"]:
            vals["tilt_angle"], vals["tilt_velocity"] = ang, vel
    if kinds["shiver"]:
        feats.add("prim:shiver")
        text, amp = _shiver_stmt(ch, feats, robot)
        stmts.append(text + _count(ch, feats, n["shiver"]))
        vals["shiver_amplitude"] = amp if n["shiver"] else None
    order = list(range(len(stmts)))
    for i in range(len(order) - 1, 0, -1):
        j = ch.integer(0, i)
        order[i], order[j] = order[j], order[i]
    span = 0.12 if kinds["approach"] else 0.0
    return [stmts[i] for i in order], Expectation(vals), span


def _shiver_stmt(ch, feats: set[str], robot: str) -> tuple[str, float]:
    """A tremor within the wrist's acceleration: amplitude * f^2 bounded per robot."""
    if robot == "ur5":  # a slower wrist: a few degrees at about 1 Hz
        amp0 = ch.uniform(1.5, 4.0)
        f0 = ch.uniform(1.0, min(1.4, math.sqrt(7.5 / amp0)))
    else:
        amp0 = ch.uniform(2.0, 8.0)
        f0 = ch.uniform(1.5, min(3.0, math.sqrt(45.0 / amp0)))
    t, amp = quantity(ch, amp0, "angle", feats, sign=False)
    parts = ["shiver", t]
    f = DEFAULT_SHIVER_F
    if ch.chance(0.6) or robot == "ur5" or amp * f * f > 45.0:
        t, f = quantity(ch, f0, "freq", feats, bare_ok=True, sign=False)
        parts.append(f"f={t}")
    if ch.chance(0.6) or 2.0 / f > DEFAULT_SHIVER_FOR:
        # at least two periods: a fast oscillation is told from a tilt by its reversals
        t, _ = quantity(ch, max(2.0 / f, ch.uniform(0.8, 1.6)) * 1.05, "duration", feats,
                        sign=False)
        parts.append(f"for {t}")
    return " ".join(parts), amp


# --------------------------------------------------------------------------------------
# the sequence form


@dataclass
class _Ev:
    kind: str  # pause radial gaze-h gaze-v tilt shiver
    value: float = 0.0  # duration s, radial change m (+ = away), bearing deg, roll deg, amp
    acc: float | None = None
    vel: float | None = None


@dataclass
class _Seq:
    """The pose a sequence has reached while it is written."""

    s: _Settings
    d: float
    h: float = 0.0  # bearings (deg) from the initial line of sight
    v: float = 0.0
    roll: float = 0.0
    events: list[_Ev] = field(default_factory=list)
    lines: list[str] = field(default_factory=list)


def _seq_count(ch, kind: str) -> int:
    if ch.chance(0.06):
        return 0
    if kind in ("tilt", "shiver", "approach", "retreat", "approach-neg") and ch.chance(0.1):
        return 2
    return 1


def _seq_radial(ch, feats: set[str], q: _Seq, kind: str, cnt: int) -> str:
    """`approach L`, `approach -L` or `retreat L` (rarely `retreat -L`)."""
    room_in = q.d - q.s.standoff - 0.005
    room_out = q.s.start + 0.2 - q.d
    word = "retreat" if kind == "retreat" else "approach"
    if kind == "approach":
        written = ch.uniform(0.01, min(0.1, room_in / max(cnt, 1)))
    elif kind == "retreat" and ch.chance(0.08) and room_in > 0.025:
        written = -ch.uniform(0.01, min(0.05, room_in / max(cnt, 1)))  # toward the goal
    else:
        written = ch.uniform(0.01, min(0.08, room_out / max(cnt, 1)))
        written = -written if word == "approach" else written
    t, lval = quantity(ch, written, "length", feats)
    if lval < 0:
        feats.add(f"sign:negative-{word}")
    feats.add(f"prim:{word}")
    key, acc = _accel_key(ch, feats, [0.05, 0.1, 0.2, 0.5, 1.5])
    cap = _speed_cap(ch, feats, 0.2) if word == "approach" else ""
    radial = -lval if word == "approach" else lval  # + = away from the goal
    for _ in range(cnt):
        q.events.append(_Ev("radial", radial, acc=acc))
        q.d += radial
    return f"{word} {t}{key}{cap}"


def _seq_rest_of_way(ch, feats: set[str], q: _Seq, cnt: int) -> str:
    key, acc = _accel_key(ch, feats, [0.05, 0.1, 0.3])
    feats.update({"prim:approach", "approach:rest-of-way"})
    if cnt:
        q.events.append(_Ev("radial", q.s.standoff - q.d, acc=acc))
        q.d = q.s.standoff
    return "approach" + key


def _seq_gaze(ch, feats: set[str], q: _Seq, kind: str, cnt: int) -> str:
    cur = q.h if kind == "gaze-h" else q.v
    target = ch.uniform(-30, 30)
    if ch.chance(0.1) and abs(cur) > 3:
        target = 0.0
    # A gaze must move the hand at least 5 mm (an arc of 4 deg at the closest stand-off).
    if abs(target - cur) < 4:
        target = cur + (6 if cur < 0 else -6)
    t, ang = quantity(ch, target, "angle", feats)
    if ang < 0:
        feats.add("sign:negative-gaze")
    feats.add(f"prim:{kind}")
    if cnt:
        if kind == "gaze-h":
            q.h = ang
        else:
            q.v = ang
        q.events.append(_Ev(kind, ang))
    plane = "horizontal" if kind == "gaze-h" else "vertical"
    return f"gaze {plane} {t}" + _ang_speed_key(ch, feats, 0.35)


def _seq_tilt(ch, feats: set[str], q: _Seq, cnt: int) -> str:
    mag = ch.uniform(8, 40)
    sign = -1.0 if q.roll > 0 and ch.chance(0.7) else (1.0 if ch.chance(0.6) else -1.0)
    if abs(q.roll + sign * mag * cnt) > 60:
        sign = -sign
    text, ang, vel = _tilt_stmt(ch, feats, sign * mag)
    if ang < 0:
        feats.add("sign:negative-tilt")
    for _ in range(cnt):
        q.events.append(_Ev("tilt", ang, vel=vel))
        q.roll += ang
    return text


def _seq_kind(ch, q: _Seq) -> str:
    pool = (["approach"] * 4 + ["approach-rest"] * 2 + ["approach-neg"] + ["retreat"] * 3
            + ["gaze-h"] * 3 + ["gaze-v"] * 2 + ["tilt"] * 2 + ["shiver"] * 2)
    kind = ch.choice(pool)
    if kind == "approach-rest" and q.d - q.s.standoff < 0.01:
        kind = "retreat"
    if kind == "approach" and q.d - q.s.standoff < 0.025:
        kind = "approach-neg"
    if kind in ("retreat", "approach-neg") and q.d > q.s.start + 0.15:
        kind = "approach-rest"
    return kind


def _sequence_form(ch, feats: set[str], s: _Settings) -> tuple[list[str], Expectation]:
    """A `sequence { }` block; the expectation follows the settled aggregation rules."""
    q = _Seq(s, s.start)
    if ch.chance(0.3):
        q.lines.append(_seq_pause(ch, feats, q.events, 1))
    for _ in range(ch.integer(2, 9)):
        kind = _seq_kind(ch, q)
        cnt = _seq_count(ch, kind)
        if kind in ("approach", "approach-neg", "retreat"):
            text = _seq_radial(ch, feats, q, kind, cnt)
        elif kind == "approach-rest":
            cnt = min(cnt, 1)
            text = _seq_rest_of_way(ch, feats, q, cnt)
        elif kind in ("gaze-h", "gaze-v"):
            cnt = min(cnt, 1)
            text = _seq_gaze(ch, feats, q, kind, cnt)
        elif kind == "tilt":
            text = _seq_tilt(ch, feats, q, cnt)
        else:
            text, amp = _shiver_stmt(ch, feats, s.robot)
            feats.add("prim:shiver")
            q.events.extend(_Ev("shiver", amp) for _ in range(cnt))
        q.lines.append(text + _count(ch, feats, cnt))
        if ch.chance(0.55):
            n_p = ch.choice([0, 2]) if ch.chance(0.08) else 1
            q.lines.append(_seq_pause(ch, feats, q.events, n_p))
    if "prim:approach" not in feats:
        feats.add("no-approach")
    return q.lines, _sequence_expectation(q.events)


def _seq_pause(ch, feats: set[str], events: list[_Ev], n: int) -> str:
    t, dur = quantity(ch, ch.uniform(0.3, 2.0), "duration", feats, sign=False)
    feats.add("prim:pause")
    for _ in range(n):
        events.append(_Ev("pause", dur))
    return f"pause {t}" + _count(ch, feats, n, explicit=0.05)


# --------------------------------------------------------------------------------------
# the settled rules over a sequence's episodes


def _split(events: list[_Ev]) -> tuple[list[float], list[tuple[list[_Ev], bool, bool]]]:
    """Pauses (those touching read as one, durations summed) and the runs of motion
    between them, each with whether a pause starts it and one ends it."""
    pauses: list[float] = []
    segs: list[tuple[list[_Ev], bool, bool]] = []
    cur: list[_Ev] = []
    start_pause = prev_pause = False
    for ev in events:
        if ev.kind != "pause":
            if not cur:
                start_pause = prev_pause
            cur.append(ev)
            prev_pause = False
        elif prev_pause:
            pauses[-1] += ev.value
        else:
            pauses.append(ev.value)
            if cur:
                segs.append((cur, start_pause, True))
            cur, prev_pause = [], True
    if cur:
        segs.append((cur, start_pause, False))
    return pauses, segs


def _retreat_rules(segs, vals: dict[str, Any], unc: dict[str, str], notes: list[str]) -> None:
    counted: list[_Ev] = []
    loose_away = False
    for seg, b0, b1 in segs:
        away = [e for e in seg if e.kind == "radial" and e.value > 0]
        if len(seg) == 1 and away and b0 and b1:
            counted.append(seg[0])
        elif away:  # settled: each move away must itself start and end at a pause
            loose_away = True
    vals["retreat_count"] = len(counted)
    if counted:
        vals["retreat_distance"] = statistics.median(e.value for e in counted)
        vals["retreat_acceleration"] = max(e.acc or 0.0 for e in counted)
    if loose_away:  # settled: the peak is over the retreats that count
        notes.append("a move away that does not start and end at a pause is not a retreat")


def _gaze_rules(events: list[_Ev], vals: dict[str, Any], unc: dict[str, str]) -> None:
    ended = [ev for ev, nxt in zip(events, events[1:], strict=False)
             if ev.kind in ("gaze-h", "gaze-v") and nxt.kind == "pause"]
    for plane, name in (("gaze-h", "horizontal_gaze"), ("gaze-v", "vertical_gaze")):
        # settled: a plane is read at the pauses that end a gaze in that plane, as a
        # bearing from the initial line of sight
        own = [abs(ev.value) for ev in ended if ev.kind == plane]
        if own:
            vals[name] = max(own)



def _roll_rules(events: list[_Ev], vals: dict[str, Any], unc: dict[str, str]) -> None:
    tilts = [e for e in events if e.kind == "tilt"]
    if tilts:
        vals["tilt_angle"] = statistics.median(abs(e.value) for e in tilts)
        vals["tilt_velocity"] = statistics.median(e.vel or 0.0 for e in tilts)
    shivers = [e.value for e in events if e.kind == "shiver"]
    if shivers:
        vals["shiver_amplitude"] = max(shivers)
    # rolls next to each other without a pause or another motion between: one tilt or
    # several, a tilt or part of a tremor? the trajectory alone cannot tell
    why = "two roll motions in a row with no pause: episode boundaries not settled"
    for a, b in zip(events, events[1:], strict=False):
        pair = {a.kind, b.kind}
        if "tilt" in pair and pair <= {"tilt", "shiver"}:
            unc["tilt_angle"] = unc["tilt_velocity"] = why
            if "shiver" in pair:
                unc["shiver_amplitude"] = why


def _sequence_expectation(events: list[_Ev]) -> Expectation:
    """The settled rules over episodes of unequal size, as the model's definitions state:
    counts are numbers of episodes, medians for durations, distances and tilts, maxima for
    peaks, gazes the largest bearing at a pause that ends a gaze."""
    vals: dict[str, Any] = dict.fromkeys(DESCRIPTORS)
    unc: dict[str, str] = {}
    notes: list[str] = []
    pauses, segs = _split(events)
    vals["pause_count"] = len(pauses)
    if pauses:
        vals["pause_duration"] = statistics.median(pauses)
    approach_acc = [e.acc or 0.0 for e in events if e.kind == "radial" and e.value < 0]
    if approach_acc:
        vals["approach_acceleration"] = max(approach_acc)
    _retreat_rules(segs, vals, unc, notes)
    _gaze_rules(events, vals, unc)
    _roll_rules(events, vals, unc)
    return Expectation(vals, unc, notes)


# --------------------------------------------------------------------------------------
# assembling a file


def build_case(ch, index: int = 0) -> Case:
    """One valid file, with its expectation and the grammar features it uses."""
    feats: set[str] = set()
    form = "sequence" if ch.chance(0.5) else "descriptor"
    feats.add(f"form:{form}")
    header = _header(ch, feats)
    robot = _robot(ch)
    if form == "descriptor":
        prims, exp, span = _descriptor_form(ch, feats, robot or "panda")
        settings = _settings(ch, feats, robot, min_span=max(span, 0.05))
        body = prims
    else:
        settings = _settings(ch, feats, robot, min_span=0.12)
        prims, exp = _sequence_form(ch, feats, settings)
        inner = _join(ch, feats, ["  " + p for p in prims])
        body = ["sequence {", *inner, "}"]
    setting_lines = settings.lines
    before = [x for x in setting_lines if ch.chance(0.7)]
    after = [x for x in setting_lines if x not in before]
    lines: list[str] = []
    if ch.chance(0.35):
        lines.append("# generated from the language contract")
        feats.add("comment")
    lines += header
    top = _join(ch, feats, before)
    if form == "descriptor":
        lines += _join(ch, feats, before + body + after)
    else:
        lines += top + body + _join(ch, feats, after)
    if ch.chance(0.25):
        i = ch.integer(0, len(lines) - 1)
        if not lines[i].rstrip().endswith("{"):
            lines[i] += "   # a trailing comment"
            feats.add("comment")
    if ch.chance(0.15):
        lines.insert(ch.integer(0, len(lines)), "")
    text = "\n".join(lines) + "\n"
    return Case(f"case_{index:05d}", text, exp, settings.robot, form, feats)


def _join(ch, feats: set[str], lines: list[str]) -> list[str]:
    """Sometimes put two statements on one line with `;`."""
    out: list[str] = []
    for line in lines:
        if out and ch.chance(0.15) and not out[-1].rstrip().endswith("{"):
            out[-1] = out[-1] + "; " + line.strip()
            feats.add("semicolon")
        else:
            out.append(line)
    return out


def random_case(rng: random.Random, index: int = 0) -> Case:
    """One case from a seeded ``random.Random``."""
    return build_case(RandomChooser(rng), index)


def random_cases(n: int, seed: int = 0) -> list[Case]:
    """`n` cases, deterministic for a given seed."""
    rng = random.Random(seed)
    return [random_case(rng, i) for i in range(n)]


@st.composite
def aou_cases(draw) -> Case:
    """Hypothesis strategy of valid files with their expectations."""
    return build_case(DrawChooser(draw))
