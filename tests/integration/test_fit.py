"""`--fit`: what the arm cannot give is changed to what it can, by the fewest values and
the least amount, keeping the declared state and the order of a variant pair; each
change is a C314 warning. Without `--fit`, a refusal's hint holds every change it needs:
applying it compiles in one round."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from aou_dsl.cli.commands import main
from aou_dsl.driver.builder import build_file, build_source
from aou_dsl.fit.plan import KNEE, compress
from aou_dsl.lang.linter import lint_source
from tests.conftest import BEHAVIOURS
from tests.integration.test_fit_reach import apply_hint

FEARFUL = BEHAVIOURS / "fearful.aou"


def test_compress_keeps_what_fits_and_the_order_of_what_does_not():
    cap = 1.46
    assert compress(0.5, cap) == 0.5 and compress(KNEE * cap, cap) == KNEE * cap
    xs = [1.4, 1.5, 2.0, 2.5, 3.0, 5.0, 50.0]
    ys = [compress(x, cap) for x in xs]
    assert all(a < b for a, b in itertools.pairwise(ys))
    assert all(y < cap for y in ys)


#: A Kinova Gen3 (7 joints) described by hand from Kinova's published kinematics, as
#: vendors ship URDFs: package:// meshes (not shipped: only collision shapes are read),
#: continuous joints, the base off the world origin.
GEN3 = str(Path(__file__).resolve().parents[1] / "vendor" / "kinova_gen3_description" / "urdf"
           / "gen3.urdf")


@pytest.mark.parametrize("robot", ["ur5", "ur10", "z1", "kinova", GEN3])
def test_the_fearful_stimulus_is_refused_where_no_shiver_keeps_its_look(robot):
    """Refused as written on these arms. Their wrists follow its shiver only slower than
    a tremor (2.5 Hz) or, at 2.5 Hz, too narrow to stay fearful: --fit refuses (C315,
    saying why) instead of turning the tremor into slow rolls, and writes nothing."""
    assert not build_file(str(FEARFUL), robot=robot).ok
    res = build_file(str(FEARFUL), robot=robot, fit=True)
    assert not res.ok  # what the fit wrote keeps the shiver as it was, not slower
    assert res.fitted_source is None or "shiver 6deg for 1.25s" in res.fitted_source
    assert not [d for d in res.diagnostics if d.code == "C314" and d.fields.get("key") == "f"]
    (c,) = [d for d in res.diagnostics if d.code == "C315"]
    assert c.span.line == 8 and "`hesitant`, not `fearful`" in c.message, c.message
    assert "slow rolls" in c.message and c.hint


FEARFUL_SLOW = FEARFUL.read_text().replace("shiver 6deg for 1.25s",
                                           "shiver 6deg f=1.4Hz for 2.15s")


def test_a_variant_pair_keeps_its_order_when_fitted():
    """Part B varies one descriptor: two retreat accelerations the UR5 cannot give are
    fitted to two it can, in the same order."""
    text = "behaviour f : fearful\nrobot ur5\napproach a=0.1\npause 1.25s x4\n" \
           "retreat 0.06m a={a}\nshiver 6deg f=1.4Hz for 2.15s\n"
    got = []
    for a in (2, 3):
        res = build_source(text.format(a=a), "pair.aou", fit=True, check=False)
        assert res.ok, [(d.code, d.message) for d in res.diagnostics]
        (c,) = [d for d in res.diagnostics if d.code == "C314"]
        assert c.fields["descriptor"] == "retreat_acceleration"
        got.append(float(c.fields["fitted"]))
    assert got[0] < got[1]


def test_a_fit_that_would_change_the_state_is_not_made():
    """A mild fearful (small slow shiver) leans on its sudden retreat: slowing the retreat
    to what the UR5 gives would make it read hesitant, so nothing is fitted."""
    text = "behaviour f : fearful\nrobot ur5\napproach a=0.1\npause 1.25s x4\n" \
           "retreat 0.06m a=2\nshiver 3deg f=1Hz\n"
    res = build_source(text, "mild.aou", fit=True, check=False)
    (c,) = [d for d in res.diagnostics if d.code == "C314"]
    assert c.message.startswith("not fitted") and "`hesitant`, not `fearful`" in c.message
    assert res.fitted_source is None


def test_nothing_to_fit_changes_nothing():
    res = build_file(str(BEHAVIOURS / "hesitant.aou"), fit=True, check=False)
    assert res.ok and res.fitted_source is None
    assert not [d for d in res.diagnostics if d.code == "C314"]
    assert "fitted" not in res.header


def _shivers():
    for amp, f, dur in itertools.product((4, 8), (2.5, 4), ("", " for 1s")):
        yield f"behaviour s\nrobot ur5\napproach a=0.1\npause 1.25s x4\n" \
              f"retreat 0.06m a=1\nshiver {amp}deg f={f}Hz{dur}\n"
    for v in (120, 300):
        yield f"robot ur5\napproach a=0.1\npause 1s\ntilt 20deg v={v}\n"


@pytest.mark.parametrize("text", list(_shivers()))
def test_applying_a_refusals_hint_compiles_in_one_round(text):
    res = build_source(text, "gen.aou", check=False)
    refused = [d for d in res.diagnostics if d.severity.name == "ERROR"]
    if not refused:
        pytest.skip("the arm gives it as written")
    (d,) = refused
    assert d.hint and d.hint.startswith("write `"), d.hint
    fixed = apply_hint(text, d)
    assert fixed != text
    again = build_source(fixed, "gen.aou", check=False)
    assert again.ok, (fixed, [(x.code, x.message) for x in again.diagnostics])
    lengthened = [x for x in lint_source(fixed, "gen.aou").diagnostics if x.code == "V126"]
    assert not lengthened or " for 1s" in text  # the hint adds no lengthened `for`


def test_write_fitted_writes_the_fitted_file_and_never_over_its_input(tmp_path, capsys):
    src = tmp_path / "fearful.aou"
    src.write_text(FEARFUL_SLOW)
    out = tmp_path / "fearful-ur5.aou"
    code = main(["compile", str(src), "--robot", "ur5", "--fit", "--no-check",
                 "--write-fitted", str(out), "-o", str(tmp_path / "f.json")])
    assert code == 0
    text = out.read_text()
    assert "retreat 0.06m a=1.437" in text and "shiver 6deg f=1.4Hz for 2.15s" in text
    assert text.splitlines()[:5] == FEARFUL_SLOW.splitlines()[:5]
    err = capsys.readouterr().err
    assert err.count(" C314 ") >= 1
    assert main(["compile", str(src), "--robot", "ur5", "--fit", "--no-check",
                 "--write-fitted", str(src), "-o", str(tmp_path / "g.json")]) == 2
    assert main(["compile", str(src), "--write-fitted", str(out)]) == 2


def test_check_fits_a_behaviour_before_its_replay(tmp_path, capsys):
    """A 4 Hz shiver the UR10's wrist follows at 2.5 Hz, still a tremor: fitted slower."""
    src = tmp_path / "s.aou"
    src.write_text("behaviour s\napproach a=0.1\npause 1s\nshiver 2deg f=4Hz\n")
    out = tmp_path / "fitted.aou"
    assert main(["check", str(src), "--robot", "ur10", "--no-dynamic"]) == 1
    capsys.readouterr()
    assert main(["check", str(src), "--robot", "ur10", "--no-dynamic", "--fit",
                 "--write-fitted", str(out)]) == 0
    err = capsys.readouterr().err
    assert " C314 " in err and "shiver 2deg f=2.5Hz" in out.read_text()
    assert main(["check", str(tmp_path / "x.json"), "--fit"]) == 2
