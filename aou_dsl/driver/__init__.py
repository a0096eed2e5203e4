"""One behaviour from text to a checked, measured trajectory (builder), many at once
(parallel), and the warm session that re-runs only what changed."""
