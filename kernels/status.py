"""Per-point status codes written by the kernels."""

DECIDED_FLOAT = 0  # interval arithmetic proved the count
UNDECIDED = 1  # the intervals could not decide: the caller must use exact arithmetic
DEGENERATE = 2  # p(lambda) is identically zero
