"""The page ``toptraj plot`` writes (``toptraj.service.plots``), opened in a real browser (Playwright driving
Debian's chromium, every other host refused): the arm's 3-D scene is drawn whole, and each
joint's plots carry all of its limits."""

from __future__ import annotations

import pytest

from tests.browser_page import drawn_to_the_edge, launch, offline_page
from tests.paths import ROOT
from toptraj.service.cli import main


@pytest.fixture(scope="module")
def plot_page(tmp_path_factory):
    """The page of ``toptraj plot examples/ur5_spline.json``, open in chromium (nothing but the
    file reachable); ``(page, refused addresses)``."""
    from playwright.sync_api import sync_playwright

    out = tmp_path_factory.mktemp("plot") / "ur5.html"
    assert main(["plot", str(ROOT / "examples" / "ur5_spline.json"), "-o", str(out)]) == 0
    refused: list[str] = []
    with sync_playwright() as playwright:
        browser = launch(playwright)
        page = offline_page(browser, out.as_uri(), refused, viewport={"width": 1400, "height": 900})
        page.goto(out.as_uri())
        page.wait_for_function("() => document.querySelectorAll('.plotly-graph-div').length === 3 && document.querySelector('#scene canvas')")
        page.wait_for_timeout(1500)  # the WebGL scene's first frames
        yield page, refused
        browser.close()


def test_the_plot_page_draws_the_whole_arm(plot_page):
    """The ur5's scene (the arm at 12 instants, its axes and box) lies within its viewport: a
    scene stretched across the page's width was cut at its bottom."""
    page, refused = plot_page
    arm = page.locator(".plotly-graph-div").nth(2)
    assert arm.evaluate("(d) => d.data.filter((t) => t.type === 'scatter3d').length") == 12
    scene = arm.locator("#scene").bounding_box()
    box = {**scene, "y": scene["y"] + page.evaluate("() => scrollY")}
    assert drawn_to_the_edge(page.screenshot(full_page=True), box) == {"top": 0, "bottom": 0, "left": 0, "right": 0}
    assert refused == []


def test_the_plot_page_draws_every_limit_of_every_joint(plot_page):
    """Dashed lines at each joint's position range and at ± its velocity, acceleration and
    torque limits (the ur5's, from its URDF and limits.toml), whatever its utilization."""
    from toptraj import robots

    page, _ = plot_page
    robot = robots.load("ur5")
    limits = robot.limits
    lines = page.locator(".plotly-graph-div").nth(1).evaluate(
        "(d) => d.data.filter((t) => / limit$/.test(t.name || '')).map((t) => [t.name, Array.from(t.y)])"
    )
    drawn: dict[str, set[float]] = {}
    for name, ys in lines:
        assert ys[0] == ys[1]  # a horizontal line
        drawn.setdefault(name, set()).add(ys[0])
    for joint, name in enumerate(robot.joint_names):
        expected = {
            "position": (limits.position_lower[joint], limits.position_upper[joint]),
            "velocity": (-limits.velocity[joint], limits.velocity[joint]),
            "acceleration": (-limits.acceleration[joint], limits.acceleration[joint]),
            "torque": (-limits.torque[joint], limits.torque[joint]),
        }
        for kind, bounds in expected.items():
            assert sorted(drawn[f"{name} {kind} limit"]) == pytest.approx(sorted(bounds), rel=1e-12), (name, kind)
