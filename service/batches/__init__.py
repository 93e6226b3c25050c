"""Many requests at once: ``toptraj batch requests.jsonl -o results.jsonl`` plans a file of
request lines on Ray (a local Ray over this machine's cores, or a cluster), writes exactly one
result line per line of the file (a line that cannot be read is a 4xx line), and resumes by
line number where an earlier run stopped (``--retry-failed``: the 504s and 5xx too).

* ``lines``: request lines read within bounds, their keys (a hash of the request), the result
  lines and the output file made ready to resume.
* ``work``: one request answered, as the service answers it (runs on a Ray worker).
* ``runner``: the batch driver: Ray, a bounded window of tasks, the output file, progress, a
  stop that keeps what finished.
"""

from toptraj.service.batches.ray_pool import RayMissing
from toptraj.service.batches.runner import BatchReport, run_batch

__all__ = ["BatchReport", "RayMissing", "run_batch"]
