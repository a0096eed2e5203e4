"""Safety: every sample of a trajectory replayed and checked before it reaches an arm: joint
limits (:mod:`.limits`), the PyBullet replay (:mod:`.replay`, :mod:`.sweep`), the replay's own
forward kinematics (:mod:`.urdf_fk`) and the motion generators' limits (:mod:`.controllers`)."""
