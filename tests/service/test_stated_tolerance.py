"""Every place that states how closely limits are held states the same figure: the promise
(``PROMISED_TOLERANCE``, 0.5 % on a dense resampling), not the gate's tighter threshold."""

from __future__ import annotations

import re

import pytest

from tests.paths import ROOT
from toptraj.client.results import Utilization
from toptraj.planners.checks.gate import LIMIT_TOLERANCE, PROMISED_TOLERANCE
from toptraj.service.compare_table import compare_table
from toptraj.service.formats import TOLERANCE_PERCENT, csv_metadata

BODY = {"robot": "r", "method": "m", "duration": 1.0, "sampled_duration": 1.0, "peak_utilization": {"velocity": [1.0]}, "warnings": []}


def test_the_promise_is_looser_than_the_gate():
    assert TOLERANCE_PERCENT == 0.5 and LIMIT_TOLERANCE < PROMISED_TOLERANCE


def test_the_csv_and_the_compare_table_state_the_promise():
    assert any("held within 0.5 %" in line for line in csv_metadata(BODY))
    assert "held within 0.5 %" in compare_table({"results": [{"method": "m", **BODY}]})


@pytest.mark.parametrize("document", ["README.md", "docs/concepts.md", "docs/client.md"])
def test_the_docs_state_the_promise(document):
    text = (ROOT / document).read_text()
    assert "0.5 %" in text and "within 0.3 %" not in text and "by more than 0.3 % on a dense resampling" not in text


def test_the_clients_utilization_states_the_promise():
    assert "within 0.5 %" in (Utilization.__doc__ or "")


def _descriptions(value) -> list[str]:
    """Every ``description`` in an OpenAPI document (nested dicts and lists)."""
    if isinstance(value, dict):
        return [*([value["description"]] if isinstance(value.get("description"), str) else []), *(text for item in value.values() for text in _descriptions(item))]
    if isinstance(value, list):
        return [text for item in value for text in _descriptions(item)]
    return []


def test_the_openapi_descriptions_state_the_promise(client):
    """Each figure stated before "on a dense resampling" is the promise (``limit_margin`` states one)."""
    descriptions = _descriptions(client.get("/openapi.json").json())
    stated = [figure for text in descriptions for figure in re.findall(r"([\d.]+) % on a dense resampling", text)]
    assert stated and set(stated) == {"0.5"}
    assert not any("0.3 %" in text for text in descriptions)
