"""Hostile inputs, written from what aou promises about what it reads (README, docs/
measure.md, docs/robots.md, docs/language.md), not from its code.

The promises: every failure is a diagnostic with a code and a location; exit 1 for an
input with errors, 2 for usage or I/O problems; no traceback; nothing hangs; a file is
read only when it is a regular file, and only up to a bound that a diagnostic names;
inputs are never changed. Each generator returns cases: a name, the files to make (name
-> bytes, or a special kind) and the command to run on them.
"""

from __future__ import annotations

import io
import json
import math
import random
import struct
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

PANDA = tuple(f"panda_joint{i}" for i in range(1, 8))
#: The Panda's home posture [rad] (docs/robots.md): inside every joint's limits.
HOME = (0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785)
GOAL = (0.55, 0.0, 0.25)


@dataclass
class Case:
    """One input and the command run on it. ``files``: name -> bytes, or ``"fifo"``,
    or ``"->TARGET"`` for a symbolic link. ``argv``: the command, ``{d}`` the folder the
    files are in. ``env``: extra environment (a bound lowered to keep the test small)."""

    name: str
    files: dict[str, bytes | str]
    argv: list[str]
    env: dict[str, str] = field(default_factory=dict)


def motion(n: int = 120, rate: float = 100.0, t0: float = 0.0, scale: float = 1.0
           ) -> tuple[np.ndarray, np.ndarray]:
    """A plausible Panda motion: ``n`` samples at ``rate`` Hz from ``t0`` [s] (times
    multiplied by ``scale``), joint 1 sweeping 0.3 rad and back."""
    t = t0 + np.arange(n) / rate
    q = np.tile(np.array(HOME), (n, 1))
    q[:, 0] += 0.3 * np.sin(np.pi * np.arange(n) / (n - 1)) ** 2
    return t * scale, q


def csv_bytes(t, q, *, goal: str | None = ",".join(map(str, GOAL)), robot="panda",
              names=PANDA, extra: str = "") -> bytes:
    head = f"# robot: {robot}\n" if robot else ""
    head += f"# goal: {goal}\n" if goal is not None else ""
    rows = "\n".join(",".join(repr(float(v)) for v in (ti, *qi))
                     for ti, qi in zip(t, q, strict=True))
    return (head + extra + "t," + ",".join(names) + "\n" + rows + "\n").encode()


def json_doc(t, q, **over) -> dict:
    doc = {"format": "aou-trajectory/1", "robot": "panda", "ee_frame": "panda_hand_tcp",
           "joint_names": list(PANDA),
           "goal": {"position": list(GOAL)}, "t": [float(x) for x in t],
           "q": [[float(v) for v in row] for row in q]}
    doc.update(over)
    return doc


