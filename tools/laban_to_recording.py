"""Turn one take of the Laban motion-based arm trajectories (a Kinova Gen3 with a gripper,
moved by 25 people in eight Laban Effort styles; published with the paper "Can We
Automatically Label Expressive Robot Arm Motion Qualities? Open Dataset and Machine
Learning Results") into a recording ``aouc measure`` reads.

    python tools/laban_to_recording.py raw_data/P10_H1.csv -o p10_h1.csv
    printf 'joint_%s=Actuator%s\\n' 1 1 2 2 3 3 4 4 5 5 6 6 7 7 > gen3.map
    aouc measure p10_h1.csv --goal final --map gen3.map \\
        --robot tests/vendor/kortex_description/arms/gen3/7dof/urdf/GEN3_URDF_V12.urdf

(Kinova's own file names the joints ``Actuator1`` to ``Actuator7``; the map tells aou
which column is which.)

The dataset's files (``raw_data/P<n>_<cond><take>.csv``) have a header
``Time,Position,Velocity,Effort``: ``Time`` in Unix seconds, then three quoted,
bracketed arrays as NumPy prints them (``[ 0.00000000e+00 -7.98948327e-05 ...]``, wrapped
over lines inside the quotes), eight values each. The first value is the gripper, the
other seven are ``joint_1`` to ``joint_7`` from the base outwards (the dataset's own
description says they run from the end effector backwards; the efforts and the home pose
say otherwise: tests/vendor/laban_gen3/README.md gives the evidence). The output is a
CSV ``t,joint_1,...,joint_7`` with the positions in radians as the file prints them and
the times unchanged; velocities and efforts are left out (aou measures from positions).
A gzip-compressed input (``.gz``) is read as well.

``--reduce`` writes instead the compact copy kept in tests/vendor/laban_gen3/ (gzip):
``# key: value`` comment lines (``source``, ``t0``: the first time as printed), a header
``t_1e-7s,joint_1,...,joint_7``, then one row per sample of integers: the first row the
time since ``t0`` in units of 1e-7 s (0) and the positions in units of 1e-9 rad, every
later row the change from the row before. Both are exact decimal roundings of the
printed texts (the times print at most 7 decimals; the positions, nine significant
digits, lose only digits below 1e-9 rad, a thousand times under the encoders' noise).
:func:`decode_reduced` reads it back.

The arrays are parsed as text (split on blanks, each item a float), never evaluated.
Nothing is downloaded: this is for a user who holds the dataset. The output is written
only where ``-o`` says, and never over the input.
"""

from __future__ import annotations

import argparse
import csv
import gzip
import io
import math
import sys
from decimal import Decimal
from pathlib import Path

#: The seven arm joints of the Gen3 in the order the arrays hold them after the gripper.
JOINTS = tuple(f"joint_{k}" for k in range(1, 8))
#: Values per array: the gripper, then the seven joints.
WIDTH = 8
HEADER = ("Time", "Position", "Velocity", "Effort")


class TakeError(ValueError):
    """A file that is not a take of the dataset, with the line where it goes wrong."""


def parse_array(text: str, line: int) -> list[float]:
    """A NumPy-printed 1-D array of :data:`WIDTH` finite numbers (``[ a b ... ]``)."""
    body = text.strip()
    if not (body.startswith("[") and body.endswith("]")):
        raise TakeError(f"line {line}: expected a bracketed array, found `{body[:40]}`")
    items = body[1:-1].split()
    if len(items) != WIDTH:
        raise TakeError(f"line {line}: expected {WIDTH} values in the array, found "
                        f"{len(items)}")
    try:
        values = [float(x) for x in items]
    except ValueError as e:
        raise TakeError(f"line {line}: {e}") from None
    if not all(math.isfinite(v) for v in values):
        raise TakeError(f"line {line}: a value is not a finite number")
    return values


