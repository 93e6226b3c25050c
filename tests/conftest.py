"""Shared fixtures: one app and TestClient per test module, each with its own temporary data
directory; ``TOPTRAJ_DATA_DIR`` points at a temporary directory too, so that no test (nor a
process a test starts) reads or writes the user's data directory."""

from __future__ import annotations

import os
import shutil
import tempfile
import warnings

import pytest

warnings.filterwarnings("ignore", message=".*httpx2.*")

_SESSION_DATA_DIR = tempfile.mkdtemp(prefix="toptraj-test-data-")
os.environ["TOPTRAJ_DATA_DIR"] = _SESSION_DATA_DIR

from fastapi.testclient import TestClient  # noqa: E402

from toptraj.planners.execution.threads import single_blas_thread  # noqa: E402
from toptraj.service.app import create_app  # noqa: E402
from toptraj.service.settings import Settings  # noqa: E402

UR5_WAYPOINTS = [
    [0.0, -1.2, 1.0, 0.0, 0.0, 0.0],
    [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
    [1.5, -0.5, 0.8, -1.0, 1.0, 0.8],
    [2.0, -1.3, 1.2, 0.2, 0.4, 1.2],
]


# Library-level tests plan in this process as the service does, with one BLAS thread; two test
# workers on two cores would otherwise spin each other's BLAS threads.
single_blas_thread()


def pytest_sessionfinish(session, exitstatus):
    shutil.rmtree(_SESSION_DATA_DIR, ignore_errors=True)


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    settings = Settings(preload_robots=False, data_dir=tmp_path_factory.mktemp("data"))
    with TestClient(create_app(settings)) as test_client:
        yield test_client


@pytest.fixture(scope="module")
def patient_client(tmp_path_factory):
    """A client whose planning budget fits a free-path collocation, which takes tens of seconds
    on a loaded machine (the synchronous default is 20 s)."""
    settings = Settings(preload_robots=False, data_dir=tmp_path_factory.mktemp("data"), plan_budget_s=300.0)
    with TestClient(create_app(settings)) as test_client:
        yield test_client

