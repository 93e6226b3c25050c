"""The documentation site (``mkdocs.yml``, ``docs/``): it builds offline with ``--strict``, a
broken link, anchor or reference fails that build, the pages load nothing from another host,
the library's reference comes from its docstrings, and the service serves the built site at
``/guide/`` (with a 404 problem saying how to build it when it is absent)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from fastapi.testclient import TestClient

from tests.paths import ROOT
from toptraj.service.app import create_app
from toptraj.service.settings import Settings

for _module in ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python"):
    pytest.importorskip(_module, reason="the docs extra (mkdocs, mkdocs-material, mkdocstrings) is not installed")

#: Pages of the site, by their path under /guide/, and a phrase each must hold.
PAGES = {
    "": "Time-optimal trajectories",
    "installation/": "Requirements",
    "concepts/": "peak_utilization",
    "paths/": "max_deviation",
    "methods/": "Which method when",
    "http-api/": "TOPTRAJ_PLAN_BUDGET_S",
    "errors/": "problem+json",
    "uploads/": "joint_limits.yaml",
    "jobs/": "budget_s",
    "cli/": "toptraj plan",
    "web-page/": "stroboscopic",
    "performance/": "benchmarks/end_to_end.py",
    "papers/": "0.9755",
    "architecture/": "ToptrajError",
    "design/": "Design notes",
    "reference/planners/": "PlannedTrajectory",
    "reference/robots/": "JointLimits",
    "client/": "ProblemError",
}


def _build(config: Path, site: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    return subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config), "-d", str(site)],
        cwd=config.parent, env=env, capture_output=True, text=True, timeout=300,
    )


def _config_copy(tmp: Path) -> Path:
    """The site's configuration over a copy of docs/ in ``tmp`` (the library read from the
    repository), so that a test may break a page without touching the repository."""
    shutil.copytree(ROOT / "docs", tmp / "docs", ignore=shutil.ignore_patterns("__pycache__"))
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())
    config["hooks"] = [str(tmp / hook) for hook in config.get("hooks", [])]
    for plugin in config["plugins"]:
        if isinstance(plugin, dict) and "mkdocstrings" in plugin:
            plugin["mkdocstrings"]["handlers"]["python"]["paths"] = [str(ROOT)]
    path = tmp / "mkdocs.yml"
    path.write_text(yaml.safe_dump(config, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("site")
    result = _build(ROOT / "mkdocs.yml", out)
    assert result.returncode == 0, result.stderr[-3000:]
    return out


def test_every_page_is_built_with_its_content(site):
    for page, phrase in PAGES.items():
        html = (site / page / "index.html").read_text()
        assert phrase in html, f"/guide/{page} lacks {phrase!r}"


def test_the_reference_comes_from_the_docstrings(site):
    html = (site / "reference" / "planners" / "index.html").read_text()
    # plan's own docstring and its signature, rendered by mkdocstrings
    assert 'id="toptraj.planners.plan.plan"' in html and 'id="toptraj.planners.LimitRequest"' in html
    assert "Plan the timed trajectory of" in html
    robots_html = (site / "reference" / "robots" / "index.html").read_text()
    assert 'id="toptraj.robots.Robot"' in robots_html and 'id="toptraj.robots.load"' in robots_html
    client_html = (site / "client" / "index.html").read_text()
    assert 'id="toptraj.client.Client"' in client_html


def test_no_page_loads_anything_from_another_host(site):
    pages = list(site.rglob("*.html"))
    assert len(pages) >= len(PAGES)
    for page in pages:
        html = page.read_text()
        assert not re.search(r"""<(script|link|img|iframe)\b[^>]*\b(src|href)\s*=\s*["']?(https?:)?//""", html), page
        assert "fonts.googleapis" not in html and "fonts.gstatic" not in html, page
    assert (site / "search" / "search_index.json").is_file()


def test_a_broken_link_or_anchor_fails_the_build(tmp_path):
    config = _config_copy(tmp_path)
    page = tmp_path / "docs" / "concepts.md"
    page.write_text(page.read_text() + "\n\nSee [the missing page](no-such-page.md) and [a missing part](methods.md#no-such-anchor).\n")
    result = _build(config, tmp_path / "site")
    assert result.returncode != 0
    assert "no-such-page.md" in result.stderr
    assert "no-such-anchor" in result.stderr


