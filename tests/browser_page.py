"""A chromium page (Playwright driving Debian's chromium) that reaches nothing but a live
``toptraj serve``: every other host is refused, and the refused addresses are kept."""

from __future__ import annotations

import io
import shutil

from tests.live_server import LiveServer

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def offline_page(browser, base: str | None, outside: list[str], **options):
    """A new page of ``browser`` whose requests go through only to ``base`` (none when None);
    any other address is refused and appended to ``outside``."""
    page = browser.new_page(**options)

    def offline(route):
        if base is not None and route.request.url.startswith(base):
            return route.continue_()
        outside.append(route.request.url)
        return route.abort()

    page.route("**/*", offline)
    return page


def launch(playwright):
    assert CHROMIUM, "a real browser is needed: apt-get install chromium (make browser does it)"
    return playwright.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox", "--disable-dev-shm-usage"])


def serve_page():
    """A page of 1400 x 1300 px on a server of its own: ``(page, base, server, outside)`` (a
    module's fixture: ``browser_page = pytest.fixture(scope="module")(serve_page)``)."""
    from playwright.sync_api import sync_playwright

    # a job's default budget of 30 s: the page's search runs as a job, which then returns the best
    # curve its local optimization reached in that time
    with LiveServer(TOPTRAJ_PRELOAD_ROBOTS="false", TOPTRAJ_JOB_BUDGET_S="30") as server, sync_playwright() as playwright:
        browser = launch(playwright)
        base = f"http://127.0.0.1:{server.port}"
        outside: list[str] = []
        page = offline_page(browser, base, outside, viewport={"width": 1400, "height": 1300}, accept_downloads=True)
        yield page, base, server, outside
        browser.close()


def drawn_to_the_edge(png: bytes, box: dict) -> dict[str, int]:
    """Pixels of each edge of ``box`` (the 3-D scene's viewport) that are not the page's white:
    a picture that reaches its viewport's edge is cut there."""
    from PIL import Image

    image = Image.open(io.BytesIO(png)).convert("RGB")
    x, y, w, h = (round(box[key]) for key in ("x", "y", "width", "height"))
    pixels = image.crop((x, y, x + w, y + h)).load()
    edges = {
        "top": [pixels[i, 1] for i in range(w)],
        "bottom": [pixels[i, h - 2] for i in range(w)],
        "left": [pixels[1, j] for j in range(h)],
        "right": [pixels[w - 2, j] for j in range(h)],
    }
    return {edge: sum(min(colour) < 235 for colour in colours) for edge, colours in edges.items()}
