"""The self-checks: does a fit hold together, and what does its 1-sigma cover?

Stage 5 of a calibration (after the observations and the fit). Owns goodness of fit (:mod:`.quality`),
scatter beyond the noise carried into the covariance (:mod:`.excess`), the plausibility of the scale
factors (:mod:`.plausibility`), their run after a fit (:mod:`.fit`) and what the 1-sigma of a
first-moment fit covers (:mod:`.noise_terms`).

Layer 5 (self-checks and planning) of docs/architecture.md: imports the package root and layers 1 to 5 only.
"""
