"""Both stores open their SQLite file the same way (``toptraj.robots.sqlite_file``): a store in a
data directory that cannot be one raises the store's own "unavailable" error naming it and the
setting to fix; reading a store that does not exist creates nothing; writing creates it."""

from __future__ import annotations

import pytest

from toptraj.robots.errors import UploadStoreUnavailable
from toptraj.robots.store import UploadStore
from toptraj.service.jobs.records import JobStoreUnavailable
from toptraj.service.jobs.store import JobStore


def test_a_data_directory_that_is_a_file_makes_each_store_say_so(tmp_path):
    not_a_directory = tmp_path / "file"
    not_a_directory.write_text("")
    with pytest.raises(UploadStoreUnavailable, match=r"^the upload store cannot be used \(.*TOPTRAJ_DATA_DIR"):
        UploadStore(not_a_directory).put("arm", "0" * 64, "<robot/>", 1)
    with pytest.raises(JobStoreUnavailable, match=r"^the job store cannot be used \(.*TOPTRAJ_DATA_DIR"):
        JobStore(not_a_directory, max_jobs=3, max_age_s=3600, max_bytes=10_000).submit("trajectory", "{}", 1.0, 10)


def test_reading_creates_nothing_and_writing_creates_the_store(tmp_path):
    jobs = JobStore(tmp_path / "data", max_jobs=3, max_age_s=3600, max_bytes=10_000)
    assert jobs.get("nope") is None and not (tmp_path / "data").exists()
    job = jobs.submit("trajectory", "{}", 1.0, 10)
    assert jobs.get(job.id).status == "queued" and (tmp_path / "data" / "jobs.sqlite3").exists()
    uploads = UploadStore(tmp_path / "other")
    assert uploads.uploads() == [] and not (tmp_path / "other").exists()
    assert uploads.put("arm", "0" * 64, "<robot/>", 1) and [row.name for row in uploads.uploads()] == ["arm"]
