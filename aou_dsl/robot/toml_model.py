"""The robot description file (TOML) as a pydantic model: the source of its JSON Schema,
which ships with the package (``aou_dsl/schemas/robot.schema.json``) so editors and other
tools can check a description before aou reads it.

:func:`~.description.read_description` checks a file itself (its messages name the line);
this model says the same of the keys and their types, and a test keeps the two together
(the same keys, the same verdicts on sample files).
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field

__all__ = ["DescriptionFile", "ServoTable"]

Finite = Annotated[float, Field(allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]
Rate = Annotated[float, Field(gt=0.0, allow_inf_nan=False)]
Name = Annotated[str, Field(min_length=1)]
Vec3 = tuple[Finite, Finite, Finite]
Rates = Rate | Annotated[list[Rate], Field(min_length=1)]


Gains = NonNegative | Annotated[list[NonNegative], Field(min_length=1)]


class ServoTable(BaseModel):
    """The arm's servos, for ``--track``: gains per joint (one number, or one per arm
    joint), the controller's rate and modes, where the numbers come from; or ``table``,
    a published table aou knows."""

    model_config = ConfigDict(extra="forbid")

    kp: Gains | None = Field(None, description="[N m/rad]")
    kv: Gains | None = Field(None, description="[N m s/rad]")
    damping: Gains | None = Field(None, description="joint damping [N m s/rad]")
    armature: Gains | None = Field(None, description="reflected motor inertia [kg m^2]")
    force: Gains | None = Field(None, description="[N m]; default: the URDF's effort limit")
    rate: Rate | None = Field(None, description="the controller's rate [Hz]")
    modes: Annotated[list[Literal["position", "feedforward", "torque"]],
                     Field(min_length=1)] | None = None
    source: Name | None = Field(None, description="where the numbers come from")
    table: Name | None = Field(None, description="a published table aou knows")


class DescriptionFile(BaseModel):
    """A robot description: a URDF (``urdf``) or a built-in arm (``robot``), one of the
    two, and what it pins. Lengths in metres, angles in radians, rates per second."""

    model_config = ConfigDict(
        extra="forbid", title="aou robot description",
        json_schema_extra={"oneOf": [{"required": ["urdf"]}, {"required": ["robot"]}]})

    urdf: Name | None = Field(None, description="the URDF, relative to this file")
    robot: Name | None = Field(None, description="a built-in arm this file extends")
    package_dirs: Annotated[list[Name], Field(min_length=1)] | None = Field(
        None, description="folders of package:// meshes, relative to this file")
    arm_joints: Annotated[list[Name], Field(min_length=1)] | None = None
    ee_frame: Name | None = Field(None, description="the end-effector link")
    shiver_joint: Name | None = None
    forward: Literal["+x", "-x", "+y", "-y", "+z", "-z", "x", "y", "z"] | None = Field(
        None, description="the axis of ee_frame that looks forward")
    goal: Vec3 | None = Field(None, description="goal position in the base frame [m]")
    from_: Vec3 | None = Field(None, alias="from",
                               description="direction from the goal toward the start")
    posture: Annotated[list[Finite], Field(min_length=1)] | None = Field(
        None, description="joint configuration [rad]")
    joint_accel: Rates | None = Field(None, description="[rad/s^2], one or one per joint")
    joint_jerk: Rates | None = Field(None, description="[rad/s^3], one or one per joint")
    joint_velocity: Rates | None = Field(None, description="[rad/s], one or one per joint")
    limit_margin: NonNegative | None = Field(None, description="[rad]")
    velocity_scale: NonNegative | None = None
    accel_scale: NonNegative | None = None
    ee_offset: NonNegative | None = Field(None, description="[m] ahead along forward")
    ee_roll: Finite | None = Field(None, description="[rad] about forward")
    allowed_contacts: list[tuple[Name, Name]] | None = None
    sources: dict[str, str] | None = Field(None, description="where each value comes from")
    servo: ServoTable | None = Field(None, description="the joints' servos, for --track")
