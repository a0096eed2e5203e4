"""Calibrate the geometric perception model against the rendered camera and its AprilTag
detector: render every sweep point, write the data (docs/perception-calibration.csv), fit
the model's curves to the fitting sweeps and print the fit (to paste into
``aou_dsl/live/geometric.py`` as ``FIT``) and the model's error on the held-out sweeps.

    python tools/calibrate_perception.py [--points N] [--repeats K] [--check] [--noise]

``--check`` renders nothing: it fits the committed data again and says whether the fit in
the package is the one the data give. ``--noise`` measures (only) how much the camera's
confidence wanders at each still scene of the fitting sweeps, as the loop reads it
(docs/perception-noise.csv), and prints the regulator's default hysteresis that noise
gives (``aou_dsl/live/regulator.py``, ``CONFIDENCE_NOISE``). Needs the ``perception``
extra.
"""

from __future__ import annotations

import argparse
import pathlib
import sys

from aou_dsl.core.files import write_atomic
from aou_dsl.live import calibrate
from aou_dsl.live.geometric import FIT

DATA = pathlib.Path(__file__).resolve().parent.parent / "docs" / "perception-calibration.csv"
NOISE = DATA.with_name("perception-noise.csv")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=int, default=16, help="points per sweep")
    ap.add_argument("--repeats", type=int, default=2, help="frames per point")
    ap.add_argument("--check", action="store_true", help="fit the committed data only")
    ap.add_argument("--noise", action="store_true", help="measure the confidence's noise "
                    "(only)")
    a = ap.parse_args()
    noise_ok = _noise(a.noise and not a.check, a.points)
    if a.noise and not a.check:
        return 0
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
    return 0 if (same and noise_ok) or not a.check else 1


def _noise(measure: bool, points: int) -> bool:
    """Measure the noise (or read the committed one) and say whether the regulator's
    default hysteresis is the one it gives."""
    from aou_dsl.live.regulator import CONFIDENCE_NOISE, Hysteresis, hysteresis_for

    if measure:
        rows = calibrate.noise(calibrate.sweeps(points))
        write_atomic(str(NOISE), calibrate.write_csv(rows, calibrate.NOISE_COLUMNS).encode())
        print(f"wrote {NOISE} ({len(rows)} still scenes)")
    else:
        rows = calibrate.read_csv(NOISE.read_text())
    sigma = calibrate.noise_sigma(rows)
    print(f"confidence noise: the largest std at a still scene {sigma:g}; the default "
          f"hysteresis it gives: {hysteresis_for(sigma)}")
    same = sigma == CONFIDENCE_NOISE and Hysteresis() == hysteresis_for(sigma)
    if not same:
        print(f"the package's CONFIDENCE_NOISE ({CONFIDENCE_NOISE:g}) is NOT the data's: set "
              f"it to {sigma:g} in aou_dsl/live/regulator.py")
    return same


if __name__ == "__main__":
    sys.exit(main())
