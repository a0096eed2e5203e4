"""The registry of diagnostic codes: what each means, why it matters, an example.

A code is a stage letter plus three digits:

- ``S`` syntax (the Lark parse),
- ``V`` validation of statements into the IR,
- ``M`` the Commitment-Vigilance model (lint's judgement of a valid file),
- ``C`` compilation (layout, geometry, IK, timing, simulation check),
- ``R`` reading trajectories (``aouc measure``),
- ``D`` behaviours as Dynamic Movement Primitives (``--format dmp``, ``aouc dmp``),
- ``I`` input/output and usage, ``K`` primitive kinds that plugins add.

Codes are never reused; a retired code stays in :data:`RULES` as an alias. Every
example triggers its own code (the architecture tests run them).
"""

from __future__ import annotations

from .rule_model import Category, Rule, Severity
from .rules_check import CHECK_RULES
from .rules_dmp import DMP_RULES
from .rules_plugin import PLUGIN_RULES
from .rules_study import STUDY_RULES

__all__ = ["RULES", "Category", "Rule", "Severity", "category"]


_E, _W, _N = Severity.ERROR, Severity.WARNING, Severity.NOTE

_RULE_LIST = [
    # --- S: syntax -------------------------------------------------------------------
    Rule("S001", "unexpected-token", _E,
         "A token appears where the grammar does not allow it.",
         "The file cannot be understood past this point.",
         "pause 1.67s x5 )"),
    Rule("S002", "unexpected-end", _E,
         "The file ends in the middle of a statement or block.",
         "Usually a `sequence {` without its closing `}`.",
         "sequence {\n  approach a=0.05"),
    Rule("S003", "unexpected-character", _E,
         "A character that no token of the language can start with.",
         "The lexer cannot continue.",
         "pause 1.67s @5"),
    # --- V: validation ---------------------------------------------------------------
    Rule("V101", "unknown-statement", _E,
         "A statement starts with a word that is not a keyword of the language.",
         "Only the settings and primitives of docs/language.md exist; typos are common.",
         "aproach a=0.05   # did you mean `approach`?"),
    Rule("V102", "wrong-unit-dimension", _E,
         "A quantity's unit has the wrong dimension for where it is used.",
         "A pause lasts a time, a retreat covers a length: `pause 3m` is meaningless.",
         "pause 3m"),
    Rule("V103", "missing-unit", _E,
         "A positional quantity (a length, duration or angle) is written without a unit.",
         "`retreat 6` could be metres or centimetres; aou refuses to guess.",
         "retreat 6 a=0.12"),
    Rule("V104", "unknown-unit", _E,
         "A quantity has a unit aou does not know.",
         "Only SI units and a few common multiples are accepted (see docs/language.md).",
         "start 12in"),
    Rule("V105", "non-positive-value", _E,
         "A duration, distance, speed, frequency, acceleration or count that must be "
         "positive is zero or negative, or under the language's least: a pause under "
         "0.2 s, a shiver under 1 Hz.",
         "A pause of 0 s or a retreat of -6 cm has no motion to compile.",
         "pause 0s"),
    Rule("V106", "effort-out-of-range", _E,
         "An `effort` component lies outside [-1, 1].",
         "Laban Effort factors run from the Condensing pole (-1) to the Indulging pole (+1).",
         "effort W=-2 T=-1 S=-1 F=1"),
    Rule("V107", "duplicate-primitive", _E,
         "A primitive kind appears twice in the descriptor form.",
         "All episodes of one kind are equal in the model; use `xN` for more of them, or a "
         "`sequence { }` block for episodes that differ.",
         "pause 1s\npause 2s"),
    Rule("V108", "mixed-forms", _E,
         "A file has both a `sequence { }` block and descriptor-form primitives.",
         "The two forms lay out time differently; a file must choose one.",
         "pause 1s\nsequence { approach }"),
    Rule("V109", "unknown-robot", _E,
         "The `robot` setting (or --robot) names no built-in arm, and no robot file (a URDF "
         "or a TOML robot description) aou can use.",
         "aou needs the robot's kinematics, its end-effector frame, a default goal and its "
         "limits; `aouc robot PATH` shows what it reads or derives from a file.",
         "robot panda2"),
    Rule("V110", "resource-bound", _E,
         "The behaviour asks for more than 10 minutes of motion or more than 1000 episodes.",
         "Such a file is almost always a typo (x10000); compiling it would hang.",
         "pause 1s x5000"),
    Rule("V111", "duplicate-setting", _E,
         "A setting (or the header) appears more than once, or a statement gives one "
         "of its arguments twice (`a=` twice, a shiver's `for` twice).",
         "Each setting has one value; the second would silently win.",
         "start 0.3m\nstart 0.4m"),
    Rule("V112", "unknown-key", _E,
         "A `key=value` argument uses a key the statement does not take.",
         "Each primitive takes a fixed set of keys (docs/language.md).",
         "pause 1s a=0.1"),
    Rule("V113", "bad-arguments", _E,
         "A statement's arguments do not have the expected shape.",
         "Each statement takes a fixed list of arguments (docs/language.md).",
         "retreat a=0.12   # missing the distance"),
    Rule("V114", "unknown-state", _E,
         "The header declares a state that is not one of the five canonical states.",
         "The model has exactly five states: confident curious hesitant fearful inactive.",
         "behaviour b : brave"),
    Rule("V115", "header-position", _E,
         "The `behaviour` header is not the first statement of the file.",
         "The header names the whole file; it must come before anything else.",
         "pause 1s\nbehaviour b : hesitant"),
    Rule("V116", "bad-repeat", _E,
         "An `xN` repeat count is malformed or given twice.",
         "`xN` takes a whole number N >= 0, once.",
         "pause 1s x2 x3"),
    Rule("V117", "start-inside-standoff", _E,
         "The start distance is not larger than the standoff distance.",
         "The reach would begin closer to the goal than it is ever allowed to get.",
         "start 0.05m\nstandoff 0.10m"),
    Rule("V118", "sign-in-descriptor-form", _E,
         "A signed or zero angle is given in the descriptor form.",
         "Descriptor values are amplitudes; directions belong in a `sequence { }` block.",
         "gaze horizontal -20deg"),
    Rule("V119", "retreat-beyond-reach", _E,
         "The retreats would carry the end-effector further from the goal than the robot "
         "can be asked to go (start distance plus all retreats exceeds 1 m).",
         "Retreating past the start is allowed but not without bound.",
         "retreat 0.5m x4"),
    Rule("V120", "nothing-to-approach", _E,
         "An `approach` with a length longer than the way left to the standoff.",
         "The reach never gets closer to the goal than the standoff.",
         "start 0.3m\nsequence { approach 0.5m }"),
    Rule("V121", "unrealisable-descriptors", _E,
         "Episodes cannot count as declared: no arrangement the state allows shows them all "
         "(a retreat needs a pause before and after it, a gaze one after it, pauses motion "
         "between them), or a sequence lacks the kind a statement needs beside it.",
         "The compiled motion would not have the descriptors the file declares.",
         "pause 1s x3   # and nothing else: three pauses in a row are one pause"),
    Rule("V122", "goal-out-of-range", _E,
         "The goal lies further than 3 m from the robot's base.",
         "No arm aou knows reaches that far; such a value is almost always a typo.",
         "goal (30, 0, 0.3)"),
    Rule("V123", "below-resolution", _E,
         "An angle under 1 deg; a move along the line of sight under 5 mm (an approach or "
         "a retreat of either sign, the rest of the way to the standoff, or a piece of a "
         "descriptor-form approach); or a gaze whose arc around the goal moves the "
         "end-effector less than 5 mm: too small to be seen, or measured.",
         "The descriptors are measured to 0.5 deg and 1 mm; a smaller motion cannot be told "
         "from a pause, and the compiled motion would not show what the file declares.",
         "shiver 0.1deg"),
    Rule("V124", "nothing-to-move", _E,
         "The behaviour has no episode: no primitive, only `x0` counts, or a sequence "
         "whose moves all vanish.",
         "There is no motion to compile and nothing to measure.",
         "behaviour b : inactive\nrobot panda"),
    Rule("V125", "touching-pauses", _N,
         "Two pauses follow each other with no motion between them; they are one pause.",
         "A pause is a hold; two holds in a row are seen (and measured) as one longer hold.",
         "sequence {\n  approach 0.2m\n  pause 1s\n  pause 1s\n}"),
    Rule("V126", "shiver-lengthened", _W,
         "A shiver's `for` is shorter than 3 cycles: the shiver runs 3 cycles (it fades in "
         "over the first and out over the last), longer than written.",
         "The behaviour lasts longer than the file says: at 1 Hz a shiver lasts at least 3 s.",
         "shiver 5deg f=1Hz for 1s"),
    Rule("V130", "value-out-of-range", _E,
         "A number lies outside the range the language takes for its kind of value: "
         "lengths up to 100 m, durations up to 1 h, angles up to one turn (360 deg), "
         "speeds from 1e-7 to 10 m/s, accelerations from 1e-7 to 1000 m/s^2, angular "
         "speeds from 1e-5 to 10000 deg/s, frequencies up to 100 Hz.",
         "Such a value is a typo, or a number at the float limits that no stage of the "
         "compiler could use (a tilt of 1e160 deg, a speed of 1e-155 m/s).",
         "tilt 1e160deg"),
    Rule("V131", "package-escape", _E,
         "A mesh path of a robot's URDF leaves its package: a `package://NAME/...` path "
         "with `..` steps that climb out of the package's folder, or one whose NAME is "
         "no package's (`package://../etc/passwd`).",
         "A package path names a file inside that package; one that climbs out of it "
         "could make aou read any file of the machine.",
         "aouc robot escape.urdf   # <mesh filename=\"package://arm/../../../etc/passwd\"/>"),
    Rule("V132", "input-too-large", _E,
         "A `.aou` file, a robot file (URDF, robot description) or a mesh a URDF names "
         "is larger than aou reads (1 MB for a `.aou` file, 16 MB for a robot file, 64 MB "
         "for a mesh), or a URDF has more links or joints than aou loads (1000), or a "
         "longer arm (32 joints); in the language server, a document over 1 MB or with a "
         "line over 10,000 characters.",
         "aou reads a whole file before checking it: a bound keeps a wrong file (a log, a "
         "disk image) from taking the machine's memory. Set AOU_MAX_INPUT_MB to read "
         "larger files.",
         "aouc lint huge.aou   # a 2 MB file"),
    # --- M: the C-V model --------------------------------------------------------------
    Rule("M201", "state-mismatch", _W,
         "The state inferred from the behaviour's primitives differs from the declared one.",
         "People read the motion, not the header: a `hesitant` file that moves confidently "
         "will be seen as confident.",
         "behaviour b : hesitant\napproach a=0.1"),
    Rule("M202", "effort-mismatch", _W,
         "The `effort` line's (C, V) point lies nearest to another state than the declared one.",
         "The Effort vector and the declared state contradict each other.",
         "behaviour b : fearful\neffort W=-1 T=-1 S=-1 F=1\npause 1s x3\n"
         "retreat 6cm a=2\nshiver 6deg"),
    Rule("M203", "no-perceived-effect", _N,
         "A descriptor that the study found to have no clear perceived effect on this state.",
         "Tuning it will probably not change how people read the behaviour (docs/model.md).",
         "behaviour b : fearful\nshiver 6deg"),
    Rule("M204", "inferred-state", _N,
         "The state inferred for a file that declares none.",
         "Without a header aou cannot check intent, so it says what the motion expresses.",
         "approach a=0.1"),
    # --- C: compilation --------------------------------------------------------------
    Rule("C301", "unreachable", _E,
         "Inverse kinematics found no configuration that reaches a pose of the path.",
         "The goal, start or an exploration arc lies outside the robot's workspace.",
         "goal (1.5, 0, 0.3)\napproach\npause 1s"),
    Rule("C302", "joint-limit", _E,
         "A pose of the path is only reachable with a joint at or beyond its position limit.",
         "The trajectory would be stopped by the controller, or worse.",
         "start 0.32m\nsequence {\n  gaze vertical -30deg\n  pause 1s\n}"),
    Rule("C303", "singularity", _E,
         "The path passes through (or too near) a kinematic singularity.",
         "Near a singularity small Cartesian motions need huge joint speeds.",
         "goal (0.0, 0, 1.2)"),
    Rule("C304", "acceleration-unattainable", _W,
         "The declared end-effector acceleration cannot be reached within the joint limits; "
         "the compiled motion peaks lower, and the binding joint is named.",
         "The measured descriptor will differ from the declared one.",
         "approach\npause 1s x2\nretreat 0.06m a=50"),
    Rule("C305", "timing-failed", _E,
         "TOPP-RA found no feasible time parametrisation of a path segment.",
         "The limits cannot all be met on this path.",
         "approach v=1e-9"),
    Rule("C306", "check-failed", _E,
         "The compiled trajectory failed a simulation check (limits, collision, target contact).",
         "A trajectory that fails a check is never written: it is not safe to send to an arm.",
         "standoff 0.02m\napproach\npause 1s"),
    Rule("C308", "shiver-too-fast", _E,
         "A shiver's amplitude and frequency need more speed, acceleration or jerk than the "
         "shivering joint allows; the message names the limit and gives the highest "
         "frequency that fits, or the widest amplitude, rounded down and checked.",
         "The controller would stop the arm, or the tremor would be smaller than declared.",
         "shiver 6deg f=8Hz"),
    Rule("C309", "tilt-too-fast", _E,
         "A tilt's angle and velocity need more joint speed, acceleration or jerk than the "
         "robot allows; the message names the limit and the joint and gives the highest "
         "velocity that fits every tilt of the statement.",
         "The tilt velocity descriptor fixes the episode's duration; it cannot be slowed.",
         "tilt 90deg v=500deg/s"),
    Rule("C310", "descriptor-mismatch", _W,
         "A descriptor measured on the compiled trajectory differs from the declared one "
         "by more than its tolerance (docs/measure.md).",
         "The motion does not show what the file declares. A value a joint limit kept "
         "from it is said once, by C304, not again here.",
         "approach a=2 v=0.01   # the speed cap is reached before the acceleration"),
    Rule("C311", "jerk-limit", _E,
         "The trajectory, sampled at the controller's rate, needs more joint jerk than the "
         "robot (or the controller named by --controller) allows.",
         "Motion generators reject acceleration jumps (Franka aborts with an acceleration "
         "discontinuity; UR arms protective-stop): such a trajectory is not safe to send.",
         "aouc check --controller franka recorded.json   # a trajectory with acceleration jumps"),
    Rule("C312", "no-collision-geometry", _E,
         "The robot's URDF has no collision shapes, so self-collision cannot be checked.",
         "A trajectory whose collisions were not checked is written only when the user opts "
         "out explicitly (--no-collision-check); the output records it.",
         'robot "arm_without_collision_shapes.urdf"\napproach\npause 1s'),
    Rule("C313", "default-limits", _W,
         "The robot has no sourced joint acceleration (or jerk) limits; a conservative "
         "default is used.",
         "URDFs carry no acceleration limits; a robot description file (TOML) beside the URDF "
         "pins them (docs/robots.md says how).",
         "robot z1\napproach\npause 1s"),
    Rule("C314", "fitted-value", _W,
         "With --fit, a value the arm cannot give was changed to one it can: the "
         "statement, the value declared and fitted, the joint and the limit that bind.",
         "The fitted behaviour keeps its state and the order of its values (docs/robots.md "
         "gives the rule); --write-fitted writes the file so the change is reviewed.",
         "robot ur5\nshiver 6deg f=2.5Hz\npause 1s"),
    Rule("C315", "fit-changes-look", _E,
         "With --fit, no value the arm can give keeps a motion looking like the kind it "
         "declares: a shiver the arm follows only slower than 2.5 Hz (where its swings "
         "read as slow rolls), or at 2.5 Hz only narrower than 1 deg or too narrow for "
         "the file's state; or a change that would make another kind of motion (a tilt "
         "rolling faster, a retreat under 5 mm).",
         "A fit keeps what a person sees, not only the eleven descriptors: a shiver made a "
         "slow roll looks like curious looking around, not fearful trembling. The file is "
         "not fitted and the refusal stands; docs/robots.md gives each kind's invariant.",
         "behaviour f : fearful\nrobot kinova\napproach a=0.1\npause 1.25s x4\n"
         "retreat 0.06m a=2\nshiver 6deg for 1.25s   # aouc compile --fit"),
    *CHECK_RULES,  # what `aouc check` alone says: torques, tracking
    # --- D: behaviours as Dynamic Movement Primitives ------------------------------------
    *DMP_RULES,  # the DMP folders' (rules_dmp.py)
    Rule("R401", "bad-trajectory", _E,
         "A trajectory file is not valid: missing keys or columns, non-increasing time, NaN.",
         "Descriptors cannot be measured from it.",
         '{"format": "aou-trajectory/1", "t": [0, 0]}'),
    Rule("R402", "unknown-joint", _E,
         "A trajectory names a joint that the robot model does not have.",
         "Forward kinematics needs every column to map onto a joint of the model.",
         "t,panda_joint9"),
    Rule("R403", "unequal-episodes", _W,
         "Episodes of one kind measure different values; the model assumes they are equal.",
         "The descriptor follows its rule (median, or maximum for peaks and gazes); "
         "per-episode values are in the JSON output. On a noisy recording it is noted "
         "only where the episodes differ by more than the noise can make them.",
         "two retreats of 4 cm and 8 cm"),
    Rule("R404", "implausible-units", _E,
         "The columns of a recording look like degrees (or its times like milliseconds), "
         "not radians and seconds; or a unit given contradicts the robot's joint limits.",
         "Descriptors measured from wrong units are nonsense; say the unit "
         "(--angle-unit deg, --time-unit ms) if the file really uses it.",
         "t,panda_joint1\n0,45\n1,90\n2,100\n3,110"),
    Rule("R405", "missing-goal", _W,
         "A recording carries no goal and none was given; gaze descriptors need one.",
         "Give --goal X,Y,Z, or --goal final to take the end-effector's final position "
         "(the gaze angles are then relative to it).",
         '{"format": "aou-trajectory/1", "robot": "panda", "joint_names": '
         '["panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4", "panda_joint5", '
         '"panda_joint6", "panda_joint7"], "t": [0, 0.1, 0.2], "q": ['
         '[0, 0, 0, -1.5, 0, 1.5, 0.8], [0, 0, 0, -1.5, 0, 1.5, 0.8], '
         '[0, 0, 0, -1.5, 0, 1.5, 0.8]]}'),
    Rule("R406", "inconsistent-measurement", _E,
         "A measured value contradicts the joint motion it came from (for instance a "
         "Cartesian acceleration the joint accelerations cannot produce).",
         "aou reports an internal inconsistency instead of a wrong number.",
         "a recording whose measured peak exceeds what its joint accelerations allow"),
    # --- I: input/output and usage -----------------------------------------------------
    Rule("R407", "undersampled-oscillation", _W,
         "A roll back and forth is sampled too few times per cycle (under about 5) to "
         "tell a shiver from tilts by its speed profile; it is reported as neither.",
         "Sample the recording, or compile, at 6 samples per cycle or more.",
         "a 5 Hz shiver in a trajectory sampled at 20 Hz"),
    Rule("R408", "outside-tolerance", _E,
         "A recording (or trajectory) measured against a behaviour file (`aouc measure REC "
         "--against FILE.aou`) shows a descriptor outside its tolerance of the declared one.",
         "The motion the robot ran is not the one the file declares; in a lab's CI the run "
         "fails. docs/measure.md gives each descriptor's tolerance.",
         "a recording whose pauses last half as long as the file declares"),
    Rule("R410", "recording-too-large", _E,
         "A trajectory or recording is larger than aou reads: over 256 MB, or more "
         "samples than 2,000,000 (its header or its rows say how many).",
         "aou reads a recording whole into memory; a bound keeps a wrong file (a disk "
         "image, a stream) from taking the machine's memory. Set AOU_MAX_INPUT_MB or "
         "AOU_MAX_SAMPLES to read larger ones.",
         "aouc measure huge.npz   # its q.npy claims 1,000,000,000 samples"),
    Rule("R411", "noise-beyond-segmentation", _W,
         "A recording's measurement is a guess: re-noised copies read another count or "
         "presence, an interval reaches a fifth of its value away, stamps taken on arrival "
         "move it (or it is read on the clock evened out), or the log cuts a fast motion.",
         "The warning names the noise level, the clock or the cut, and each descriptor it "
         "affects; a judgement against a behaviour file reads them as inconclusive.",
         "a 250 Hz recording of the hesitant behaviour with 1e-3 rad of joint noise"),
    Rule("R412", "inconclusive", _W,
         "A recording measured against a behaviour file shows a descriptor whose 95 % "
         "interval straddles its tolerance's edge, or a count or presence its noise can "
         "flip: neither a pass nor a fail.",
         "Its noise leaves the descriptor undecided: passing it would claim what the "
         "recording does not show, failing it would blame the motion for the logger's "
         "noise. `aouc measure --against` exits 3 when nothing fails but something is "
         "inconclusive.",
         "a retreat's peak acceleration measured 0.1205 +- 0.009 m/s^2 against a declared "
         "0.12 +- 0.0036"),
    Rule("R413", "undeclared-kind", _W,
         "A recording measured against a behaviour file (`aouc measure REC --against "
         "FILE.aou`) has episodes that read as a kind of motion the file does not "
         "declare: a tilt, a gaze, a retreat..., or a shiver slower than 2.5 Hz, whose "
         "swings read as slow rolls (a tilt).",
         "The descriptors can pass while a person sees another motion: a tremor slowed "
         "into rolls looks like looking around, not trembling. The warning gives the "
         "episodes' times and what that kind looks like.",
         "a 1.1 Hz shiver measured against a file that declares a shiver and no tilt"),
    *STUDY_RULES, *PLUGIN_RULES,  # studies' files, plugins (rules_study, rules_plugin)
    Rule("I501", "cannot-read", _E,
         "An input file or folder cannot be read (missing, a directory, permissions, encoding).",
         "Nothing can be checked or compiled.",
         "aouc lint missing.aou"),
    Rule("I502", "cannot-write", _E,
         "An output file cannot be written, or would overwrite an input: it is, or links "
         "to, a file the command reads (the `.aou` file, its robot file, the URDF, a mesh, "
         "the trajectory); it is a device, a FIFO or a socket; or a bag's folder holds "
         "other files than a bag aou wrote.",
         "aou writes atomically and never overwrites its inputs.",
         "aouc compile a.aou -o a.aou"),
    Rule("I503", "no-inputs", _E,
         "A folder given on the command line holds no `.aou` files.",
         "Probably the wrong folder.",
         "aouc lint empty/"),
    Rule("I504", "bad-argument", _E,
         "A value given on the command line or to the Python API is not one aou can use "
         "(a malformed `--vary`, a state it does not know, a number outside its range, a "
         "recording measured without its robot).",
         "The command cannot start; the message says what the value should be.",
         "aouc variants a.aou --vary speed=1,2"),
    Rule("I505", "cannot-connect", _E,
         "The scheduler given with `--cluster` cannot be reached, or its address is not "
         "one (`tcp://HOST:PORT`).",
         "Nothing is built: the files would have had no workers.",
         "aouc compile a.aou --cluster tcp://127.0.0.1:9"),
    Rule("I506", "not-aou-output", _E,
         "`synth`, `variants` or `robot -o` would replace an existing file that aou did not "
         "write (aou's own files start with a comment line saying they were written by "
         "aouc, or are JSON with an `aouc` generator).",
         "A hand-written behaviour or robot file is not lost to a command that makes "
         "one; `--force` replaces it.",
         "aouc synth --state confident --no-verify -o a.aou"),
    Rule("I507", "bad-scenario", _E,
         "A scenario file for `aouc live` is not one: not TOML, a key it does not know, a "
         "value of the wrong kind or out of its range, an event that names an occluder "
         "the scene lacks.",
         "Nothing runs: a scenario read halfway would play another scene than the one "
         "written.",
         "aouc live a.aou   # a behaviour file, not a scenario: not TOML"),
]

RULES: dict[str, Rule] = {r.code: r for r in _RULE_LIST}
if len(RULES) != len(_RULE_LIST):  # a code listed twice: the second would hide the first
    raise RuntimeError("a rule code is registered twice: "
                       + ", ".join(sorted({r.code for r in _RULE_LIST
                                           if [q.code for q in _RULE_LIST].count(r.code) > 1})))


def category(code: str) -> Category:
    """The category of a registered code (KeyError for one the registry lacks)."""
    return RULES[code].category
