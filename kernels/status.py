"""Per-point status codes written by the kernels."""

DECIDED_FLOAT = 0  # the interval Sturm sequence proved the count
UNDECIDED = 1  # the intervals could not decide: the caller must use exact arithmetic
ZERO_POLYNOMIAL = 2  # p(lambda) is identically zero
DECIDED_INCLUSION = 3  # disjoint root-inclusion disks proved the count
DECIDED_INERTIA = 4  # all roots real, proved by the inertia of Phi(x) between the roots (certify.py)
DECIDED_DISKS = 5  # real roots by inertia, non-real ones by inclusion disks from det Phi(z) (certify.py)
DECIDED_ALLATONCE = 6  # every eigenvalue of the first-order pencil at once: discs after an approximate eigen-decomposition (allatonce.py)
