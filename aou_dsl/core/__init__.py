"""The lowest layer: diagnostics and the rule registry, units, files, the trajectory type and
the built-in arms' data. Imports nothing else of aou."""
