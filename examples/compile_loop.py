"""Compile one behaviour in a loop, varying one value through source text.

Shows ``aou_dsl.compile(source=...)``: no files are needed to try a value. The loop takes
the study's hesitant behaviour and varies its pause duration; each compile is linted,
laid out, solved (IK), timed (TOPP-RA), replayed in PyBullet and measured back, and the
script prints the declared and measured pause duration, the C-V point and the time each
compile took. The last compiled trajectory is written to the output folder as JSON.

Run from the repository root::

    python examples/compile_loop.py [OUTPUT_FOLDER]

OUTPUT_FOLDER defaults to a new temporary folder.
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
from pathlib import Path

import aou_dsl

#: The hesitant stimulus of the study, with the pause duration left open.
TEMPLATE = """\
behaviour hesitant_{tag} : hesitant
approach a=0.05
pause {pause}s x5
retreat 0.06m a=0.12 x3
"""

#: Pause durations to try [s].
PAUSES = (1.0, 1.67, 2.5, 3.5)


def main(argv: list[str]) -> int:
    """Compile the template once per pause duration; print one line per compile."""
    out = Path(argv[0]) if argv else Path(tempfile.mkdtemp(prefix="aou-loop-"))
    out.mkdir(parents=True, exist_ok=True)
    print(f"{'pause [s]':>9} {'declared':>9} {'measured':>9} {'C':>6} {'V':>6} "
          f"{'state':<9} {'motion [s]':>10} {'compile [s]':>11}")
    last = None
    for pause in PAUSES:
        text = TEMPLATE.format(tag=str(pause).replace(".", "_"), pause=pause)
        start = time.perf_counter()
        build = aou_dsl.compile(source=text, path=f"hesitant-{pause}.aou")
        elapsed = time.perf_counter() - start
        if not build.ok or build.measured is None or build.declared is None:
            for d in build.diagnostics:
                print(f"  {d.span}: {d.code} {d.message}")
            return 1
        cv = build.lint.cv
        assert cv is not None
        print(f"{pause:9.2f} {build.declared['pause_duration']:9.3f} "
              f"{build.measured.descriptors['pause_duration']:9.3f} {cv.C:+6.2f} {cv.V:+6.2f} "
              f"{cv.state.value:<9} {build.trajectory.duration:10.2f} {elapsed:11.2f}")
        last = build
    assert last is not None and last.document is not None
    path = out / "hesitant-last.json"
    path.write_text(json.dumps(last.document))
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
