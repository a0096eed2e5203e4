"""Measure a CSV recording: the way a trajectory of a real arm would be checked.

Compiles the study's hesitant behaviour (``behaviours/hesitant.aou``) to a CSV file with
the command-line entry ``aou_dsl.cli.commands.main`` (the same as ``aouc compile ... -o X.csv``).
Its rows hold only sample times and joint positions, like a log recorded on a robot.
A CSV that aou writes also names its robot, end-effector frame and goal in ``#`` comment
lines above the columns, so ``aouc measure hesitant.csv`` needs nothing more; a log from
a real arm has no such lines, and measuring it needs the robot and the goal named
(``--robot``, ``--goal``; ``robot=`` and ``goal=`` here). The script names them, as it
would for such a log. ``aou_dsl.measure`` then finds the episodes and the eleven
descriptors from the joint motion alone, and the script prints them beside the values
the study used (Table II, hesitant column).

Run from the repository root::

    python examples/measure_csv.py [OUTPUT_FOLDER]

OUTPUT_FOLDER defaults to a new temporary folder; the CSV is written there.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import aou_dsl
from aou_dsl.cli.commands import main as aouc

ROOT = Path(__file__).resolve().parent.parent
BEHAVIOUR = ROOT / "behaviours" / "hesitant.aou"
#: The file sets no `goal` line, so it reaches for the Panda's default goal [m].
GOAL = (0.55, 0.0, 0.25)
#: The hesitant stimulus of the study (None: the primitive is absent).
STUDY = {"approach_acceleration": 0.05, "pause_count": 5, "pause_duration": 1.67,
         "retreat_count": 3, "retreat_distance": 0.06, "retreat_acceleration": 0.12}


def main(argv: list[str]) -> int:
    """Compile to CSV, measure the CSV, print the descriptors and the C-V point."""
    out = Path(argv[0]) if argv else Path(tempfile.mkdtemp(prefix="aou-csv-"))
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / "hesitant.csv"
    status = aouc(["compile", str(BEHAVIOUR), "-o", str(csv_path)])
    if status != 0:
        print(f"aouc compile failed with exit status {status}")
        return status
    lines = csv_path.read_text().splitlines()
    comments = [ln for ln in lines if ln.startswith("#")]
    header = next(ln for ln in lines if not ln.startswith("#"))
    print(f"wrote {csv_path}: columns {header}")
    print(f"  and {len(comments)} comment lines: {'; '.join(c[2:] for c in comments)}")

    # As for a log recorded on a robot, which has no comment lines: name robot and goal.
    m = aou_dsl.measure(csv_path, robot="panda", goal=GOAL)
    print(f"measured {m.duration:.2f} s of motion, {len(m.episodes)} episodes "
          f"(line of sight within {m.gaze_error:.4f} deg of the goal)")
    print(f"{'descriptor':<22} {'unit':<6} {'measured':>9} {'study':>7}")
    for name, value in m.descriptors.items():
        unit = aou_dsl.REGISTRY[name].unit
        shown = "-" if value is None else f"{value:.4g}"
        study = STUDY.get(name)
        print(f"{name:<22} {unit:<6} {shown:>9} {'-' if study is None else study:>7}")
    print(f"C-V point of the measured motion: C={m.cv.C:+.2f}, V={m.cv.V:+.2f} "
          f"({m.cv.state.value})")
    for d in m.diagnostics:
        print(f"{d.code} {d.severity}: {d.message}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
