"""Result files: the calibration and the reports a run writes, their registry and their old versions.

What every method hands on: the calibration (:mod:`.calibration`) and its optional sections
(:mod:`.sections`), the registry of file kinds with ``load`` and ``save`` (:mod:`.files`; it knows
each kind by name and imports it when it meets its format) and upgrades of old versions
(:mod:`.legacy`). A method's own report keeps its document code in the method's package
(``gyrocal.noise.document``, ``gyrocal.flight.thermal_bias_document``).

Layer 6 (result files) of docs/architecture.md: imports the package root and layers 1 to 6 only.
"""
