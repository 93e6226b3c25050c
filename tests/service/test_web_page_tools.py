"""The web page's tools in a real browser (Playwright driving Debian's chromium, every other host
refused): limit lines on every plot, the peak-utilization table, the downloads (JSON, CSV,
JointTrajectory, the page as one HTML file), cancelling a job, a 390 px wide screen, and the
request kept in the URL."""

from __future__ import annotations

import base64
import csv
import io
import json
import zlib

import pytest

from tests.browser_page import drawn_to_the_edge, offline_page, serve_page

browser_page = pytest.fixture(scope="module")(serve_page)

UR5_PATH = {"kind": "waypoints", "interpolation": "spline", "waypoints": [
    [0.0, -1.2, 1.0, 0.0, 0.3, 0.0], [0.8, -1.0, 1.4, -0.5, 0.6, 0.3], [1.5, -0.5, 0.8, -1.0, 1.0, 0.8]]}
SEARCH = "Geering arm around a sphere (global search, Jeong & Lee §2)"


def _plan(page, base: str, fragment: str = "", timeout: float = 60_000) -> None:
    """Open the page (with a URL fragment, planned at once when it holds a request), or open it
    and press Plan; wait for the answer and fail on an error."""
    page.goto("about:blank")  # a new document, not a move to another fragment of the same one
    page.goto(base + "/" + fragment)
    page.wait_for_selector("body[data-ready=true]", timeout=30_000)
    if not fragment:
        page.click("#plan")
    page.wait_for_selector("body[data-planned=true], #error:not([hidden])", timeout=timeout)
    assert not page.is_visible("#error"), page.inner_text("#error")


def _deflated(text: bytes) -> str:
    deflater = zlib.compressobj(wbits=-15)
    return base64.urlsafe_b64encode(deflater.compress(text) + deflater.flush()).decode().rstrip("=")


def _fragment(form: dict) -> str:
    """The page's URL fragment of ``form``, made independently: raw deflate, base64url."""
    return "#r=" + _deflated(json.dumps({"v": 1, **form}).encode())


def _request(page) -> dict:
    """The POST /v1/trajectories body of the page's form (its first method)."""
    return page.evaluate(
        "() => ({robot: document.getElementById('robot').value, path: JSON.parse(document.getElementById('path').value),"
        " timing: {method: [...document.querySelectorAll('#methods input:checked')][0].value,"
        " constraints: [...document.querySelectorAll('#constraints input:checked')].map((b) => b.value)},"
        " output: {dt: Number(document.getElementById('dt').value)}})"
    )


def _answer(server, request: dict, **output) -> bytes:
    status, _, raw = server.request("POST", "/v1/trajectories", {**request, "output": {**request["output"], **output}})
    assert status == 200, raw
    return raw


def _limit_lines(page) -> dict[tuple[str, str], list[float]]:
    """The dashed limit lines of the joints plot: (kind, joint) -> their y values."""
    lines = page.evaluate(
        "() => document.getElementById('joints').data.filter((t) => t.meta && t.meta.limit)"
        ".map((t) => [t.meta.limit, t.meta.joint, t.y[0], t.y[1]])"
    )
    found: dict[tuple[str, str], list[float]] = {}
    for kind, joint, y0, y1 in lines:
        assert y0 == y1  # a horizontal line
        found.setdefault((kind, joint), []).append(y0)
    return {key: sorted(values) for key, values in found.items()}


def test_every_plot_draws_each_joints_limits(browser_page):
    """q against its range, q̇, q̈ and τ against their limits, for every joint whatever its
    utilization (the ur5's τ peaks at 48 % of a limit: no line was drawn for it before)."""
    page, base, server, outside = browser_page
    _plan(page, base)
    status, _, raw = server.request("GET", "/v1/robots/ur5")
    limits = json.loads(raw)["limits"]
    lines = _limit_lines(page)
    names = json.loads(raw)["joint_names"]
    for joint, name in enumerate(names):
        assert lines[("position", name)] == [limits["position_lower"][joint], limits["position_upper"][joint]]
        for kind in ("velocity", "acceleration", "torque"):
            assert lines[(kind, name)] == [-limits[kind][joint], limits[kind][joint]]
    assert not any(kind == "jerk" for kind, _ in lines)  # phase_plane has no finite jerk: no jerk row
    assert outside == []


def test_a_jerk_limited_answer_draws_its_jerk_against_the_limit(browser_page):
    page, base, server, outside = browser_page
    form = {"robot": "ur5", "path": UR5_PATH, "methods": ["jerk_limited"], "constraints": ["velocity", "acceleration", "torque", "jerk"], "dt": 0.01}
    _plan(page, base, _fragment(form))
    answer = json.loads(_answer(server, _request(page)))
    lines = _limit_lines(page)
    for joint, name in enumerate(answer["joint_names"]):
        assert lines[("jerk", name)] == [-200.0, 200.0]  # the ur5's jerk limits (acceleration / 0.05 s)
        jerk = page.evaluate(f"() => document.getElementById('joints').data.filter((t) => t.name === '{name}' && t.yaxis === 'y4')[0].y")
        # differences of q̈ average the jerk over a period: never above its peak on the dense resampling
        assert 0.5 * answer["peak_utilization"]["jerk"][joint] < max(map(abs, jerk)) / 200.0 <= answer["peak_utilization"]["jerk"][joint] + 1e-9
    assert outside == []


