"""The perception-loop regulator: re-plans a running behaviour as uncertainty changes."""
