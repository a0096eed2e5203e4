"""The rules only ``aouc check`` says: the torques a trajectory needs, the dynamic
replay's tracking error, and what the arm shows through its servos (``--track``). Kept
apart from :mod:`.rules` (which lists them among the C codes) to keep that table's
module small."""

from __future__ import annotations

from .codes import C320, C321, C322, C323
from .rule_model import Rule, Severity

__all__ = ["CHECK_RULES"]

_E, _W = Severity.ERROR, Severity.WARNING

CHECK_RULES = [
    Rule(C320, "torque-limit", _E,
         "Following the trajectory needs more torque at a joint than the URDF's effort "
         "limit: torques by inverse dynamics (gravity included) of every sample; the "
         "message names the time, the joint and the ratio.",
         "A motor at its limit cannot follow: the arm lags, and a controller watching its "
         "torques stops it.",
         "aouc check fast.json   # a shoulder swinging at 4 Hz"),
    Rule(C321, "tracking-error", _E,
         "In the dynamic replay (position control, each motor capped at its effort limit) "
         "a joint lagged the plan by more than the tracking limit (1 degree).",
         "A joint that cannot follow the plan draws a different motion, and a controller "
         "watching its following error stops the arm.",
         "aouc check fast.json   # a shoulder swinging at 4 Hz"),
    Rule(C322, "lost-under-tracking", _W,
         "With --track, the motion the arm's servos give (simulated through the servo "
         "mode of --servo) shows a descriptor outside its tolerance of the declared one; "
         "the message names the descriptor, the value the arm gives, and a servo mode "
         "that keeps it.",
         "Servos filter motion: a fast shiver sent as plain position set-points reaches "
         "the arm smaller and late, so the arm does not show what the file declares. A "
         "warning: the motion is as safe as the plan; what a person sees differs.",
         "aouc check behaviours/fearful.aou --track --servo position"),
    Rule(C323, "generic-servo", _W,
         "With --track, the arm has no servo table (gains, damping, armature, force "
         "limits); a generic servo is simulated instead.",
         "What tracking shows depends on the servos; a robot description's [servo] table "
         "gives the arm's own (docs/robots.md says how).",
         "aouc check behaviours/curious.aou --robot z1 --track"),
]
