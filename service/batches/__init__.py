"""Many requests at once: ``toptraj batch requests.jsonl -o results.jsonl`` plans a file of
request lines on Ray (a local Ray over this machine's cores, or a cluster), writes a result line
per request line, and resumes where an earlier run stopped.

* ``lines``: request lines, their keys (a hash of the request) and the result lines.
* ``work``: one request answered, as the service answers it (runs on a Ray worker).
* ``runner``: the batch driver: Ray, a bounded window of tasks, the output file, progress.
"""

from service.batches.runner import BatchReport, run_batch

__all__ = ["BatchReport", "run_batch"]
