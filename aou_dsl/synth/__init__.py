"""Behaviours chosen from a state or a C-V point and an intensity, fitted to an arm."""
