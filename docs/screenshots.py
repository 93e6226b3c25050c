"""The README's screenshots of the web page: the ur5 example, the Geering free-path example and
the Geering arm around a sphere (the global search), planned in a real browser (Playwright
driving chromium) against a server started here.

    python docs/screenshots.py [FILE ...]   # writes docs/page_ur5.png, docs/page_geering_free.png,
                                            # docs/page_geering_search.png and docs/page_ur5_phone.png
                                            # (390 px wide), or the files named
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from tests.live_server import LiveServer  # noqa: E402

# file: the index of the page's example, and the width of the window (px)
SHOTS = {"page_ur5.png": (0, 1400), "page_geering_free.png": (1, 1400), "page_geering_search.png": (2, 1400), "page_ur5_phone.png": (0, 390)}


def main() -> None:
    from playwright.sync_api import sync_playwright

    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    with LiveServer(TOPTRAJ_PRELOAD_ROBOTS="false") as server, sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=chromium, args=["--no-sandbox", "--disable-dev-shm-usage"])
        for name, (preset, width) in SHOTS.items():
            if sys.argv[1:] and name not in sys.argv[1:]:
                continue
            page = browser.new_page(viewport={"width": width, "height": 1300})
            page.goto(f"http://127.0.0.1:{server.port}/")
            page.wait_for_selector("body[data-ready=true]")
            page.select_option("#preset", index=preset)
            page.click("#plan")
            page.wait_for_selector("body[data-planned=true]", timeout=300_000)
            page.wait_for_timeout(500)  # let the plots settle
            page.screenshot(path=str(HERE / name), full_page=True)
            print(name, page.inner_text("#summary"))
            page.close()
        browser.close()


if __name__ == "__main__":
    main()
