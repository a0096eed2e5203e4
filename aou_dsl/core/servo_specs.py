"""The servos of the arms aou knows: what ``--track`` simulates an arm's joints with.

A servo here is the joint controller of a position-controlled arm, per joint: a
proportional gain ``kp`` [N m/rad] on the position error, a derivative gain ``kv``
[N m s/rad] on the velocity (error, with feed-forward), the joint's own viscous
``damping`` [N m s/rad], the motor's reflected inertia ``armature`` [kg m^2] added to
the joint, and the torque the motor can give, ``force`` [N m]. Each table also says the
controller's ``rate`` [Hz] and the modes it offers.

Every number names its source. The Panda's, the UR5e's and the Kinova Gen3's are the
position servos of MuJoCo Menagerie's published models of those arms (the files
``franka_emika_panda/panda.xml``, ``universal_robots_ur5e/ur5e.xml`` and
``kinova_gen3/gen3.xml``; their values are written here, no file of theirs is read at
run time). The rates are the vendors' controller rates. An arm without a table gets
:func:`generic_table` and a C323 warning; a robot description's ``[servo]`` table gives an
arm's own identified values.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["GENERIC_SOURCE", "MODES", "SERVOS", "ServoTable", "generic_table", "servo_table"]

#: The servo modes ``--servo`` names, in the order reports list them:
#: ``position`` (plain set-points), ``feedforward`` (set-points and the velocity the
#: trajectory carries), ``torque`` (set-points, velocity and the inverse-dynamics torque).
MODES = ("position", "feedforward", "torque")


@dataclass(frozen=True)
class ServoTable:
    """One arm's servos, one entry per arm joint (in the arm's joint order).

    Attributes:
        kp: position gains [N m/rad]; kv: velocity gains [N m s/rad].
        damping: joint damping [N m s/rad]; armature: reflected motor inertia [kg m^2].
        force: torque limits [N m] (0: the URDF's effort limit).
        rate: the controller's rate [Hz]; the simulation steps at it.
        modes: the servo modes the arm's controller offers (of :data:`MODES`).
        source: where the numbers come from, in words.
    """

    kp: tuple[float, ...]
    kv: tuple[float, ...]
    damping: tuple[float, ...]
    armature: tuple[float, ...]
    force: tuple[float, ...]
    rate: float
    modes: tuple[str, ...]
    source: str

    @property
    def n(self) -> int:
        return len(self.kp)

    def to_json(self) -> dict:
        return {"kp": list(self.kp), "kv": list(self.kv), "damping": list(self.damping),
                "armature": list(self.armature), "force": list(self.force),
                "rate_hz": self.rate, "modes": list(self.modes), "source": self.source}


def _rows(*groups: tuple[int, float]) -> tuple[float, ...]:
    """``(count, value)`` groups as one tuple: ``_rows((4, 1.0), (3, 2.0))``."""
    return tuple(v for n, v in groups for _ in range(n))


_MENAGERIE = "MuJoCo Menagerie's published model"

#: Franka Emika Panda: Menagerie's franka_emika_panda/panda.xml, actuators 1-7 (class
#: "panda": armature 0.1, damping 1; kp 4500, 3500, 2000 for joints 1-2, 3-4, 5-7, kv a
#: tenth of kp, force 87 N m on joints 1-4 and 12 on 5-7). Rate: the Franka Control
#: Interface's 1 kHz; it offers joint position, joint velocity and torque control.
PANDA = ServoTable(
    kp=_rows((2, 4500.0), (2, 3500.0), (3, 2000.0)),
    kv=_rows((2, 450.0), (2, 350.0), (3, 200.0)),
    damping=_rows((7, 1.0)), armature=_rows((7, 0.1)),
    force=_rows((4, 87.0), (3, 12.0)), rate=1000.0, modes=MODES,
    source=f"{_MENAGERIE} franka_emika_panda/panda.xml; 1 kHz: Franka Control Interface")

#: Universal Robots: Menagerie's universal_robots_ur5e/ur5e.xml (classes "size3" for the
#: shoulder and elbow: kp 3500, damping 200, armature 0.1, force 150 N m; "size1" for the
#: wrist: kp 3000, damping 15, armature 0.1, force 28 N m; its position actuators have no
#: kv). The e-Series of the UR5's size; UR publishes no servo gains for the CB3. Rate: the
#: e-Series controller's 500 Hz; ur_robot_driver streams positions (and velocities to its
#: trajectory controller), no joint torques.
UR5E = ServoTable(
    kp=_rows((3, 3500.0), (3, 3000.0)), kv=_rows((6, 0.0)),
    damping=_rows((3, 200.0), (3, 15.0)), armature=_rows((6, 0.1)),
    force=_rows((3, 150.0), (3, 28.0)), rate=500.0, modes=("position", "feedforward"),
    source=f"{_MENAGERIE} universal_robots_ur5e/ur5e.xml (the UR5's e-Series); "
    "500 Hz: the e-Series controller")

#: Kinova Gen3 (7 joints): Menagerie's kinova_gen3/gen3.xml ("large_actuator" on joints
#: 1-4: kp 2000, kv 100, force 105 N m; "small_actuator" on 5-7: kp 500, kv 50, force
#: 52 N m; no armature or damping given). Rate: the Kortex API's 1 kHz low-level loop,
#: which offers position and torque control.
GEN3 = ServoTable(
    kp=_rows((4, 2000.0), (3, 500.0)), kv=_rows((4, 100.0), (3, 50.0)),
    damping=_rows((7, 0.0)), armature=_rows((7, 0.0)),
    force=_rows((4, 105.0), (3, 52.0)), rate=1000.0, modes=MODES,
    source=f"{_MENAGERIE} kinova_gen3/gen3.xml; 1 kHz: Kortex low-level control")

#: The servo of an arm without a table: the softest of the published sets above on
#: every joint (the Panda's wrist servo: kp 2000, kv 200, armature 0.1, damping 1),
#: each joint's force its URDF effort limit, at 1 kHz, every mode.
GENERIC_JOINT = {"kp": 2000.0, "kv": 200.0, "damping": 1.0, "armature": 0.1}
GENERIC_SOURCE = ("aou's generic servo (the Panda's wrist servo of "
                  f"{_MENAGERIE} on every joint, the URDF's effort limits, 1 kHz)")


def generic_table(n: int) -> ServoTable:
    """The generic servo for an arm of ``n`` joints (force 0: the URDF's limits)."""
    g = GENERIC_JOINT
    return ServoTable(kp=(g["kp"],) * n, kv=(g["kv"],) * n, damping=(g["damping"],) * n,
                      armature=(g["armature"],) * n, force=(0.0,) * n, rate=1000.0,
                      modes=MODES, source=GENERIC_SOURCE)


#: Built-in arms (and the names a robot description's ``[servo] table`` may give).
SERVOS: dict[str, ServoTable] = {
    "panda": PANDA, "ur5": UR5E, "ur5_limited": UR5E, "ur5_gripper": UR5E,
    "kinova_gen3": GEN3,
}


def servo_table(robot: str) -> ServoTable | None:
    """The published table of a built-in arm (or a named table), None when there is none."""
    return SERVOS.get(robot)
