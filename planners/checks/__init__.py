"""The limit gate: every timing's dense states checked against the limits (``limit_check``
with its compiled kernels), and refinement rounds until they hold (``gate``)."""
