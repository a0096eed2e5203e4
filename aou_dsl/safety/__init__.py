"""Checks that a trajectory is safe to send to an arm (limits now; PyBullet replay next)."""
