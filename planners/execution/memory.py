"""The memory of a planning, estimated before it starts, and the one cap it is held to.

A planning's memory grows with three things: the grid its path is timed on (each method holds
about ``bytes_per_interval_joint`` bytes per grid interval and joint: its constraint rows, its
solver's matrices and workspace), the samples of its answer (``SAMPLE_ARRAYS`` arrays of eight-
byte numbers per sample and joint: q, q', q'', tau and the sampling's work array), and what a
motion generator holds besides (the search's graph, ``MotionGenerator.estimate``). Together
they stay within ``MEMORY_CAP_BYTES``: 140,000 grid intervals times joints at toppra's 2.3 kB
(20,000 intervals on a 7-joint arm), about 322 MB. The samples are reserved at the most the
answer may hold (``max_samples``, and at most half the cap: ``most_samples``), since the
duration that sets their number is known only after the timing.

The runner admits a problem against the cap before any work
(``toptraj.planners.runner.admission``); the methods thin their default grids and refine
within the same figure (``largest_grid``).
"""

from __future__ import annotations

#: Default memory cap of one search, in bytes (``toptraj.planners.generators.search.memory``; the service's
#: ``search_memory_bytes``): 2 GiB, which serves every arm's default search (the three-joint
#: lattice's, estimated at 1.6 GiB, peaks at 1.45 GB).
DEFAULT_SEARCH_MEMORY = 2**31
#: The most bytes one planning may take by its estimate: 140,000 grid intervals times joints at
#: toppra's 2,300 bytes each.
MEMORY_CAP_BYTES = 140_000 * 2_300
#: Eight-byte arrays per sample and joint: q, q', q'', tau and the sampling's own work array.
SAMPLE_ARRAYS = 5
#: The most samples an answer holds unless the caller asks for fewer.
MAX_SAMPLES = 200_000


def samples_bytes(samples: int, dof: int) -> int:
    """Bytes of ``samples`` samples of a ``dof``-joint motion (``SAMPLE_ARRAYS`` arrays)."""
    return samples * max(dof, 1) * SAMPLE_ARRAYS * 8


def most_samples(max_samples: int, dof: int) -> int:
    """The most samples of a ``dof``-joint answer: ``max_samples``, and no more than half the
    cap holds (what a sample period may give at most; the grid gets the rest)."""
    return max(2, min(max_samples, MEMORY_CAP_BYTES // 2 // samples_bytes(1, dof)))


def grid_bytes(intervals: int, dof: int, bytes_per_interval_joint: int) -> int:
    """Bytes of a method timing a ``dof``-joint path on ``intervals`` grid intervals."""
    return intervals * max(dof, 1) * bytes_per_interval_joint


def largest_grid(bytes_per_interval_joint: int, dof: int, reserved: int, cap: int | None = None) -> int:
    """The most grid intervals whose bytes fit in ``cap`` (default ``MEMORY_CAP_BYTES``) beside
    ``reserved`` bytes (the samples, a generator's own); 0 when none fit."""
    cap = MEMORY_CAP_BYTES if cap is None else cap
    return max(cap - reserved, 0) // (max(dof, 1) * bytes_per_interval_joint)


def method_grid_cap(bytes_per_interval_joint: int, dof: int) -> int:
    """The most grid intervals a method takes on a ``dof``-joint arm beside the most samples an
    answer holds (``MAX_SAMPLES``): its default grid is thinned to it and its refinements stay
    within it."""
    return largest_grid(bytes_per_interval_joint, dof, samples_bytes(most_samples(MAX_SAMPLES, dof), dof))
