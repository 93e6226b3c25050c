"""The web page with a cell (POST /v1/cells) in a real browser: the two-ur5 preset planned,
the duration the API gives, both arms in one stroboscope (each at 12 instants, placed by its
base pose), and the coordination diagram: the API's collision region and curve."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.browser_page import serve_page

browser_page = pytest.fixture(scope="module")(serve_page)
PRESET = "Two ur5 across a table, crossing paths (a cell: POST /v1/cells)"


def test_the_cell_preset_shows_both_arms_and_the_coordination_diagram(browser_page):
    page, base, server, outside = browser_page
    page.goto(base + "/")
    page.wait_for_selector("body[data-ready=true]", timeout=30_000)
    page.select_option("#preset", PRESET)
    page.click("#plan")
    page.wait_for_selector("body[data-planned=true], #error:not([hidden])", timeout=120_000)
    assert not page.is_visible("#error"), page.inner_text("#error")
    request = json.loads(page.input_value("#path")) | {"dt": float(page.input_value("#dt")), "format": "samples"}
    status, _, raw = server.request("POST", "/v1/cells", request)
    assert status == 200
    answer = json.loads(raw)
    assert float(page.get_attribute("#duration", "data-duration")) == answer["duration"]
    assert page.inner_text("#duration") == f"cell of 2 arms: {answer['duration']:.4f} s"
    # both arms at 12 instants, the second placed by its base 1.2 m along x
    arms = page.evaluate("() => document.getElementById('arm').data.map((t) => ({name: t.name, x: t.x}))")
    for index in (0, 1):
        traces = [trace for trace in arms if trace["name"].startswith(f"arms[{index}] t = ")]
        assert len(traces) == 12
        assert traces[0]["x"][0] == pytest.approx(1.2 * index, abs=1e-9)  # the base's origin, first point of the figure
    # the diagram: the API's collision region (transposed: s1 along x) and the curve taken
    shown = page.evaluate(
        "() => document.getElementById('phase-plane').data.map((t) => ({type: t.type, x: t.x, y: t.y, z: t.z}))"
    )
    heatmap = next(trace for trace in shown if trace["type"] == "heatmap")
    assert np.array_equal(np.array(heatmap["z"]).T, np.array(answer["diagram"]["blocked"]))
    curve = np.array(answer["diagram"]["curve"])
    line = next(trace for trace in shown if trace["type"] != "heatmap")
    assert np.allclose(line["x"], curve[:, 0]) and np.allclose(line["y"], curve[:, 1])
    # the trajectory's tables and joint plots are not shown for a cell
    assert not page.is_visible("#joints") and not page.is_visible("#downloads")
    assert page.locator("#warnings li").count() == len(answer["warnings"]) == 0
    # under velocity limits only, the answer's warnings (accelerations and torques past their limits) are listed
    cell = json.loads(page.input_value("#path"))
    page.fill("#path", json.dumps(cell | {"constraints": ["velocity"]}))
    page.click("#plan")
    page.wait_for_function("() => document.querySelectorAll('#warnings li').length > 0", timeout=120_000)
    warned = json.loads(server.request("POST", "/v1/cells", request | {"constraints": ["velocity"]})[2])
    assert page.locator("#warnings li").all_inner_texts() == warned["warnings"]
    assert outside == []


def test_a_cell_is_kept_in_the_link_and_hides_the_single_arm_controls(browser_page):
    """The single-arm controls (robot, methods, constraints), which a cell ignores, are hidden
    while the path holds a cell; the link after planning one reopens and plans that cell."""
    page, base, server, outside = browser_page
    page.goto(base + "/")
    page.wait_for_selector("body[data-ready=true]", timeout=30_000)
    assert page.is_visible("#robot") and page.is_visible("#constraints") and not page.is_visible("#cell-note")
    page.select_option("#preset", PRESET)
    assert not page.is_visible("#robot") and not page.is_visible("#methods") and not page.is_visible("#constraints")
    assert page.is_visible("#cell-note")
    cell = json.loads(page.input_value("#path"))
    page.fill("#path", json.dumps(cell | {"clearance": 0.03}))
    page.click("#plan")
    page.wait_for_selector("body[data-planned=true], #error:not([hidden])", timeout=120_000)
    assert not page.is_visible("#error"), page.inner_text("#error")
    planned = float(page.get_attribute("#duration", "data-duration"))
    link = page.url
    assert "#r=" in link
    page.goto("about:blank")
    page.goto(link)
    page.wait_for_selector("body[data-planned=true], #error:not([hidden])", timeout=120_000)
    assert not page.is_visible("#error"), page.inner_text("#error")
    assert json.loads(page.input_value("#path"))["clearance"] == 0.03
    assert float(page.get_attribute("#duration", "data-duration")) == planned
    assert page.inner_text("#duration").startswith("cell of 2 arms")
    # a single arm's path again: its controls are back
    page.fill("#path", json.dumps({"kind": "waypoints", "waypoints": [[0.0, 0.0], [1.0, 1.0]]}))
    page.dispatch_event("#path", "input")
    assert page.is_visible("#robot") and page.is_visible("#constraints") and not page.is_visible("#cell-note")
    assert outside == []