def test_a_missing_reference_fails_the_build(tmp_path):
    config = _config_copy(tmp_path)
    (tmp_path / "docs" / "client.md").write_text("# Python client\n\n::: toptraj.client.NoSuchThing\n")
    result = _build(config, tmp_path / "site")
    assert result.returncode != 0
    assert "toptraj.client.NoSuchThing" in result.stderr


def _guide_client(guide_dir: Path, tmp_path: Path) -> TestClient:
    return TestClient(create_app(Settings(preload_robots=False, data_dir=tmp_path / "data", guide_dir=guide_dir)))


def test_the_service_serves_the_built_site_at_guide(site, tmp_path):
    with _guide_client(site, tmp_path) as client:
        bare = client.get("/guide", follow_redirects=False)
        assert bare.status_code == 308 and bare.headers["location"] == "/guide/"
        for page, phrase in PAGES.items():
            response = client.get(f"/guide/{page}")
            assert response.status_code == 200, page
            assert response.headers["content-type"].startswith("text/html")
            assert phrase in response.text
        # every asset a page loads is served, with its media type
        home = client.get("/guide/").text
        assets = re.findall(r"""<(?:script|link)\b[^>]*\b(?:src|href)="([^"]+\.(?:js|css))""", home)
        assert any(a.endswith(".css") for a in assets) and any(a.endswith(".js") for a in assets)
        for asset in assets:
            served = client.get("/guide/" + asset)
            assert served.status_code == 200, asset
            assert served.headers["content-type"].split(";")[0] in ("text/css", "text/javascript"), asset
        assert client.get("/guide/methods", follow_redirects=False).headers["location"] == "/guide/methods/"
        for outside in ("/guide/../../pyproject.toml", "/guide/%2e%2e/%2e%2e/settings.py", "/guide/no-such-page/"):
            missing = client.get(outside)
            assert missing.status_code == 404, outside
            assert missing.headers["content-type"] == "application/problem+json"


def test_an_absent_site_is_a_404_that_says_how_to_build_it(tmp_path):
    with _guide_client(tmp_path / "not-built", tmp_path) as client:
        for path in ("/guide/", "/guide/methods/"):
            response = client.get(path)
            assert response.status_code == 404
            assert response.headers["content-type"] == "application/problem+json"
            assert "make guide" in response.json()["detail"]


def test_the_page_and_the_api_docs_link_to_the_guide(client):
    assert 'href="/guide/"' in client.get("/").text
    assert "/guide/" in client.get("/openapi.json").json()["info"]["description"]


def test_the_guide_works_in_a_browser_with_no_other_host(site):
    """Material's pages, styles, scripts and search in Debian's chromium against a real server,
    every other host refused: nothing is fetched from elsewhere, and the search finds a method."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        pytest.skip("no chromium: apt-get install chromium (make test does it)")
    from playwright.sync_api import sync_playwright

    from tests.live_server import LiveServer

    with LiveServer(TOPTRAJ_PRELOAD_ROBOTS="false", TOPTRAJ_GUIDE_DIR=str(site)) as server, sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=chromium, args=["--no-sandbox", "--disable-dev-shm-usage"])
        page = browser.new_page(viewport={"width": 1300, "height": 900})
        base = f"http://127.0.0.1:{server.port}"
        outside: list[str] = []

        def offline(route):
            if route.request.url.startswith(base):
                return route.continue_()
            outside.append(route.request.url)
            return route.abort()

        page.route("**/*", offline)
        page.goto(base + "/")
        page.click("a[href='/guide/']")
        page.wait_for_url(base + "/guide/")
        # the theme's style sheet applied: its header bar is laid out at the top
        assert page.locator("header.md-header").bounding_box()["height"] > 20
        page.click("text=Methods")
        page.wait_for_url(base + "/guide/methods/")
        # Material reads the query on keyup (and once when its search worker is ready): wait for the
        # index, then type key by key as a person does; `fill` sends no keyup and races the worker
        page.click("input.md-search__input")
        page.wait_for_function(
            "() => { const m = document.querySelector('.md-search-result__meta');"
            " return m && m.textContent.trim() !== '' && !/Initializing/.test(m.textContent); }",
            timeout=60_000,
        )
        page.locator("input.md-search__input").press_sequentially("jerk_limited")
        page.wait_for_selector(".md-search-result__item", timeout=30_000)
        assert "jerk_limited" in page.inner_text(".md-search-result")
        browser.close()
        assert outside == []
