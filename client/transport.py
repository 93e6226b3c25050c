"""``Transport``: requests to the service over one keep-alive ``httpx.Client``, error answers
raised as ``ProblemError``; the base of ``client.Client``."""

from __future__ import annotations

from typing import Any, Self

import httpx

from toptraj.client.bodies import plain
from toptraj.client.errors import ProblemError
from toptraj.client.results import CsvTrajectory

CSV = "text/csv"


class Transport:
    """Requests to the service at ``base_url`` over one ``httpx.Client`` (see ``client.Client``)."""

    def __init__(
        self,
        base_url: str = "http://127.0.0.1:8000",
        timeout: float | httpx.Timeout = 60.0,
        *,
        connect_timeout: float = 10.0,
        headers: dict[str, str] | None = None,
        http: httpx.Client | None = None,
    ):
        if http is None:
            limits = timeout if isinstance(timeout, httpx.Timeout) else httpx.Timeout(timeout, connect=connect_timeout)
            http = httpx.Client(base_url=base_url, timeout=limits, headers=headers)
            self._owned = True
        else:
            self._owned = False
        self._http = http

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the connections (unless the ``httpx.Client`` was given)."""
        if self._owned:
            self._http.close()

    def request(
        self,
        method: str,
        path: str,
        json: Any = None,
        *,
        headers: dict[str, str] | None = None,
        params: dict[str, Any] | None = None,
        timeout: float | None = None,
    ) -> httpx.Response:
        """One request as it is, for what the typed methods do not cover: the response, raw.
        ``json`` may hold numpy arrays and scalars (sent as lists and numbers).

        Raises:
            ProblemError: The service answered with a status of 400 or more.
            ValueError: ``json`` holds a NaN or infinite number (JSON has neither).
        """
        extra: dict[str, Any] = {} if timeout is None else {"timeout": timeout}
        if json is not None:
            json = plain(json)
        response = self._http.request(method, path, json=json, headers=headers, params=params, **extra)
        if response.status_code >= 400:
            raise ProblemError.from_response(response)
        return response

    def _call(self, method: str, path: str, json: Any = None, **options: Any) -> Any:
        """The JSON answer of one request (None when it has no body)."""
        response = self.request(method, path, json, **options)
        return response.json() if response.content else None

    def _answer(self, response: httpx.Response) -> Any:
        """A trajectory answer by its media type: CSV, or a JSON body."""
        if response.headers.get("content-type", "").startswith(CSV):
            return CsvTrajectory.from_text(response.text, dict(response.headers))
        return response.json()

