"""Measuring: any joint trajectory, compiled or recorded, -> the eleven descriptors.

:func:`.measured.measure` is the entry point; :func:`.recording.read_recording` reads
JSON, NPZ and CSV files. Signals (:mod:`.signal`) -> holds (:mod:`.holds`, :mod:`.onset`)
-> episodes (:mod:`.episodes`, :mod:`.peaks`) and rolls (:mod:`.roll`) -> descriptors.
"""