def npy(array: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.lib.format.write_array(buf, array, allow_pickle=False)
    return buf.getvalue()


def npy_claiming(shape: tuple[int, ...], descr: str = "<f8", body: bytes = b"") -> bytes:
    """An .npy whose header claims ``shape`` of ``descr`` but holds only ``body``."""
    header = repr({"descr": descr, "fortran_order": False, "shape": shape}).encode()
    header += b" " * ((64 - (10 + len(header) + 1) % 64) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header + body


def npz_bytes(members: dict[str, bytes], *, method: int = zipfile.ZIP_DEFLATED,
              patch_method: int | None = None, encrypted: bool = False) -> bytes:
    """A zip of ``members``; ``patch_method`` rewrites each member's compression method
    (deflate64 is 9, AES 99) and ``encrypted`` sets each member's encryption flag."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", method) as zf:
        for name, data in members.items():
            zf.writestr(name, data)
    raw = bytearray(buf.getvalue())
    if patch_method is not None or encrypted:
        for sig, flag_at, method_at in ((b"PK\x03\x04", 6, 8), (b"PK\x01\x02", 8, 10)):
            at = raw.find(sig)
            while at >= 0:
                if patch_method is not None:
                    raw[at + method_at:at + method_at + 2] = struct.pack("<H", patch_method)
                if encrypted:
                    flags = struct.unpack_from("<H", raw, at + flag_at)[0] | 1
                    raw[at + flag_at:at + flag_at + 2] = struct.pack("<H", flags)
                at = raw.find(sig, at + 4)
    return bytes(raw)


def npz_of(t, q, header: dict | None = None, **members: bytes) -> bytes:
    h = header if header is not None else {k: v for k, v in json_doc(t, q).items()
                                           if k not in ("t", "q")}
    base = {"t.npy": npy(np.asarray(t)), "q.npy": npy(np.asarray(q)),
            "header.json": json.dumps(h).encode()}
    base.update({k.replace("_", "."): v for k, v in members.items()})
    return npz_bytes(base)


def _measure(name: str, ext: str = "") -> list[str]:
    return ["measure", "{d}/" + name + ext]


def recording_cases() -> list[Case]:
    """Recordings and trajectories that are malformed, of wrong types, or too large."""
    t, q = motion()
    jd = json_doc(t, q)
    out: list[Case] = []

    def add(name: str, data: bytes, ext: str, argv: list[str] | None = None, **env: str):
        out.append(Case(name, {name + ext: data}, argv or _measure(name, ext), env))

    for goal in ("0.5,0", "0.5,0,0.3,1", "nan,nan,nan", "inf,0,0", "1e308,1e308,1e308",
                 "a,b,c", "", ",,"):
        add(f"csv-goal-{goal or 'empty'}", csv_bytes(t, q, goal=goal), ".csv")
    add("csv-field-huge", csv_bytes(t, q, extra="x" * (200 * 1024) + "\n"), ".csv")
    add("csv-cell-huge", csv_bytes(t, q).replace(b"\n0.01,", b"\n0.01" + b"1" * 140_000
                                                  + b",", 1), ".csv")
    add("csv-unclosed-quote", csv_bytes(t, q).replace(b"\n0.05,", b'\n"0.05,', 1), ".csv")
    add("csv-t-huge", csv_bytes(t * 1e300, q), ".csv")
    with np.errstate(over="ignore", invalid="ignore"):  # times that are not finite
        add("csv-t-1e308", csv_bytes(np.linspace(-1e308, 1e308, len(t)), q), ".csv")
    add("csv-t-tiny-steps", csv_bytes(t * 1e-300, q), ".csv")
    add("csv-q-1e308", csv_bytes(t, np.full_like(q, 1e308)), ".csv")
    add("csv-q-huge-one", csv_bytes(t, q * np.where(np.arange(len(t))[:, None] == 5,
                                                      1e300, 1)), ".csv")
    add("csv-ms-times", csv_bytes(*motion(2000, 250.0, scale=1000.0)), ".csv",
        ["check", "{d}/csv-ms-times.csv"])
    add("csv-ms-measure", csv_bytes(*motion(2000, 250.0, scale=1000.0)), ".csv")
    add("csv-rows-over-bound", csv_bytes(*motion(400)), ".csv", None, AOU_MAX_SAMPLES="300")
    add("csv-bytes-over-bound", csv_bytes(*motion(400)), ".csv", None,
        AOU_MAX_INPUT_MB="0.01")
    add("csv-no-rows", b"# robot: panda\n", ".csv")
    add("csv-nul-bytes", b"\x00" * 5000, ".csv")
    add("csv-one-column", b"# robot: panda\nt\n0\n1\n2\n", ".csv")
    add("csv-wrong-robot-joints", csv_bytes(t, q, robot="ur5"), ".csv")
    # JSON: types the format does not allow, in every named field
    for key, value in (("goal", [True, False, True]), ("goal", ["0.5", "0", "0.3"]),
                       ("goal", {"position": [0.5, 0, None]}), ("rate", True),
                       ("rate", "250"), ("duration", -1), ("joint_names", [1, 2, 3]),
                       ("robot", 7), ("ee_frame", 3), ("format", None),
                       ("t", [True] * len(t)), ("t", [str(x) for x in t]),
                       ("q", [[[v] for v in row] for row in q.tolist()]),
                       ("q", [[str(v) for v in row] for row in q.tolist()]),
                       ("q", [[True] * 7 for _ in t]), ("q", [[1e308] * 7 for _ in t]),
                       ("q", q.tolist()[:1] * len(t) + [[0] * 7]),
                       ("t", [0, 1e-320, 2e-320] + [1.0 + i for i in range(len(t) - 3)]),
                       ("episodes", [{"kind": "pause", "t_start": 0, "t_end": 1}] * 200_000)):
        name = f"json-{key}-{json.dumps(value)[:24]}"
        name = "".join(c if c.isalnum() or c in "-." else "_" for c in name)
        add(name, json.dumps({**jd, key: value}).encode(), ".json")
    add("json-deep", ("[" * 100_000 + "]" * 100_000).encode(), ".json")
    add("json-deep-goal", json.dumps({**jd, "goal": 0}).encode().replace(
        b'"goal": 0', b'"goal": ' + b"[" * 50_000 + b"]" * 50_000), ".json")
    add("json-huge-int", json.dumps(jd).encode().replace(b'"t": [0.0', b'"t": [' +
                                                         b"9" * 5000, 1), ".json")
    add("json-plot-episodes", json.dumps({**jd, "episodes": [
        {"kind": "pause", "t_start": 0.1, "t_end": 0.2}] * 300_000}).encode(), ".json",
        ["plot", "{d}/json-plot-episodes.json", "-o", "{d}/plot-out.png"])
    add("json-rows-over-bound", json.dumps(jd).encode(), ".json", None, AOU_MAX_SAMPLES="50")
    # NPZ: compression and headers aou does not read, and claims of sizes
    members = {"t.npy": npy(t), "q.npy": npy(q), "header.json": json.dumps(
        {k: v for k, v in jd.items() if k not in ("t", "q")}).encode()}
    add("npz-deflate64", npz_bytes(members, patch_method=9), ".npz")
    add("npz-aes", npz_bytes(members, patch_method=99), ".npz")
    add("npz-encrypted", npz_bytes(members, encrypted=True), ".npz")
    for label, claim in (("1e9", (10**9, 7)), ("1e12", (10**12, 7)), ("neg", (-5, 7))):
        add(f"npz-claims-{label}", npz_of(t, q, q_npy=npy_claiming(claim)), ".npz")
    add("npz-t-claims-1e9", npz_of(t, q, t_npy=npy_claiming((10**9,))), ".npz")
    add("npz-nested-header", npz_of(t, q, q_npy=npy_claiming(
        (5, 7), "[" * 3000 + "]" * 3000)), ".npz")
    add("npz-header-bomb", npz_of(t, q, q_npy=b"\x93NUMPY\x02\x00" + struct.pack(
        "<I", 50_000_000) + b"{" * 1000), ".npz")
    for label, arr in (("datetime64", np.zeros((len(t), 7), "datetime64[s]")),
                       ("complex", q.astype(complex)), ("bytes", q.astype("S8")),
                       ("bool", np.ones((len(t), 7), bool)), ("3d", q[:, :, None]),
                       ("object-free-structured", np.zeros(len(t), [("a", "<f8")])),
                       ("1e308", np.full_like(q, 1e308))):
        add(f"npz-q-{label}", npz_of(t, q, q_npy=npy(arr)), ".npz")
    add("npz-t-complex", npz_of(t, q, t_npy=npy(t.astype(complex))), ".npz")
    add("npz-header-json-bad", npz_of(t, q, header_json=b"[" * 100_000), ".npz")
    add("npz-truncated", npz_of(t, q)[:600], ".npz")
    add("npz-random", random.Random(3).randbytes(4096), ".npz")
    # --robot that is not the robot of the recording: the joints do not match
    out.append(Case("json-robot-ur5", {"p.json": json.dumps(jd).encode()},
                    ["measure", "{d}/p.json", "--robot", "ur5"]))
    return out


def clock_cases() -> list[Case]:
    """`check` on times that do not start at 0 (the same motion, shifted)."""
    out = []
    for label, t0 in (("unix", 1.7e9), ("minus100", -100.0), ("minus1", -1.0)):
        t, q = motion(t0=t0)
        out.append(Case(f"check-t-{label}", {"c.json": json.dumps(json_doc(t, q)).encode()},
                        ["check", "{d}/c.json"]))
    return out


def special_cases() -> list[Case]:
    """FIFOs and devices where a file is expected: each must be refused, at once."""
    out = []
    for ext, cmd in ((".csv", "measure"), (".json", "measure"), (".npz", "measure"),
                     (".aou", "lint"), (".aou", "compile"), (".json", "check"),
                     (".json", "plot")):
        argv = [cmd, "{d}/x" + ext] + (["-o", "{d}/out.png"] if cmd == "plot" else [])
        out.append(Case(f"fifo{ext}-{cmd}", {"x" + ext: "fifo"}, argv))
    for dev in ("/dev/zero", "/dev/urandom"):
        for ext, cmd in ((".csv", "measure"), (".json", "measure"), (".npz", "measure"),
                         (".aou", "lint"), (".urdf", "robot"), (".toml", "robot")):
            out.append(Case(f"{dev[5:]}{ext}-{cmd}", {"x" + ext: "->" + dev},
                            [cmd, "{d}/x" + ext]))
    out.append(Case("dev-zero-plain", {}, ["measure", "/dev/zero", "--robot", "panda"]))
    out.append(Case("fifo-robot", {"arm.urdf": "fifo", "a.aou": b'robot "arm.urdf"\n'
                                   b"approach\npause 1s\n"}, ["compile", "{d}/a.aou"]))
    return out


def urdf(links: list[str], joints: list[tuple[str, str, str, str]], *,
         limit: str = 'lower="-2" upper="2" velocity="2" effort="50"',
         axis: str = "0 0 1", mesh: str | None = None) -> bytes:
    """A URDF of ``links`` and ``joints`` (name, type, parent, child)."""
    geo = f'<mesh filename="{mesh}"/>' if mesh else '<box size="0.05 0.05 0.1"/>'
    body = "".join(
        f'<link name="{n}"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" '
        f'ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial><collision><geometry>{geo}'
        "</geometry></collision></link>" for n in links)
    body += "".join(
        f'<joint name="{n}" type="{ty}"><parent link="{p}"/><child link="{c}"/>'
        f'<origin xyz="0 0 0.1"/><axis xyz="{axis}"/><limit {limit}/></joint>'
        for n, ty, p, c in joints)
    return f'<?xml version="1.0"?><robot name="arm">{body}</robot>'.encode()


def chain(n: int, **kw) -> bytes:
    links = [f"l{i}" for i in range(n + 1)]
    return urdf(links, [(f"j{i}", "revolute", f"l{i}", f"l{i + 1}") for i in range(n)], **kw)


def panda_urdf() -> str:
    """The Panda's URDF as example-robot-data ships it."""
    import os

    from aou_dsl.core.robot_specs import ROBOTS
    from aou_dsl.robot.load import _data_path

    with open(_data_path(ROBOTS["panda"].urdf), encoding="utf-8") as fh:
        text = fh.read()
    assert os.path.basename(ROBOTS["panda"].urdf) == "panda.urdf"
    return text


def panda_with(joint: str, attr: str, value: str) -> bytes:
    """The Panda's URDF with ``attr`` of joint ``joint``'s <limit> (or <axis> for
    ``xyz``) set to ``value``."""
    import re

    text = panda_urdf()
    start = text.index(f'<joint name="{joint}"')
    end = text.index("</joint>", start)
    block = text[start:end]
    tag = "axis" if attr == "xyz" else "limit"
    new = re.sub(rf'(<{tag}[^>]*\b{attr}=")[^"]*(")', rf"\g<1>{value}\g<2>", block)
    assert new != block or value in block, (joint, attr)
    return (text[:start] + new + text[end:]).encode()


def robot_cases() -> list[Case]:
    """Robot files: broken trees, oversize, values the URDF and TOML formats allow but no
    arm has, escapes from a package."""
    out: list[Case] = []

    def add(name: str, data: bytes, ext: str = ".urdf", **more: bytes | str):
        out.append(Case(name, {"arm" + ext: data, **more}, ["robot", "{d}/arm" + ext]))

    links = [f"l{i}" for i in range(4)]
    add("urdf-cycle", urdf(links, [("j0", "revolute", "l0", "l1"),
                                   ("j1", "revolute", "l1", "l2"),
                                   ("j2", "revolute", "l2", "l0")]))
    add("urdf-self-loop", urdf(links[:2], [("j0", "revolute", "l0", "l1"),
                                           ("j1", "revolute", "l1", "l1")]))
    add("urdf-two-parents", urdf(links[:3], [("j0", "revolute", "l0", "l2"),
                                             ("j1", "revolute", "l1", "l2")]))
    add("urdf-unknown-link", urdf(links[:2], [("j0", "revolute", "l0", "nowhere")]))
    add("urdf-many-roots", urdf([f"a{i}" for i in range(2000)], [
        (f"j{i}", "revolute", f"a{2 * i}", f"a{2 * i + 1}") for i in range(1000)]))
    add("urdf-chain-1000", chain(1000))
    add("urdf-chain-100", chain(100))
    for label, attr, value in (("velocity-0", "velocity", "0"),
                               ("velocity-neg", "velocity", "-1"),
                               ("lower-gt-upper", "lower", "2.9"),
                               ("effort-0", "effort", "0"), ("effort-neg", "effort", "-5"),
                               ("limit-nan", "lower", "nan"), ("upper-inf", "upper", "inf"),
                               ("velocity-1e308", "velocity", "1e308"),
                               ("limit-words", "lower", "low"),
                               ("axis-zero", "xyz", "0 0 0"), ("axis-1e308", "xyz", "1e308 0 0"),
                               ("axis-nan", "xyz", "nan 0 1"), ("axis-tiny", "xyz", "1e-320 0 0")):
        add(f"urdf-{label}", panda_with("panda_joint4", attr, value))
    def mesh(uri: str) -> bytes:  # every collision mesh of the Panda at ``uri``
        import re

        return re.sub(r'(<collision>\s*<geometry>\s*<mesh filename=")[^"]*', rf"\g<1>{uri}",
                      panda_urdf()).encode()

    out.append(Case("urdf-mesh-folder", {"arm.urdf": mesh("meshes"), "meshes": "dir",
                                         "a.aou": b'robot "arm.urdf"\napproach\npause 1s\n'},
                    ["compile", "{d}/a.aou", "-o", "{d}/out.json"]))
    out.append(Case("urdf-mesh-fifo", {"arm.urdf": mesh("m.stl"), "m.stl": "fifo",
                                       "a.aou": b'robot "arm.urdf"\napproach\npause 1s\n'},
                    ["compile", "{d}/a.aou", "-o", "{d}/out.json"]))
    add("urdf-package-escape", mesh("package://arm/../../../../etc/passwd"))
    add("urdf-package-escape-abs", mesh("package://arm//etc/passwd"))
    add("urdf-not-xml", b"<robot" * 1000)
    add("urdf-billion-laughs", b'<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">'
        + b"".join(f'<!ENTITY a{i} "{"&a" + (str(i - 1) if i else "") + ";" * 1}'
                   f'{("&a" + (str(i - 1) if i else "") + ";") * 9}">'.encode()
                   for i in range(9)) + b']><robot name="x">&a8;</robot>')
    add("urdf-bytes-over-bound", chain(6) + b"<!--" + b"x" * 30_000 + b"-->")
    out[-1].env["AOU_MAX_INPUT_MB"] = "0.01"
    good = chain(6)
    toml_cases = {
        "toml-unknown-contact": b'urdf = "u.urdf"\nallowed_contacts = [["l1", "nolink"]]\n',
        "toml-deep": b"x = " + b"[" * 5000 + b"]" * 5000 + b"\n",
        "toml-deep-table": b"a = " + b"{b = " * 3000 + b"1" + b"}" * 3000 + b"\n",
        "toml-huge-int": b'urdf = "u.urdf"\nee_offset = ' + b"9" * 5000 + b"\n",
        "toml-velocity-scale-inf": b'urdf = "u.urdf"\nvelocity_scale = inf\n',
        "toml-accel-scale-inf": b'urdf = "u.urdf"\naccel_scale = inf\n',
        "toml-limit-margin-inf": b'urdf = "u.urdf"\nlimit_margin = inf\n',
        "toml-scale-nan": b'urdf = "u.urdf"\nvelocity_scale = nan\n',
        "toml-scale-huge": b'urdf = "u.urdf"\naccel_scale = 1e308\n',
        "toml-rates-1e308": b'urdf = "u.urdf"\njoint_accel = 1e308\njoint_jerk = 1e308\n',
        "toml-posture-huge": b'urdf = "u.urdf"\nposture = [1e308, 0, 0, 0, 0, 0]\n',
        "toml-goal-huge": b'urdf = "u.urdf"\ngoal = [1e308, 0, 0]\n',
        "toml-ee-roll-huge": b'urdf = "u.urdf"\nee_roll = 1e308\n',
        "toml-ee-offset-huge": b'urdf = "u.urdf"\nee_offset = 1e308\n',
        "toml-from-zero": b'urdf = "u.urdf"\nfrom = [0, 0, 0.0]\n',
        "toml-from-nan": b'urdf = "u.urdf"\nfrom = [nan, 0, 1]\n',
        "toml-arm-joints-many": b'urdf = "u.urdf"\narm_joints = [' +
                                b", ".join(b'"j%d"' % i for i in range(5000)) + b"]\n",
        "toml-self-urdf": b'urdf = "arm.toml"\n',
        "toml-urdf-escape": b'urdf = "../../../../etc/passwd"\n',
        "toml-types": b'urdf = 5\n',
    }
    for name, text in toml_cases.items():
        add(name, text, ".toml", **{"u.urdf": good})
    return out


def lookalike_digits(rng: random.Random) -> str:
    """A digit that is not ASCII but reads as one."""
    return rng.choice("０１２３４５６７８９٠١٢٣٤٥٦٧٨٩۰۱۲۳۴۵۶۷۸۹०१२३४५६७८९")


#: Numbers at and around the float limits, and of every other awkward shape.
EXTREME = ("1e308", "1.7976931348623157e308", "1e309", "1e160", "1e155", "1e-155",
           "1e-308", "5e-324", "1e-400", "-1e308", "0", "-0", "0.0e0", "1e-7", "1e-6",
           "1e7", "360", "361", "3600", "3601", "100", "101", "9" * 400, "0." + "0" * 400
           + "1", "1" + "0" * 30)
UNITS = ("", "m", "cm", "mm", "s", "ms", "deg", "rad", "m/s", "mm/s", "m/s^2", "deg/s",
         "rad/s", "Hz")
STATEMENTS = ("approach {n}{u}", "approach v={n}{u}", "approach a={n}{u}",
              "retreat {n}{u}", "retreat 0.06m a={n}{u}", "pause {n}{u}", "tilt {n}{u}",
              "tilt 20deg v={n}{u}", "shiver {n}{u}", "shiver 5deg f={n}{u}",
              "shiver 5deg for {n}{u}", "gaze horizontal {n}{u}", "gaze vertical {n}{u}",
              "start {n}{u}", "standoff {n}{u}", "goal ({n}{u}, 0, 0.3)",
              "goal (0.5, {n}{u}, {n}{u})", "from ({n}, {n}, 0)", "pause 1s x{n}",
              "effort W={n} T=0 S=0 F=0")


def aou_numbers(rng: random.Random, count: int) -> list[str]:
    """``.aou`` files whose numbers sit at the float limits (or look like digits)."""
    out = []
    for _ in range(count):
        lines = []
        for _ in range(rng.randint(1, 3)):
            n = rng.choice(EXTREME)
            if rng.random() < 0.1:
                k = rng.randrange(len(n))
                n = n[:k] + lookalike_digits(rng) + n[k + 1:]
            lines.append(rng.choice(STATEMENTS).format(n=n, u=rng.choice(UNITS)))
        if rng.random() < 0.5:
            lines.insert(0, "behaviour b : " + rng.choice(
                ("confident", "curious", "hesitant", "fearful", "inactive")))
        if not any(line.startswith(("approach", "sequence")) for line in lines):
            lines.append("approach")
        out.append("\n".join(lines) + "\n")
    return out


def mutate_recording(rng: random.Random, data: bytes) -> bytes:
    """A recording with a few bytes changed, cut, or repeated."""
    b = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        op = rng.random()
        at = rng.randrange(len(b)) if b else 0
        if op < 0.4 and b:
            b[at] = rng.choice(b"0123456789.,-e\n\"#[]{}:x\x00 ")
        elif op < 0.6:
            del b[at:at + rng.randint(1, 200)]
        elif op < 0.8:
            b[at:at] = b[at:at + rng.randint(1, 2000)] * rng.randint(1, 3)
        else:
            b[at:at] = rng.choice((b"1e308", b"nan", b"-1e308", b"9" * 5000, b'"', b"inf"))
    return bytes(b)


def is_finite_number(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


Generator = Callable[[], list[Case]]


def materialise(case: Case, folder: str) -> list[str]:
    """Make ``case``'s files in ``folder``; the argv with ``{d}`` filled in."""
    import os

    for name, data in case.files.items():
        path = os.path.join(folder, name)
        if data == "fifo":
            os.mkfifo(path)
        elif data == "dir":
            os.makedirs(path, exist_ok=True)
        elif isinstance(data, str) and data.startswith("->"):
            os.symlink(data[2:], path)
        else:
            assert isinstance(data, bytes)
            with open(path, "wb") as fh:
                fh.write(data)
    return [a.replace("{d}", folder) for a in case.argv]


def snapshot(folder: str) -> dict[str, tuple[str, bytes | None]]:
    """Every entry of ``folder``: its kind and, for a regular file, its bytes."""
    import os
    import stat

    out: dict[str, tuple[str, bytes | None]] = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            path = os.path.join(root, name)
            mode = os.lstat(path).st_mode
            if stat.S_ISREG(mode):
                with open(path, "rb") as fh:
                    out[path] = ("file", fh.read())
            else:
                out[path] = (stat.filemode(mode)[0], None)
    return out


def run_cli(argv: list[str], env: dict[str, str], timeout: float = 90.0,
            memory: int = 2 << 30, cpu: int = 30) -> tuple[int | None, str]:
    """``python -m aou_dsl ARGV`` in a subprocess limited to ``memory`` bytes of address
    space and ``cpu`` seconds of processor time (a busy loop is killed there, exit
    -SIGXCPU), and waited for ``timeout`` seconds of wall time (a process blocked on a
    FIFO uses no processor; the wall bound is wider for a machine shared with other
    work); (exit code or None on a timeout, stderr + stdout)."""
    import os
    import resource
    import subprocess
    import sys

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 1))

    full = {**os.environ, **env, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    try:
        p = subprocess.run([sys.executable, "-m", "aou_dsl", *argv], capture_output=True,
                           text=True, timeout=timeout, env=full, preexec_fn=limit,
                           stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired as exc:
        return None, f"timeout: {exc.stderr!r}"
    return p.returncode, p.stderr + p.stdout
