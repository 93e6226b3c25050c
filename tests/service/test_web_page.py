"""The web page in a real browser (Playwright driving Debian's chromium): it loads with no
internet, plans the ur5 example, draws its plots, and shows the duration the API gives; ``/docs``
renders its operations offline too."""

from __future__ import annotations

import json

import pytest

from tests.browser_page import serve_page

browser_page = pytest.fixture(scope="module")(serve_page)


def _plotted(page, element: str) -> int:
    """Traces Plotly drew in ``element`` (0 when nothing was drawn)."""
    return page.evaluate(
        f"() => {{ const d = document.getElementById('{element}'); "
        "return d && d.data && d.querySelector('.main-svg') ? d.data.length : 0; }"
    )


def test_the_page_plans_the_ur5_example_and_draws_it(browser_page):
    page, base, server, outside = browser_page
    page.goto(base + "/")
    page.wait_for_selector("body[data-ready=true]", timeout=30_000)
    assert page.input_value("#robot") == "ur5"
    page.click("#plan")
    page.wait_for_selector("body[data-planned=true], #error:not([hidden])", timeout=60_000)
    assert not page.is_visible("#error"), page.inner_text("#error")
    shown = float(page.get_attribute("#duration", "data-duration"))
    request = page.evaluate(
        "() => ({robot: document.getElementById('robot').value, path: JSON.parse(document.getElementById('path').value),"
        " timing: {method: 'phase_plane', constraints: ['velocity', 'acceleration', 'torque']}, output: {dt: 0.01}})"
    )
    status, _, raw = server.request("POST", "/v1/trajectories", request)
    assert status == 200
    answer = json.loads(raw)
    assert shown == answer["duration"]
    assert page.inner_text("#duration").startswith(f"phase_plane: {answer['duration']:.4f} s")
    # the warnings and the binding limit, as the API says them
    assert page.locator("#warnings li").all_inner_texts() == answer["warnings"]
    assert answer["binding"] is None and page.inner_text("#binding") == ""  # phase_plane names no binding limit
    assert _plotted(page, "phase-plane") >= 3  # speed, maximum velocity curve, switch points
    assert _plotted(page, "joints") >= 4 * 6  # q, qd, qdd, tau of six joints
    assert _plotted(page, "arm") == 12  # the arm at 12 instants
    rows = page.locator("#durations tbody tr")
    assert rows.count() == 3 and rows.nth(0).inner_text().startswith("phase_plane")
    # each compared method's duration, and the limit that binds a time law, as /compare says them
    methods = [rows.nth(k).locator("td").nth(0).inner_text() for k in range(3)]
    status, _, raw = server.request("POST", "/v1/trajectories/compare", {
        "robot": request["robot"], "path": request["path"], "methods": methods,
        "timing": {"constraints": request["timing"]["constraints"]},
    })
    assert status == 200
    for k, result in enumerate(json.loads(raw)["results"]):
        cells = rows.nth(k).locator("td").all_inner_texts()
        assert float(cells[1]) == pytest.approx(result["duration"], abs=5e-5 + 1e-9)  # shown to 4 decimals
        binding = result["binding"]
        assert cells[3].strip() == ("" if binding is None else f"{binding['kind']} {binding['joint'] or ''}".strip())
    assert any(result["binding"] for result in json.loads(raw)["results"])  # the quintic's binding limit is shown
    assert outside == []


def test_an_error_shows_the_problem_detail(browser_page):
    page, base, _, _ = browser_page
    page.goto(base + "/")
    page.wait_for_selector("body[data-ready=true]")
    page.fill("#path", '{"kind": "waypoints", "waypoints": [[0, 0, 0, 0, 0, 0], [9, 0, 0, 0, 0, 0]]}')
    page.click("#plan")
    page.wait_for_selector("#error:not([hidden])", timeout=30_000)
    assert "outside the limits" in page.inner_text("#error") and "422" in page.inner_text("#error")


def test_the_search_preset_draws_the_obstacle_and_its_shadows(browser_page):
    """The Geering arm around a sphere (Jeong & Lee section 2): planned as a job by the global
    search, the arm's picture shows the sphere and the obstacle shadows of section 2.2."""
    page, base, _, outside = browser_page
    page.goto(base + "/")
    page.wait_for_selector("body[data-ready=true]")
    page.select_option("#preset", "Geering arm around a sphere (global search, Jeong & Lee §2)")
    assert page.input_value("#robot") == "geering_2r"
    page.click("#plan")
    page.wait_for_selector("body[data-planned=true], #error:not([hidden])", timeout=120_000)
    assert not page.is_visible("#error"), page.inner_text("#error")
    shown = float(page.get_attribute("#duration", "data-duration"))
    assert shown >= 0.9755 * 0.998  # never below the obstacle-free optimum (the paper's 0.9755 s)
    assert page.inner_text("#duration").startswith("search: ")
    names = page.evaluate("() => document.getElementById('arm').data.map((trace) => trace.name)")
    assert "obstacle" in names
    assert any(name.startswith("obstacle shadow") for name in names)
    assert sum(name.startswith("t = ") for name in names) == 12
    assert outside == []


@pytest.mark.parametrize("docs", ["/docs", "/redoc"])
def test_the_api_docs_render_offline(browser_page, docs):
    page, base, _, outside = browser_page
    page.goto(base + docs)
    for operation in ("Plan a timed trajectory", "Compare timing methods on one path", "Start a background job"):
        page.get_by_text(operation).first.wait_for(state="attached", timeout=30_000)
    assert page.get_by_text("/v1/trajectories").count() > 0
    # nothing from elsewhere: ReDoc's "powered by" logo on its vendor's CDN is left out by the
    # page's Content-Security-Policy (service/offline_pages.py) before the browser asks for it
    assert outside == []
