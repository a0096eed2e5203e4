"""Save the velocity profile of a compiled behaviour as a PNG.

Compiles a behaviour (by default the study's fearful one) with ``aou_dsl.compile`` and
draws its velocity profile with ``aou_dsl.media.plot``: the end-effector speed over time
with the episodes shaded and labelled, the distance to the goal, and the joint positions
and velocities as fractions of their limits. Then it draws the C-V plane with the five
shipped behaviours from their lint results (what ``aouc plot --cv behaviours -o
cv-map.png`` draws). Needs the media extra (matplotlib): ``pip install ".[media]"``.

Run from the repository root::

    python examples/plot_profile.py [OUTPUT_FOLDER] [BEHAVIOUR.aou]

OUTPUT_FOLDER defaults to a new temporary folder; BEHAVIOUR defaults to
``behaviours/fearful.aou``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import aou_dsl
from aou_dsl.media.plot import cv_figure, profile_data, profile_figure, save

ROOT = Path(__file__).resolve().parent.parent
DEFAULT = ROOT / "behaviours" / "fearful.aou"


def main(argv: list[str]) -> int:
    """Compile, plot the velocity profile, plot the C-V map; print what was written."""
    out = Path(argv[0]) if argv else Path(tempfile.mkdtemp(prefix="aou-plot-"))
    source = Path(argv[1]) if len(argv) > 1 else DEFAULT
    out.mkdir(parents=True, exist_ok=True)

    build = aou_dsl.compile(source)
    if not build.ok:
        for d in build.diagnostics:
            print(f"{d.span}: {d.code} {d.message}")
        return 1
    data = profile_data(build.trajectory)
    profile = out / f"{source.stem}-profile.png"
    save(profile_figure(data), str(profile))
    print(f"wrote {profile}: {data.t[-1]:.2f} s, peak speed {data.speed.max():.3f} m/s, "
          f"{len(data.episodes)} episodes")
    for kind, t0, t1 in data.episodes:
        print(f"  {t0:6.2f} - {t1:6.2f} s  {kind}")

    cv_map = out / "cv-map.png"
    results, problems = aou_dsl.lint_paths([str(ROOT / "behaviours")])
    points = [(r.behaviour.name, r.cv) for r in results
              if r.behaviour is not None and r.cv is not None]
    if problems or len(points) != len(results):
        print("the shipped behaviours do not all lint")
        return 1
    save(cv_figure(points), str(cv_map))
    print(f"wrote {cv_map}: {len(points)} behaviours on the C-V plane")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
