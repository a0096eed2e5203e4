"""The live regulator moves a running reach's intensity through its DMPs, without a
re-plan: the arm's position, velocity and acceleration carry on where the change is
made, the rest of the reach measures as the new intensity's scaling rules predict, and
it passes the same safety checks as a compiled trajectory."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("movement_primitives")

from aou_dsl.core.diagnostics import AouError  # noqa: E402
from aou_dsl.lang.cv import CANONICAL  # noqa: E402
from aou_dsl.lang.descriptors import REGISTRY  # noqa: E402
from aou_dsl.lang.ir import State  # noqa: E402
from aou_dsl.live.regulator import Hysteresis, Regulator  # noqa: E402


@pytest.fixture(scope="module")
def started():
    """A hesitant reach at intensity 0.5 followed as its DMPs, and the first pause's middle
    (the arm's sample there)."""
    reg = Regulator("panda", through_dmp=True)
    plan = reg.plan(State.HESITANT, 0.5)
    first = reg.replan(plan.q[0], None, None, State.HESITANT, 0.5, restart=True)
    tr = first.trajectory
    pause = next((a, b) for k, a, b in tr.episodes if k == "pause")
    i = int(np.searchsorted(tr.t, 0.5 * sum(pause)))
    return reg, first, i


@pytest.fixture(scope="module")
def raised(started):
    """The same reach raised to intensity 1 in its first pause."""
    reg, first, i = started
    tr = first.trajectory
    return reg.change_intensity(tr.q[i], tr.qd[i], tr.qdd[i], 1.0, elapsed=float(tr.t[i]))


def _within(name, want, got) -> bool:
    return abs(got - want) <= REGISTRY[name].tolerance(want) + 1e-9


def test_the_change_carries_on_from_the_arms_state(started, raised):
    """The trajectory returned starts at the arm's sample (q, qd, qdd equal), is the
    running one until the running part ends, and its joint accelerations step from
    sample to sample by no more than the running trajectory's do (continuous q, qd,
    qdd where the new parameters take over)."""
    _, first, i = started
    old, new = first.trajectory, raised.trajectory
    assert raised.transition == 0.0 and raised.intensity == 1.0
    for a, b in ((old.q, new.q), (old.qd, new.qd), (old.qdd, new.qdd)):
        assert np.array_equal(a[i], b[0])
    end = next(b for k, a, b in new.episodes if k == "pause")  # the running pause's end
    n = int(np.searchsorted(new.t, end))
    assert np.array_equal(new.q[:n], old.q[i:i + n])
    step_old = np.abs(np.diff(old.qdd, axis=0)).max()
    assert np.abs(np.diff(new.qdd, axis=0)).max() <= 1.05 * step_old


def test_the_rest_measures_as_the_new_intensity(started, raised):
    """From the first part that takes the new intensity on, the motion measures the
    descriptors the scaling rules give at intensity 1: hesitance reads stronger with
    pauses the synthesis' span (1.5x) longer; counts, distances and angles unchanged."""
    from aou_dsl.measuring.measured import measure

    reg, _, _ = started
    new = raised.trajectory
    ro = reg._dmp.rollout
    src = reg._dmp.sequence.descriptors
    t0 = next(b for k, a, b in new.episodes if k == "pause")
    i = int(np.searchsorted(new.t, t0))
    rest = new.with_(t=new.t[i:] - new.t[i], q=new.q[i:], qd=new.qd[i:], qdd=new.qdd[i:],
                     episodes=())
    m = measure(rest).descriptors
    assert ro.intensity == 1.0
    assert _within("pause_duration", 1.5 * src["pause_duration"], m["pause_duration"])
    for name in ("pause_duration", "approach_acceleration", "retreat_acceleration",
                 "retreat_distance"):
        assert _within(name, ro.predicted[name], m[name]), (name, ro.predicted[name], m[name])


def test_the_changed_motion_stays_within_the_arms_limits(raised):
    """The rest of the reach passes the safety replay (joint limits, collisions) and the
    controllers' checks."""
    from aou_dsl.safety.controllers import controller_checks
    from aou_dsl.safety.replay import replay

    tr = raised.trajectory
    report = replay(tr)
    report.checks += controller_checks(tr, None)
    assert report.ok, [c.name for c in report.failed()]


def test_update_moves_the_intensity_through_the_dmps():
    """update() with a new intensity level of the expressed state changes it through the
    DMPs (no transition: the trajectory starts at the arm's state); a second change
    keeps the first one's parts; a new state re-plans as before (an estimate given
    directly, not a camera's: a one-level change passes the hysteresis)."""
    reg = Regulator("panda", through_dmp=True, hysteresis=Hysteresis(intensity=0.05))
    c, v = CANONICAL[State.HESITANT]
    plan = reg.plan(State.HESITANT, 0.5)
    start = reg.update(plan.q[0], C=c, V=v, intensity=0.5)
    assert start is not None and reg._dmp is not None
    tr = start.trajectory
    i = int(np.searchsorted(tr.t, tr.episodes[1][1] + 0.1))
    up = reg.update(tr.q[i], tr.qd[i], tr.qdd[i], C=c, V=v, intensity=1.0,
                    elapsed=float(tr.t[i]))
    assert up is not None and up.intensity == 1.0 and up.transition == 0.0
    assert np.array_equal(up.trajectory.q[0], tr.q[i])
    tr = up.trajectory
    j = int(np.searchsorted(tr.t, tr.episodes[2][1] + 0.1))
    down = reg.update(tr.q[j], tr.qd[j], tr.qdd[j], C=c, V=v, intensity=0.75,
                      elapsed=float(tr.t[j]))
    assert down is not None and down.intensity == 0.75
    assert np.array_equal(down.trajectory.qdd[0], tr.qdd[j])
    assert [x for _, x in reg._dmp.rollout.schedule] == [0.5, 1.0, 0.75]
    c2, v2 = CANONICAL[State.CURIOUS]
    other = reg.update(tr.q[j], tr.qd[j], tr.qdd[j], C=c2, V=v2, intensity=0.5)
    assert other is not None and other.state is State.CURIOUS and reg._dmp is None


def test_change_without_a_dmp_reach_is_refused():
    """A regulator that follows compiled plans has no DMPs to change: I504."""
    reg = Regulator("panda")
    with pytest.raises(AouError) as err:
        reg.change_intensity(np.zeros(7), None, None, 1.0)
    assert err.value.diagnostics[0].code == "I504"
