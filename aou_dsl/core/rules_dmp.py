"""The rules of behaviours as Dynamic Movement Primitives (``--format dmp``, ``aouc dmp
roll``): what a ``.dmp`` folder must be, and what a rollout may ask. Kept apart from
:mod:`.rules` (which lists them among its codes) to keep that table's module small."""

from __future__ import annotations

from .codes import D601, D602, D603, D604, D605, D606, D607, D608
from .rule_model import Rule, Severity

__all__ = ["DMP_RULES"]

_E, _W = Severity.ERROR, Severity.WARNING

DMP_RULES = [
    Rule(D601, "dmp-needs-episodes", _E,
         "Only a compiled trajectory (with the compiler's episodes and goal) can become a "
         "sequence of DMPs; a recording carries neither.",
         "Each DMP is one rest-to-rest episode; without the episodes there are no parts.",
         "aou_dsl.dmp.to_dmp(aou_dsl.read_trajectory('arm.csv', robot='panda'))"),
    Rule(D602, "bad-dmp-file", _E,
         "A `.dmp` folder's manifest is not an `aou-dmp/1` sequence, or a part it names is "
         "missing: a field is absent, unknown, or not of its type, range or size (a "
         "number not finite, a robot, frame or joint the arm does not have, a goal at "
         "the start); the message names the file and the field.",
         "The sequence cannot be rolled out, and a shared folder is untrusted input.",
         'x.dmp/manifest.json: {"format": "aou-trajectory/1"}'),
    Rule(D603, "rollout-unreachable", _E,
         "The arm cannot follow the rolled-out motion: a pose is out of reach, needs a "
         "joint past its limit, or passes a singularity.",
         "The goal moved too far for this arm; move it less or compile for the new goal.",
         "aouc dmp roll hesitant.dmp --goal 2,0,0.3   # far out of the Panda's reach"),
    Rule(D604, "rollout-beyond-limit", _E,
         "The rolled-out motion fails a safety check; the message names the check, the "
         "joint, the value and the limit (joint velocity, acceleration, collision...).",
         "A faster tempo or a larger motion needs more of the arm than it has; such a "
         "motion is not safe to send.",
         "aouc dmp roll fearful.dmp --time-scale 0.25   # its 2 m/s^2 retreat at 32 m/s^2"),
    Rule(D605, "rollout-off-rule", _W,
         "A descriptor measured on the rolled-out motion is not what its scaling rule "
         "predicts, within the descriptor's tolerance.",
         "The adapted motion would not mean what the behaviour means.",
         "a rollout whose pauses no longer read as pauses"),
    Rule(D606, "blend-beyond-limit", _E,
         "A goal changed in the middle of a motion would need more than the declared peak "
         "acceleration (plus 10 %) or more than the arm's limits.",
         "The blend is refused rather than sent: the arm keeps its goal.",
         "a goal moved 30 cm during a fast retreat"),
    Rule(D607, "dmp-class-not-allowed", _E,
         "A `.dmp` part file names a module or class other than movement_primitives' "
         "`CartesianDMP` (and its `ForcingTerm`s).",
         "A part file is untrusted: aou builds only the classes it allows, from checked "
         "arguments, and imports nothing a file names (the library's `read_json` would "
         "import and call it).",
         'x.dmp/parts/01-approach.json: {"module": "subprocess", "class": "getoutput"}'),
    Rule(D608, "dmp-folder-not-closed", _E,
         "A `.dmp` folder reaches outside itself or past a bound: a part path that is "
         "absolute, has `..` or resolves outside the folder through a symbolic link; a "
         "FIFO, device or socket; a file, part count, duration or step count beyond its "
         "bound (docs/dmp.md lists them); a part file named twice.",
         "A shared folder must not make aou read other files, wait forever or run "
         "without bound.",
         'x.dmp/manifest.json: "parts": [{"kind": "approach", "file": "../outside.json", '
         '...}]'),
    # --- R: reading trajectories -------------------------------------------------------
]
