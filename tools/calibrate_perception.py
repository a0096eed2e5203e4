"""Calibrate the geometric perception model against the rendered camera and its AprilTag
detector: render every sweep point, write the data (docs/perception-calibration.csv), fit
the model's curves to the fitting sweeps and print the fit (to paste into
``aou_dsl/live/geometric.py`` as ``FIT``) and the model's error on the held-out sweeps.

    python tools/calibrate_perception.py [--points N] [--repeats K] [--check]

``--check`` renders nothing: it fits the committed data again and says whether the fit in
the package is the one the data give. Needs the ``perception`` extra.
"""

from __future__ import annotations

import argparse
import pathlib
import sys

from aou_dsl.core.files import write_atomic
from aou_dsl.live import calibrate
from aou_dsl.live.geometric import FIT

DATA = pathlib.Path(__file__).resolve().parent.parent / "docs" / "perception-calibration.csv"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=int, default=16, help="points per sweep")
    ap.add_argument("--repeats", type=int, default=2, help="frames per point")
    ap.add_argument("--check", action="store_true", help="fit the committed data only")
    a = ap.parse_args()
    if a.check:
        rows = calibrate.read_csv(DATA.read_text())
    else:
        rows = calibrate.measure(calibrate.sweeps(a.points), a.repeats)
        write_atomic(str(DATA), calibrate.write_csv(rows).encode())
        print(f"wrote {DATA} ({len(rows)} points)")
    got, errors = calibrate.fit(rows)
    print(calibrate.fit_text(got))
    print("fit RMS error per curve: " + ", ".join(f"{k} {v:.3g}" for k, v in errors.items()))
    for which in ("fit", "held"):
        e = calibrate.evaluate(rows, got, which)
        print(f"{which} sweeps: {e['points']:.0f} points, confidence error RMS {e['rms']:.3f}, "
              f"max {e['max']:.3f}; same state in {100 * e['same_state']:.0f} %")
    same = got == FIT
    print("the package's fit is " + ("the data's" if same else "NOT the data's: paste the "
                                    "fit above into aou_dsl/live/geometric.py"))
    return 0 if same or not a.check else 1


if __name__ == "__main__":
    sys.exit(main())