def read_take(text: str) -> tuple[list[str], list[list[str]]]:
    """The times and the seven joints' positions of a take, as the file writes them
    (texts, so that the output keeps every digit)."""
    reader = csv.reader(io.StringIO(text))
    try:
        head = next(reader)
    except StopIteration:
        raise TakeError("the file is empty") from None
    if tuple(h.strip() for h in head) != HEADER:
        raise TakeError(f"line 1: expected the header {','.join(HEADER)}, found "
                        f"{','.join(head)[:80]}")
    times: list[str] = []
    rows: list[list[str]] = []
    following = reader.line_num + 1  # where the next row starts (a row spans lines)
    for row in reader:
        line, following = following, reader.line_num + 1
        if not row:
            continue
        if len(row) != len(HEADER):
            raise TakeError(f"line {line}: expected {len(HEADER)} fields, found {len(row)}")
        try:
            t = float(row[0])
        except ValueError:
            raise TakeError(f"line {line}: the time `{row[0][:40]}` is not a number") from None
        if not math.isfinite(t) or (times and t <= float(times[-1])):
            raise TakeError(f"line {line}: the time must be finite and increase")
        parse_array(row[1], line)  # checked; the texts are kept
        times.append(row[0].strip())
        rows.append(row[1].strip()[1:-1].split()[1:])
    if len(times) < 3:
        raise TakeError("a take needs at least 3 samples")
    return times, rows


def to_recording(text: str) -> str:
    """The recording CSV of a take's text."""
    times, rows = read_take(text)
    out = ["t," + ",".join(JOINTS)]
    out += [t + "," + ",".join(q) for t, q in zip(times, rows, strict=True)]
    return "\n".join(out) + "\n"


#: Units of the reduced copy's integers: seconds and radians per unit.
T_UNIT, Q_UNIT = Decimal("1e-7"), Decimal("1e-9")


def reduce_take(text: str, source: str) -> str:
    """The compact copy of a take (see the module's description)."""
    times, rows = read_take(text)
    t0 = Decimal(times[0])
    ticks = [int(((Decimal(t) - t0) / T_UNIT).to_integral_value()) for t in times]
    nrad = [[int((Decimal(x) / Q_UNIT).to_integral_value()) for x in q] for q in rows]
    out = [f"# source: {source}", f"# t0: {times[0]}",
           "t_1e-7s," + ",".join(f"{j}_1e-9rad" for j in JOINTS)]
    prev = [0] * (1 + len(JOINTS))
    for tick, q in zip(ticks, nrad, strict=True):
        now = [tick, *q]
        out.append(",".join(str(a - b) for a, b in zip(now, prev, strict=True)))
        prev = now
    return "\n".join(out) + "\n"


def decode_reduced(text: str) -> tuple[float, list[float], list[list[float]]]:
    """``t0``, the times since ``t0`` [s] and the positions [rad] of a reduced copy."""
    lines = text.splitlines()
    notes = {k.strip(): v.strip() for k, _, v in
             (ln.lstrip("#").partition(":") for ln in lines if ln.startswith("#"))}
    body = [ln for ln in lines if ln and not ln.startswith("#")][1:]
    acc = [0] * (1 + len(JOINTS))
    times: list[float] = []
    rows: list[list[float]] = []
    for ln in body:
        acc = [a + int(d) for a, d in zip(acc, ln.split(","), strict=True)]
        times.append(acc[0] * float(T_UNIT))
        rows.append([a * float(Q_UNIT) for a in acc[1:]])
    return float(notes["t0"]), times, rows


def _read(path: Path) -> str:
    data = path.read_bytes()
    if path.suffix == ".gz":
        data = gzip.decompress(data)
    return data.decode("utf-8-sig")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("take", type=Path, help="a raw_data/P<n>_<cond><take>.csv of the dataset")
    ap.add_argument("-o", "--output", type=Path, help="the recording to write (default: "
                    "standard output)")
    ap.add_argument("--reduce", action="store_true", help="write the compact copy the "
                    "tests keep (gzip) instead of a recording")
    args = ap.parse_args(argv)
    try:
        raw = _read(args.take)
        text = reduce_take(raw, args.take.name) if args.reduce else to_recording(raw)
    except (OSError, UnicodeDecodeError, TakeError, csv.Error, EOFError) as e:
        print(f"error: {args.take}: {e}", file=sys.stderr)
        return 2
    if args.output is None:
        if args.reduce:
            sys.stdout.buffer.write(gzip.compress(text.encode(), 9, mtime=0))
        else:
            sys.stdout.write(text)
        return 0
    if args.output.exists() and args.output.resolve() == args.take.resolve():
        print(f"error: {args.output}: would overwrite the input", file=sys.stderr)
        return 2
    if args.reduce:
        args.output.write_bytes(gzip.compress(text.encode(), 9, mtime=0))
    else:
        args.output.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
