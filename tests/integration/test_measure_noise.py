"""Measuring noisy recordings: every descriptor carries a 95 % interval that holds what
the file declares as often as it claims, a segmentation the noise can flip is said
(R411) instead of guessed, and ``measure --against`` answers pass, fail or
inconclusive (exit 0, 1 or 3).

The recordings are the compiled behaviours logged by tests/recsim.py with encoder noise
from 1e-4 to 1e-3 rad, a jittered clock, dropped samples and an encoder's resolution.
The arm's own motion is the compiled one (no dynamic replay): the truth the intervals
must hold is then what the file declares, and nothing but the logger stands between
the two. The expected values are the declared ones (``aou_dsl.lang.declared``), never
what measure printed.

``python -m tests.integration.test_measure_noise [N]`` prints the coverage per noise level and
descriptor over the shipped behaviours and N generated ones (docs/measure.md's table).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from aou_dsl.cli.commands import main
from aou_dsl.core.trajectory import Trajectory
from aou_dsl.lang.descriptors import REGISTRY
from aou_dsl.measuring.measured import Measured, measure
from aou_dsl.measuring.verdict import FAIL, INCONCLUSIVE, PASS, _result
from tests.conftest import BEHAVIOURS
from tests.integration.test_recordings import build, generated
from tests.recsim import NOISE_LEVELS as NOISES
from tests.recsim import Logger, record, to_csv_text
from tests.recsim import noisy as logger

GOAL = ("--goal", "0.55,0,0.25")


def logged(doc: dict, log: Logger) -> tuple[dict, Measured]:
    rec = record(doc, log, dynamic=False)
    tr = Trajectory(rec["t"], rec["q"], tuple(rec["joint_names"]), rec["robot"], None,
                    tuple(rec["goal"]["position"]))
    return rec, measure(tr)


def coverage(items, noises=NOISES, rates=(1000.0,)) -> dict[tuple[str, float], list[bool]]:
    """Per descriptor and noise level: for each recording where the copies agree on it,
    whether its interval holds the declared value (a count: whether it is exact). A
    recording whose copies disagree is left out of its descriptor's list: R411 said it
    is not to be trusted, which the tests check apart."""
    out: dict[tuple[str, float], list[bool]] = {}
    for i, (doc, want, _) in enumerate(items):
        for noise in noises:
            for rate in rates:
                _, m = logged(doc, logger(noise, rate, 100 * i + int(noise * 1e5)))
                for k, d in REGISTRY.items():
                    s, w = m.uncertainty[k], want[k]
                    if not s.stable:
                        continue
                    if d.is_count:
                        held = (w or 0) == (m.descriptors[k] or 0)
                    elif w is None or s.low is None:
                        held = w is None and m.descriptors[k] is None
                    else:
                        held = s.low <= w <= s.high
                    out.setdefault((k, noise), []).append(held)
    return out


@pytest.fixture(scope="module")
def shipped():
    return {name: build((BEHAVIOURS / f"{name}.aou").read_text(), name)
            for name in ("hesitant", "fearful", "curious")}


def test_intervals_hold_the_declared_values_as_often_as_they_claim(shipped):
    """Three shipped behaviours (pauses, retreats, gazes, a shiver) logged at 250 Hz,
    each at 1e-4 to 1e-3 rad: counts exact and every value's 95 % interval holding the
    declared one in at least 95 % of the cases, with none of them thrown out as
    untrusted up to 3e-4 rad."""
    cov = coverage(list(shipped.values()), rates=(250.0,))
    counts = [ok for (k, _), oks in cov.items() if REGISTRY[k].is_count for ok in oks]
    values = [ok for (k, _), oks in cov.items() if not REGISTRY[k].is_count for ok in oks]
    assert all(counts)
    assert np.mean(values) >= 0.95, {k: np.mean(v) for k, v in cov.items()}
    low = [len(v) for (k, noise), v in cov.items() if noise <= 3e-4]
    assert min(low) == len(shipped)  # every recording trusted on every descriptor


def test_a_trajectory_without_noise_is_measured_exactly(shipped):
    """A compiled trajectory has no noise: every interval is the value itself, and
    nothing warns."""
    from aou_dsl.driver.builder import build_file

    res = build_file(str(BEHAVIOURS / "hesitant.aou"), check=False)
    m = measure(res.trajectory)
    for k, v in m.descriptors.items():
        s = m.uncertainty[k]
        assert (s.low, s.high, s.stable) == (v, v, True), k
    assert not [d for d in m.diagnostics if d.code == "R411"]
    inf = m.inferred
    assert (inf.C.low, inf.C.high, inf.V.low, inf.V.high) == (m.cv.C, m.cv.C, m.cv.V, m.cv.V)
    assert inf.states == (m.cv.state.value,)
    assert (inf.sight_max.low, inf.sight_max.high) == (m.line_of_sight.max,) * 2


def test_the_inferred_state_and_the_line_of_sight_carry_their_interval(shipped, tmp_path,
                                                                       capsys):
    """The C-V point and the line of sight come from the whole motion: each gets an
    interval from the same copies. Over logs of the hesitant and the fearful, the point
    the compiled motion itself measures (the truth) lies inside the recording's
    intervals, or the copies disagree on the state and R411 says so; at 1e-3 rad and 250
    Hz the hesitant's state is such a case, and the text, the JSON and the warning
    show it."""
    from aou_dsl.driver.builder import build_file

    for name, noise, rate, seed in (("hesitant", 3e-4, 1000.0, 1), ("fearful", 6e-4, 250.0, 2),
                                    ("hesitant", 6e-4, 250.0, 4)):
        truth = build_file(str(BEHAVIOURS / f"{name}.aou"), check=False).measured.cv
        _, m = logged(shipped[name][0], logger(noise, rate, seed))
        inf = m.inferred
        assert inf.C.sd + inf.V.sd > 0  # (a coordinate at its bound, 1, may not move)
        if len(inf.states) == 1:
            assert inf.C.low <= truth.C <= inf.C.high, (name, noise, inf.C, truth)
            assert inf.V.low <= truth.V <= inf.V.high, (name, noise, inf.V, truth)
    path = _csv(tmp_path, shipped["hesitant"][0], logger(1e-3, 250.0, 3))
    assert main(["measure", path, "--robot", "panda", *GOAL]) == 0
    out, err = capsys.readouterr()
    line = next(ln for ln in out.splitlines() if "C-V:" in ln)
    assert line.count("+") >= 3 and "the re-noised copies read" in line, line
    assert "the inferred state reads" in err and " R411 " in err
    assert main(["measure", path, "--robot", "panda", *GOAL, "--format", "json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    got = doc["inferred_uncertainty"]
    assert len(got["states"]) > 1 and doc["cv"]["state"] in got["states"]
    assert got["C"]["low"] < doc["cv"]["C"] < got["C"]["high"]
    sight = got["line_of_sight_max_deg"]
    assert sight["low"] < doc["line_of_sight"]["max_deg"] < sight["high"]


def test_more_noise_than_the_segmentation_bears_is_said_with_its_level(shipped):
    """1e-3 rad at 250 Hz on the hesitant's slow approaches: its retreat count cannot be
    trusted (its pauses, now read through the slow motion beside them, can). R411 gives
    the noise level and names the descriptors it affects, and the count's interval
    reaches past one value."""
    doc = shipped["hesitant"][0]
    _, m = logged(doc, logger(1e-3, 250.0, 3))
    (warn,) = [d for d in m.diagnostics if d.code == "R411"]
    assert "0.001 rad" in warn.message
    shaky = warn.fields["descriptors"]
    assert "retreat_count" in shaky
    s = m.uncertainty["retreat_count"]
    assert s.low < s.high and not s.stable
    # A value whose interval is far wider than itself is named too.
    assert all(k in shaky for k, sp in m.uncertainty.items()
               if sp.low is not None and m.descriptors[k] is not None
               and not REGISTRY[k].is_count
               and sp.high - sp.low > 0.5 * abs(m.descriptors[k]) + 1e-9)


def test_the_interval_grows_with_the_noise(shipped):
    """The same motion logged at 1e-4 and 1e-3 rad: the acceleration's interval widens
    about tenfold (the copies carry the noise the recording shows)."""
    doc = shipped["fearful"][0]
    half = []
    for noise in (1e-4, 1e-3):
        _, m = logged(doc, logger(noise, 1000.0, 5))
        s = m.uncertainty["retreat_acceleration"]
        half.append((s.high - s.low) / 2)
    assert 4 < half[1] / half[0] < 25



#: A slow retreat straight into a shiver, a pause, a shiver between two approaches: the
#: shivers' envelopes fade in and out over a cycle, and under the noise their soft ends
#: look like a hold beside the pauses declared.
SOFT_ENDS = """robot ur5
goal (0.46, 0.17, 0.16)
sequence {
  approach a=0.1
  pause 1.5s
  retreat 5cm a=0.05m/s^2
  shiver 1.9deg f=2Hz for 1.7s
  pause 1s
  approach 3cm a=0.1
  shiver 3.9deg f=1.5Hz for 2s
  approach 2cm a=0.1
}
"""


def test_a_shivers_soft_start_or_end_is_no_pause():
    """At 250 Hz with 6e-4 and 1e-3 rad, a shiver's fading ends hide under the noise
    for a fifth of a second: a pause only when the joints hold still once the
    oscillation's own start and end are found. No log makes every copy read a count
    the file does not declare (that would fail a verdict on noise alone), and at
    6e-4 rad most logs read the declared count in every copy."""
    doc, want, _ = build(SOFT_ENDS, "soft")
    exact = 0
    for noise, seed in ((6e-4, 0), (6e-4, 1), (6e-4, 2), (1e-3, 3), (1e-3, 4)):
        _, m = logged(doc, logger(noise, 250.0, seed))
        s = m.uncertainty["pause_count"]
        assert s.low <= want["pause_count"] <= s.high, (noise, seed, s)
        exact += noise < 1e-3 and s.stable and m.descriptors["pause_count"] == 2
    assert want["pause_count"] == 2 and exact >= 2

#: An approach (a=0.0968) whose acceleration rises above its phase's level by less than an
#: arm's transients would (about 0.7 %): a recording reads the level, 0.7 % low, at any
#: noise (a generated behaviour of the calibration set).
UNRESOLVED = """goal (0.57, 0.002m, 0.289)
sequence {
  retreat 0.0423m; pause 1.4s
  shiver 7.16deg for 1.13s
  pause 1.31s; approach a=0.0968
  tilt -0.3591rad v=6.4deg/s
  approach -3.25cm x0
  pause 1.44s
}
start 0.299m
"""


def test_a_peak_the_reading_cannot_resolve_is_inside_the_interval():
    """Logged at 1 kHz with 1e-4 and 3e-4 rad, the approach reads its phase's level,
    below the declared peak by more than the noise explains: the interval reaches above
    the reading by what a reading cannot resolve, and holds the declared value; below
    the reading it reaches only as far as the noise does."""
    doc, want, _ = build(UNRESOLVED, "unresolved")
    declared = want["approach_acceleration"]
    for noise, seed in ((1e-4, 1), (3e-4, 2)):
        _, m = logged(doc, logger(noise, 1000.0, seed))
        v, s = m.descriptors["approach_acceleration"], m.uncertainty["approach_acceleration"]
        assert s.stable and v < declared - 4 * s.sd, (noise, v, s)
        assert s.low <= declared <= s.high, (noise, v, s)
        assert v - s.low < s.high - v - 0.009 * v, (noise, v, s)


# --- the three-way verdict ---------------------------------------------------------------


@pytest.mark.parametrize("low,high,result", [
    (0.0495, 0.0505, PASS),              # the whole interval within 0.05 +- 0.0015
    (0.0530, 0.0560, FAIL),              # none of it
    (0.0460, 0.0480, FAIL),
    (0.0500, 0.0530, INCONCLUSIVE),      # straddles the upper edge
    (0.0400, 0.0600, INCONCLUSIVE),      # straddles both
])
def test_an_interval_across_the_tolerance_edge_is_inconclusive(low, high, result):
    d = REGISTRY["approach_acceleration"]
    got = (low + high) / 2
    assert _result(d, 0.05, got, low, high, True) == result


def test_a_count_or_presence_the_noise_can_flip_is_inconclusive():
    count = REGISTRY["pause_count"]
    assert _result(count, 5, 5, 5, 5, True) == PASS
    assert _result(count, 5, 5, 4, 5, False) == INCONCLUSIVE
    assert _result(count, 5, 7, 6, 7, False) == FAIL  # no copy reads 5
    gaze = REGISTRY["horizontal_gaze"]
    assert _result(gaze, None, None, 0.2, 0.2, False) == INCONCLUSIVE
    assert _result(gaze, None, 12.0, 11.0, 13.0, True) == FAIL


def test_a_value_not_to_be_trusted_is_inconclusive_even_outside_the_tolerance():
    """A recording stamped on arrival read 0.119 m/s^2 on its clock evened out and 0.071
    on its stamps, both marked not to be trusted (R411), for a motion declared and made
    at 0.05: its interval took in both readings and missed the tolerance as a whole, and
    the verdict was a failure of a motion that matched its file. Trusted, the same
    interval fails."""
    d = REGISTRY["approach_acceleration"]
    assert _result(d, 0.05, 0.071, 0.065, 0.119, False) == INCONCLUSIVE
    assert _result(d, 0.05, 0.071, 0.065, 0.119, True) == FAIL


def _csv(tmp_path: Path, doc: dict, log: Logger) -> str:
    rec = record(doc, log, dynamic=False)
    path = tmp_path / "run.csv"
    path.write_text(to_csv_text(rec))
    return str(path)


def test_measure_against_exits_3_when_only_the_noise_leaves_a_descriptor_open(
        shipped, tmp_path, capsys):
    """3e-4 rad at 250 Hz: the retreat's peak acceleration reads within its 3 % but its
    interval reaches past it. Nothing fails, so exit 3 (not 0, not 1), the row says
    INCONCLUSIVE with its interval, R412 warns at the statement, and the JSON carries
    the result and the interval of every row."""
    path = _csv(tmp_path, shipped["hesitant"][0], logger(3e-4, 250.0, 3))
    hesitant = str(BEHAVIOURS / "hesitant.aou")
    assert main(["measure", path, "--robot", "panda", *GOAL, "--against", hesitant]) == 3
    out, err = capsys.readouterr()
    rows = {ln.split()[0]: ln for ln in out.splitlines()[2:13]}
    assert rows["retreat_acceleration"].endswith("INCONCLUSIVE")
    assert "+-" in rows["retreat_acceleration"]
    assert rows["pause_count"].endswith("pass")
    assert " R412 " in err and " R408 " not in err
    assert main(["measure", path, "--robot", "panda", *GOAL, "--against", hesitant,
                 "--format", "json"]) == 3
    doc = json.loads(capsys.readouterr().out)
    assert doc["result"] == "inconclusive" and doc["ok"] is False
    row = next(r for r in doc["descriptors"] if r["descriptor"] == "retreat_acceleration")
    assert row["result"] == "inconclusive" and row["ok"] is False
    assert row["low"] < row["declared"] - row["tolerance"] < row["measured"] < row["high"]


def test_a_real_miss_still_fails_under_noise(shipped, tmp_path, capsys):
    """The same log judged against a file with 2 s pauses: a fail stays a fail (exit 1),
    whatever else is inconclusive."""
    other = tmp_path / "longer.aou"
    other.write_text((BEHAVIOURS / "hesitant.aou").read_text().replace("pause 1.67s",
                                                                        "pause 2s"))
    path = _csv(tmp_path, shipped["hesitant"][0], logger(3e-4, 250.0, 3))
    assert main(["measure", path, "--robot", "panda", *GOAL, "--against", str(other)]) == 1
    out = capsys.readouterr().out
    assert next(ln for ln in out.splitlines() if ln.split()[:1] == ["pause_duration"]
                ).endswith("FAIL")


def test_no_interval_reaches_below_zero_for_a_magnitude(shipped):
    """The eleven descriptors and the line of sight are magnitudes; the copies' spread
    put hesitant's approach at 1e-3 rad and 250 Hz in -2.8 to 1.9 m/s^2. An interval
    reaching below zero tells the reader nothing the zero does not."""
    _, m = logged(shipped["hesitant"][0], logger(1e-3, 250.0, 3))
    lows = {k: s.low for k, s in m.uncertainty.items() if s.low is not None}
    assert lows and min(lows.values()) >= 0.0, lows
    approach = m.uncertainty["approach_acceleration"]
    assert approach.low == 0.0 and not approach.stable  # reaching down to it: R411
    sight = m.inferred.sight_max
    assert sight is not None and sight.low >= 0.0


def test_measure_prints_and_writes_every_interval(shipped, tmp_path, capsys):
    path = _csv(tmp_path, shipped["fearful"][0], logger(3e-4, 250.0, 2))
    assert main(["measure", path, "--robot", "panda", *GOAL]) == 0
    out = capsys.readouterr().out
    row = out.split("shiver_amplitude")[1].splitlines()[0].split()
    assert row[-1] == "deg" and (row[1] == "+-" or row[1].startswith("+")), row
    # A count every copy reads alike is not "exact": that is a value read without noise.
    counts = [ln for ln in out.splitlines() if ln.split()[:1] == ["pause_count"]]
    assert counts and "exact" not in counts[0], out
    assert main(["measure", path, "--robot", "panda", *GOAL, "--format", "json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert set(doc["uncertainty"]) == set(REGISTRY) and doc["uncertainty_level"] == 0.95
    for k, v in doc["descriptors"].items():
        u = doc["uncertainty"][k]
        if v is not None and not REGISTRY[k].is_count:
            assert u["low"] < v < u["high"] and u["sd"] > 0, k


#: Generated behaviours in the slow calibration (the default run logs three shipped ones).
CALIBRATION = 100


@pytest.fixture(scope="module")
def calibration_set():
    """The shipped behaviours and :data:`CALIBRATION` generated ones."""
    items = [build((BEHAVIOURS / f"{s}.aou").read_text(), s)
             for s in ("confident", "curious", "hesitant", "fearful", "inactive")]
    return items + [b for _, b in generated(CALIBRATION, 11)]


@pytest.mark.slow
@pytest.mark.large
@pytest.mark.parametrize("rate", [250.0, 1000.0])
@pytest.mark.parametrize("noise", NOISES)
def test_generated_behaviours_intervals_hold_the_declared_values(calibration_set, noise,
                                                                 rate):
    """The larger variant: the shipped behaviours and 100 generated ones, at each rate
    and noise level (one test each, so that none runs for long): at least 95 % of the
    trusted values inside their interval, and below 1e-3 rad at least 97 % of the
    counts the copies agree on exact."""
    assert len(calibration_set) == 5 + CALIBRATION
    cov = coverage(calibration_set, noises=(noise,), rates=(rate,))
    values = [ok for (k, _), oks in cov.items() if not REGISTRY[k].is_count for ok in oks]
    assert np.mean(values) >= 0.95, {k: np.mean(v) for k, v in cov.items()}
    if noise < 1e-3:
        counts = [ok for (k, _), oks in cov.items() if REGISTRY[k].is_count for ok in oks]
        assert np.mean(counts) >= 0.97


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    items = [build((BEHAVIOURS / f"{s}.aou").read_text(), s)
             for s in ("confident", "curious", "hesitant", "fearful", "inactive")]
    items += [b for _, b in generated(n, 11)]
    for rate in (250.0, 1000.0):
        cov = coverage(items, rates=(rate,))
        print(f"{rate:g} Hz, {len(items)} behaviours")
        for noise in NOISES:
            vals = [ok for (k, nz), oks in cov.items() if nz == noise
                    and not REGISTRY[k].is_count for ok in oks]
            cnts = [ok for (k, nz), oks in cov.items() if nz == noise
                    and REGISTRY[k].is_count for ok in oks]
            print(f"  {noise:g} rad: values held {np.mean(vals):.3f} ({len(vals)}), "
                  f"stable counts exact {np.mean(cnts):.3f} ({len(cnts)})")
        for (k, noise), oks in sorted(cov.items()):
            if not all(oks):
                print(f"    {k} at {noise:g}: {np.mean(oks):.2f} of {len(oks)}")
