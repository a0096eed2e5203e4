"""One message per cause: a statement repeated is compiled once per repeat, but what
goes wrong with it is said once, with the count; C310 is not said of a value C304 has
explained; a robot's unsourced limits (C313) are said once per robot in a run."""

from __future__ import annotations

from aou_dsl.core.diagnostics import Span, diag
from aou_dsl.core.repeats import once_per_run, said_once
from aou_dsl.driver.builder import build_source
from aou_dsl.driver.parallel import build_many

RETREAT = """behaviour r : fearful
robot ur5
approach a=0.1
pause 1.25s x4
retreat 5mm a=2 x3
"""


def test_a_compiler_diagnostic_at_one_statement_is_folded_keeping_the_lowest_reach():
    at = Span("f.aou", 5, 1, 5, 20)
    said = [diag("C304", f"retreat reaches {a} m/s^2", at, achieved=a, declared=2.0)
            for a in (1.5, 1.42, 1.47)]
    other = Span("f.aou", 6, 1, 6, 20)
    lint = [diag("V101", "one", at), diag("V101", "two", at)]
    out = said_once([*said, diag("C304", "elsewhere", other, achieved=1.0), *lint])
    assert [d.code for d in out] == ["C304", "C304", "V101", "V101"]
    assert out[0].fields["achieved"] == 1.42 and out[0].fields["repeats"] == 3
    assert "3 repeats" in out[0].message
    assert "repeats" not in out[1].fields  # one of its kind: as it was


def test_a_repeated_retreat_the_arm_cannot_give_is_said_once_and_not_again_as_c310():
    res = build_source(RETREAT, "r.aou")
    codes = [d.code for d in res.diagnostics]
    assert codes.count("C304") == 1, codes
    (c304,) = [d for d in res.diagnostics if d.code == "C304"]
    assert c304.fields["repeats"] == 3
    assert c304.fields["descriptor"] == "retreat_acceleration"
    assert not [d for d in res.diagnostics if d.code == "C310"
                and d.fields.get("descriptor") == "retreat_acceleration"]
    assert res.ok


def test_unsourced_limits_are_said_once_per_robot_in_a_run(tmp_path):
    paths = []
    for k in range(3):
        p = tmp_path / f"b{k}.aou"
        p.write_text(f"robot ur5\napproach a=0.{k + 1}\npause 1s\n")
        paths.append(str(p))
    results = list(build_many(paths))
    per_file = [[d.code for d in r.diagnostics].count("C313") for r in results]
    assert per_file == [1, 0, 0]
    assert all(r.ok for r in results)


def test_once_per_run_leaves_a_kept_result_unchanged():
    class R:
        def __init__(self):
            self.diagnostics = [diag("C313", "robot `x`: no sourced limit",
                                     Span.whole_file("a"))]

    a, b = R(), R()
    out = list(once_per_run([a, b]))
    assert out[0] is a and len(out[1].diagnostics) == 0
    assert len(b.diagnostics) == 1