def test_the_peak_utilization_table_marks_the_limits_the_joints_reach(browser_page):
    page, base, server, _ = browser_page
    _plan(page, base)
    answer = json.loads(_answer(server, _request(page)))
    kinds = [cell.split(" ")[0] for cell in page.locator("#utilization thead th").all_inner_texts()[1:]]
    assert kinds == ["velocity", "acceleration", "torque"]
    rows = page.locator("#utilization tbody tr")
    assert rows.count() == len(answer["joint_names"]) == 6
    reached: dict[str, list[str]] = {}
    for joint, name in enumerate(answer["joint_names"]):
        row = rows.nth(joint)
        assert row.locator("td").first.inner_text() == name
        values = [float(row.locator(f"td[data-kind={kind}]").get_attribute("data-value")) for kind in kinds]
        assert values == [answer["peak_utilization"][kind][joint] for kind in kinds]
        marked = [kind for kind in kinds if "binding" in (row.locator(f"td[data-kind={kind}]").get_attribute("class") or "")]
        assert marked == [kind for kind, value in zip(kinds, values) if value >= 0.995], (name, values)
        reached[name] = marked
    # the ur5 example reaches acceleration limits and wrist_1's velocity limit; its torques are far
    # from theirs, and wrist_3 reaches nothing (its largest, 0.49, is not marked)
    assert reached["wrist_1_joint"] == ["velocity", "acceleration"] and reached["wrist_3_joint"] == []
    caption = page.inner_text("#utilization-note")
    assert "0.5 %" in caption and "1.0000019" in caption and "dense resampling" in caption


def _download(page, button: str) -> bytes:
    with page.expect_download() as info:
        page.click(button)
    with open(info.value.path(), "rb") as handle:
        return handle.read()


def test_the_answer_downloads_as_json_csv_and_joint_trajectory(browser_page):
    """Each file equals what the API serves for the same request, sampled as shown (every dt
    and the final instant: ``exact_period`` false)."""
    page, base, server, _ = browser_page
    _plan(page, base)
    request = _request(page)
    downloaded, served_answer = json.loads(_download(page, "#download-json")), json.loads(_answer(server, request))
    assert downloaded.pop("solve_ms") > 0 and served_answer.pop("solve_ms") > 0  # the one field that varies
    assert downloaded == served_answer
    rows = [row for row in csv.reader(io.StringIO(_download(page, "#download-csv").decode())) if row]
    served = [row for row in csv.reader(io.StringIO(_answer(server, request, format="csv", exact_period=False).decode())) if row and not row[0].startswith("#")]
    assert rows[0] == served[0] and len(rows) == len(served) > 100
    assert [[float(v) for v in row] for row in rows[1:]] == [[float(v) for v in row] for row in served[1:]]
    trajectory = json.loads(_download(page, "#download-joint-trajectory"))
    assert trajectory == json.loads(_answer(server, request, format="joint_trajectory", exact_period=False))["joint_trajectory"]


def test_the_page_downloads_as_one_html_file_that_opens_offline(browser_page, tmp_path):
    page, base, _, _ = browser_page
    _plan(page, base)
    shown = {plot: page.evaluate(f"() => document.getElementById('{plot}').data.length") for plot in ("phase-plane", "arm", "joints")}
    saved = tmp_path / "page.html"
    saved.write_bytes(_download(page, "#download-html"))
    refused: list[str] = []
    copy = offline_page(page.context.browser, saved.as_uri(), refused, viewport={"width": 1400, "height": 1300})
    try:
        copy.goto(saved.as_uri())
        for plot, traces in shown.items():
            copy.wait_for_function(f"() => document.getElementById('{plot}').data && document.getElementById('{plot}').querySelector('.main-svg')", timeout=30_000)
            assert copy.evaluate(f"() => document.getElementById('{plot}').data.length") == traces
        assert copy.inner_text("#duration") == page.inner_text("#duration") and copy.title().endswith(page.inner_text("#duration"))
        assert copy.locator("#utilization tbody tr").count() == 6 and copy.locator("#durations tbody tr").count() == 3
        assert refused == []  # nothing from elsewhere
    finally:
        copy.close()


