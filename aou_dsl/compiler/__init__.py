"""The compiler: a validated behaviour and its timeline -> a joint trajectory.

:func:`.pipeline.compile_behaviour` is the entry point: the gaze-locked path of each
episode solved by IK (:mod:`aou_dsl.robot.ik`), timed (:mod:`.timing`: TOPP-RA in
:mod:`.topp`, jerk-limited laws in :mod:`.timelaw`, shivers in :mod:`.oscillation`, the
limits' peaks in :mod:`.peak_limits`, values that fit in :mod:`.fits`), sampled, and
written by :mod:`.output` (ROS 2 bags: :mod:`.ros`).
"""
