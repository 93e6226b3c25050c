"""docs/client.md's table of endpoints names every call of ``Client``."""

from __future__ import annotations

import inspect

from tests.paths import ROOT
from toptraj.client import Client

#: The transport's own calls, which no endpoint answers alone.
TRANSPORT = {"close", "request"}


def test_every_client_call_is_in_the_endpoint_table():
    text = (ROOT / "docs" / "client.md").read_text()
    table = text[text.index("| Endpoint | Method |"):]
    table = table[: table.index("\n\n")]
    calls = {name for name, _ in inspect.getmembers(Client, inspect.isfunction) if not name.startswith("_")} - TRANSPORT
    assert sorted(name for name in calls if f"`{name}(" not in table and f" {name}(" not in table) == []
    assert "| `POST /v1/cells` | `cell(body)`" in table
