"""The production station: unit identity, acceptance limits with guard bands, and what builds on them.

* :mod:`.identity`: the ``unit`` section of a result file (serial, station, procedure, input hashes);
* :mod:`.limits`: the limits file (TOML) and its bounds;
* :mod:`.accept`: the guard-banded decision of a result against limits.

Layer 9 (studies, capture and the station) of docs/architecture.md: imports the package root and layers 1 to 9
only.
"""
