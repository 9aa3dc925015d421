"""Physical and statistical constants, each defined once, in a module that imports nothing.

The command line reads them for its defaults without loading numpy; :mod:`gyrocal.units` and the
library use them from here.
"""

__all__ = ["MAD_TO_SIGMA", "STANDARD_GRAVITY"]

#: [m/s^2] the standard acceleration of gravity (3rd CGPM, 1901).
STANDARD_GRAVITY = 9.80665
#: Median absolute deviation -> sigma of a Gaussian: 1 / Phi^-1(3/4).
MAD_TO_SIGMA = 1.482602218505602
