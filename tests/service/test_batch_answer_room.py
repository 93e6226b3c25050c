"""A batch job's answer is kept up to the server's answer cap (``max_response_bytes``): the
answers of its requests, known only once planned, are counted as they come, and once they fill
the cap the job plans no more (not only at the end, after all the work): each request left gets
a 422 saying from which request on to submit them again, which then are answered."""

from __future__ import annotations

import json
import re

import orjson

import toptraj.service.batches.work as batch_work
from toptraj.planners import Deadline
from toptraj.service.jobs.work import KINDS, WorkerSetup

#: A ur5 motion of 0.4 s sampled every 0.5 ms: an answer of about 380 kB.
DENSE = {"robot": "ur5", "path": {"waypoints": [[0.0] * 6, [0.4, 0.3, -0.2, 0.1, 0.2, 0.3]]}, "output": {"dt": 0.0005}}
CAP = 1_000_000


def _setup(tmp_path) -> WorkerSetup:
    return WorkerSetup(data_dir=str(tmp_path), max_uploads=10, max_upload_bytes=1_000_000, upload_cache_size=2, max_response_bytes=CAP)


def _run(requests: list[dict], tmp_path, monkeypatch) -> tuple[bytes, int]:
    """The batch's answer and how many requests were planned."""
    planned = []
    original = batch_work.answer
    monkeypatch.setattr(batch_work, "answer", lambda *args: planned.append(1) or original(*args))
    result = KINDS["batch"](orjson.dumps({"requests": requests}).decode(), Deadline(120.0), _setup(tmp_path))
    return result, len(planned)


def test_a_batch_stops_planning_once_its_answers_fill_the_cap(tmp_path, monkeypatch):
    requests = [DENSE] * 8
    result, planned = _run(requests, tmp_path, monkeypatch)
    assert len(result) <= CAP
    results = json.loads(result)["results"]
    assert [row["line"] for row in results] == list(range(1, 9))
    kept = [row for row in results if row["status"] == 200]
    # planned: the answers kept and the one that did not fit, no more
    assert 1 <= len(kept) < 8 and planned == len(kept) + 1, (len(kept), planned)
    first = len(kept) + 1
    assert f"request {first} has " in results[first - 1]["body"]["detail"]
    for row in results[first - 1 :]:
        assert row["status"] == 422 and row["body"]["title"] == "Answer too large", row
        assert f"at most {CAP} bytes" in row["body"]["detail"]
        assert f"(from request {first} on) in batches of at most {len(kept)} requests" in row["body"]["detail"], row["body"]["detail"]


def test_the_requests_left_are_answered_when_submitted_as_the_advice_says(tmp_path, monkeypatch):
    result, _ = _run([DENSE] * 4, tmp_path, monkeypatch)
    rows = json.loads(result)["results"]
    kept = sum(row["status"] == 200 for row in rows)
    again, _ = _run([DENSE] * kept, tmp_path, monkeypatch)  # the next requests, in a batch of the size advised
    assert [row["status"] for row in json.loads(again)["results"]] == [200] * kept


def test_a_request_whose_samples_exceed_the_room_gets_the_dt_that_fits(tmp_path, monkeypatch):
    """Each request is planned with the job's answer cap as its body cap, as the synchronous
    endpoint is with its own: more samples than that holds is this request's 422 naming
    output.dt, and the batch goes on (what is left of the room decides only what is kept)."""
    finer = {**DENSE, "output": {"dt": 0.00005}}  # 8,000 samples: about 3.8 MB
    result, _ = _run([finer, DENSE], tmp_path, monkeypatch)
    rows = json.loads(result)["results"]
    assert rows[0]["status"] == 422 and "output.dt" in rows[0]["body"]["detail"], rows[0]
    assert rows[1]["status"] == 200


def test_the_advised_batch_size_counts_the_largest_answers_not_the_small_ones_kept(tmp_path, monkeypatch):
    """Large and small answers mixed: the number kept counts the small ones too, so advising it
    was wrong (six advised, five of the large ones fitting); the advice is the number of answers
    as large as the largest that the cap holds, and a batch of that many large ones is answered."""
    small = {"robot": "ur5", "path": DENSE["path"]}  # dt 0.01: a few kB
    result, _ = _run([DENSE, small, DENSE, small, small, DENSE, DENSE, small], tmp_path, monkeypatch)
    rows = json.loads(result)["results"]
    refused = [row for row in rows if row["status"] == 422]
    assert refused, [row["status"] for row in rows]
    advised = int(re.search(r"in batches of at most (\d+) requests", refused[0]["body"]["detail"]).group(1))
    kept = sum(row["status"] == 200 for row in rows)
    assert advised < kept  # the small answers do not count
    again, _ = _run([DENSE] * advised, tmp_path, monkeypatch)
    assert [row["status"] for row in json.loads(again)["results"]] == [200] * advised
