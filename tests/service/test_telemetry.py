"""FastAPI's OpenTelemetry instrumentation is off unless ``TOPTRAJ_TELEMETRY`` turns it on: the
service sets up no provider, and the instrumentation's checks would cost every request time."""

from __future__ import annotations

from toptraj.service.app import create_app
from toptraj.service.settings import Settings


def _instrumentation(settings: Settings) -> dict:
    config = create_app(settings)._telemetry  # what FastAPI(telemetry=...) was given
    return {part: config[part] for part in ("tracing", "metrics", "logs", "operation_spans")}


def test_the_instrumentation_is_off_by_default_and_on_when_asked(tmp_path, monkeypatch):
    assert _instrumentation(Settings(data_dir=tmp_path, preload_robots=False)) == dict.fromkeys(
        ("tracing", "metrics", "logs", "operation_spans"), False
    )
    monkeypatch.setenv("TOPTRAJ_TELEMETRY", "1")
    assert _instrumentation(Settings(data_dir=tmp_path, preload_robots=False)) == dict.fromkeys(
        ("tracing", "metrics", "logs", "operation_spans"), True
    )
