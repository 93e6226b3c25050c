"""What a request past its time budget can do instead: the advice its 504 ends with, by where
it was planned (synchronously, as a line of a batch, as a cell).

A synchronous request has the planning budget (``TOPTRAJ_PLAN_BUDGET_S``, 20 s by default); a
job (``POST /v1/jobs``) runs the same request in the background under a budget of its own, up
to ``TOPTRAJ_JOB_MAX_BUDGET_S``. A batch's line has the batch's per-line budget, which the
command line's ``--budget`` sets and ``POST /v1/batches`` fixes.
"""

from __future__ import annotations

from toptraj.planners.errors import BudgetExceeded


def as_job(kind: str, plan_budget_s: float, job_budget_s: float, job_max_budget_s: float) -> str:
    """Advice for a synchronous ``kind`` request ("trajectory" or "compare") past the planning
    budget of ``plan_budget_s`` s: to run it as a job, when a job may run longer, with a budget
    of the job's default (``job_budget_s``) or five times the planning budget if more, within
    ``job_max_budget_s``."""
    if job_max_budget_s <= plan_budget_s:
        return (
            f"this server allows no planning longer than {plan_budget_s:g} s; its operator can raise "
            "TOPTRAJ_PLAN_BUDGET_S and TOPTRAJ_JOB_MAX_BUDGET_S"
        )
    suggested = min(job_max_budget_s, max(job_budget_s, 5.0 * plan_budget_s))  # always more time than it had
    return (
        f'run it as a job, in the background: POST /v1/jobs with {{"{kind}": <this request>, "budget_s": {suggested:g}}} '
        f"(at most {job_max_budget_s:g} s), then GET the job's Location until it is done"
    )


def for_cell() -> str:
    """Advice for a cell (``POST /v1/cells``, planned only synchronously) past the planning
    budget: the server setting that gives it more time."""
    return "a cell is planned only within the server's planning budget, which its operator can raise with TOPTRAJ_PLAN_BUDGET_S"


def advised(error: BudgetExceeded, advice: str) -> BudgetExceeded:
    """``error`` with ``advice`` appended to its message (its facts kept)."""
    if not advice or advice in str(error):
        return error
    facts = {key: value for key, value in vars(error).items() if key != "detail"}
    return BudgetExceeded(f"{error}; {advice}", **facts)


def for_batch_line(budget_s: float, max_budget_s: float) -> str:
    """Advice for a line of ``toptraj batch`` past its budget (``--budget``, ``budget_s`` s):
    to plan the lines answered 504 again with a larger one."""
    if budget_s >= max_budget_s:
        return (
            f"no line may take longer than {max_budget_s:g} s in a batch; plan this request alone as a job "
            '(POST /v1/jobs with {"trajectory": <this line>, "budget_s": ...})'
        )
    larger = min(max_budget_s, max(5.0 * budget_s, 60.0))
    return (
        f"run the same command again with --retry-failed --budget {larger:g} (at most {max_budget_s:g} s): "
        "only the lines answered with a budget error or a 5xx are planned again"
    )


def advised_line(status: int, body: bytes, advice: str) -> bytes:
    """A batch line's answer ``body`` (problem+json when ``status`` is 504) with ``advice``
    appended to its detail; any other answer unchanged."""
    if status != 504 or not advice:
        return body
    import orjson

    problem = orjson.loads(body)
    if advice not in problem.get("detail", ""):
        problem["detail"] = f"{problem.get('detail', '')}; {advice}"
    return orjson.dumps(problem)


def job_kind(text: str) -> str:
    """The job kind that plans the request ``text`` of a batch line: "compare" for a line with
    ``methods``, else "trajectory"."""
    import orjson

    try:
        body = orjson.loads(text)
    except orjson.JSONDecodeError:
        return "trajectory"
    return "compare" if isinstance(body, dict) and "methods" in body else "trajectory"


def larger_job_budget(budget_s: float, job_max_budget_s: float) -> str:
    """Advice for a job past its ``budget_s``: to submit it again with a larger one, when the
    server allows one."""
    if budget_s >= job_max_budget_s:
        return (
            f"{job_max_budget_s:g} s is the most a job may take on this server (its operator can raise TOPTRAJ_JOB_MAX_BUDGET_S)"
        )
    return f"submit it again with a larger budget_s, at most {job_max_budget_s:g} s"
