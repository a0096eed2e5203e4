"""aou: a declarative language and compiler for expressive robot-arm motion."""
__version__ = "0.1.0"
