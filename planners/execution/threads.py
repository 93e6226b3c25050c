"""One BLAS thread per computation.

The planners work on small matrices (a collocation's Jacobians are a few hundred rows), where a
multi-threaded BLAS gains nothing and its spinning threads cost much: measured on the Geering
free-motion collocation (2 cores), OpenBLAS's default two threads took 14.2 s of CPU for 7.3 s
of wall time, one thread 5.6 s for 5.6 s, and with the other core busy the default ran more than
ten times slower than alone. The service runs many plannings side by side, one per thread or
process, so each keeps to one BLAS thread (``threadpoolctl``, which limits the libraries already
loaded, whatever environment variables were set before their import).
"""

from __future__ import annotations

from threadpoolctl import threadpool_limits


def single_blas_thread() -> None:
    """Limit every BLAS and OpenMP library loaded in this process to one thread."""
    threadpool_limits(limits=1)
