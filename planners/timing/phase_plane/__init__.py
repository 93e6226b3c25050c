"""The phase-plane method (Bobrow, Shin & McKay; Pfeiffer & Johanni; Jeong & Lee §3): the
timing (``method``) and its compiled sweeps, grid refinement and interval splitting."""