def test_a_running_job_can_be_cancelled(browser_page):
    page, base, server, _ = browser_page
    page.goto("about:blank")
    page.goto(base + "/")
    page.wait_for_selector("body[data-ready=true]")
    page.select_option("#preset", SEARCH)
    assert not page.is_visible("#cancel")
    page.click("#plan")
    page.wait_for_selector("#cancel:not([hidden])", timeout=30_000)
    page.wait_for_function("() => /job running/.test(document.getElementById('status').textContent)", timeout=30_000)
    page.click("#cancel")
    page.wait_for_function("() => /^Cancelled/.test(document.getElementById('status').textContent)", timeout=30_000)
    assert "nothing was planned" in page.inner_text("#status")
    assert not page.is_visible("#error") and not page.is_visible("#cancel") and page.is_enabled("#plan")
    status, _, raw = server.request("GET", f"/v1/jobs/{page.get_attribute('body', 'data-job')}")
    assert status == 200 and json.loads(raw)["status"] == "cancelled"


def test_the_arm_is_drawn_whole(browser_page):
    """The ur5's 3-D scene (the arm at 12 instants, its axes and box) lies within its viewport."""
    page, base, _, _ = browser_page
    _plan(page, base)
    page.wait_for_timeout(1000)  # the WebGL scene's first frames
    scene = page.locator("#arm #scene").bounding_box()
    box = {**scene, "y": scene["y"] + page.evaluate("() => scrollY")}
    assert drawn_to_the_edge(page.screenshot(full_page=True), box) == {"top": 0, "bottom": 0, "left": 0, "right": 0}


def _overlap(a: dict, b: dict) -> bool:
    return a["x"] < b["x"] + b["width"] and b["x"] < a["x"] + a["width"] and a["y"] < b["y"] + b["height"] and b["y"] < a["y"] + a["height"]


@pytest.mark.parametrize("width", [390, 1400])
def test_the_page_fits_its_screen(browser_page, width):
    """No horizontal overflow, the example list inside its card, the phase plane's `s` title
    clear of its legend and of its tick labels."""
    page, base, _, outside = browser_page
    narrow = offline_page(page.context.browser, base, outside, viewport={"width": width, "height": 844})
    try:
        _plan(narrow, base)
        assert narrow.evaluate("() => document.documentElement.scrollWidth") <= width
        select, card = narrow.locator("#preset").bounding_box(), narrow.locator("#request-panel").bounding_box()
        assert card["x"] <= select["x"] and select["x"] + select["width"] <= card["x"] + card["width"]
        title, legend = narrow.locator("#phase-plane .g-xtitle").bounding_box(), narrow.locator("#phase-plane .legend").bounding_box()
        assert title and legend and not _overlap(title, legend)
        ticks = narrow.locator("#phase-plane .xtick text")
        assert ticks.count() >= 3 and not any(_overlap(title, ticks.nth(k).bounding_box()) for k in range(ticks.count()))
        assert outside == []
    finally:
        narrow.close()


def test_the_url_keeps_the_request_and_reopens_it(browser_page):
    page, base, _, outside = browser_page
    page.goto("about:blank")
    page.goto(base + "/")
    page.wait_for_selector("body[data-ready=true]")
    page.uncheck("#methods input[value=toppra]")
    page.fill("#dt", "0.02")
    page.click("#plan")
    page.wait_for_selector("body[data-planned=true]", timeout=60_000)
    url = page.url
    assert "#r=" in url and len(url) < 2000
    # the fragment is raw deflate in base64url, read here independently of the page
    encoded = url.split("#r=")[1]
    form = json.loads(zlib.decompress(base64.urlsafe_b64decode(encoded + "=" * (-len(encoded) % 4)), wbits=-15))
    assert form == {"v": 1, "robot": "ur5", "path": json.loads(page.input_value("#path")), "methods": ["phase_plane", "quintic"],
                    "constraints": ["velocity", "acceleration", "torque"], "dt": 0.02}
    shown = page.get_attribute("#duration", "data-duration")
    reopened = offline_page(page.context.browser, base, outside, viewport={"width": 1400, "height": 1300})
    try:
        _plan(reopened, base, "#r=" + encoded)
        assert reopened.get_attribute("#duration", "data-duration") == shown
        assert reopened.input_value("#dt") == "0.02"
        assert reopened.locator("#methods input:checked").evaluate_all("(boxes) => boxes.map((b) => b.value)") == ["phase_plane", "quintic"]
        assert reopened.locator("#durations tbody tr").count() == 2
    finally:
        reopened.close()
    assert outside == []


@pytest.mark.parametrize(("fragment", "says"), [
    ("#r=" + "A" * 20_000, "more than the 16384"),  # too long to be read at all
    ("#r=" + _deflated(b" " * 1_000_000), "more than 262144 characters"),  # 1 MB that deflates into 1 kB
    ("#r=not-deflate", "cannot be read"),
    ("#r=" + _deflated(b'{"v": 1, "robot": "ur5"}'), "lacks robot, path"),
    ("#plan", "not a request of this page"),
])
def test_a_bad_or_oversized_url_request_is_refused_with_a_reason(browser_page, fragment, says):
    page, base, _, _ = browser_page
    page.goto("about:blank")
    page.goto(base + "/" + fragment)
    page.wait_for_selector("body[data-ready=true]", timeout=30_000)
    assert page.is_visible("#error") and says in page.inner_text("#error")
    assert page.input_value("#robot") == "ur5"  # the page starts as without a link
