"""Shared fixtures: one app and TestClient per test module."""

from __future__ import annotations

import warnings

import pytest

warnings.filterwarnings("ignore", message=".*httpx2.*")

from fastapi.testclient import TestClient  # noqa: E402

from service.app import create_app  # noqa: E402
from service.settings import Settings  # noqa: E402

UR5_WAYPOINTS = [
    [0.0, -1.2, 1.0, 0.0, 0.0, 0.0],
    [0.8, -1.0, 1.4, -0.5, 0.6, 0.3],
    [1.5, -0.5, 0.8, -1.0, 1.0, 0.8],
    [2.0, -1.3, 1.2, 0.2, 0.4, 1.2],
]


@pytest.fixture(scope="module")
def client():
    with TestClient(create_app(Settings(preload_robots=False))) as test_client:
        yield test_client
