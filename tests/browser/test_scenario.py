"""finsd's page with a running scenario (issue 26 points 10 and 11): the Scenario panel
lists the tags in their own types, its buttons pause and advance the scenario, and the
page's panels never overlap at 1280, 900 and 420 px wide. Each test starts its own finsd
with a small scenario written here; screenshots go to the build's artifacts."""
import json
import math
import urllib.error
import urllib.request
from pathlib import Path

from selenium.webdriver.common.by import By

from conftest import open_page, screenshot, severe_console_errors, wait_for

SCENARIO = """
[scenario]
seed = 3
tick_ms = 100
time = "virtual"

[[scenario.signal]]
address = "D100"
type = "float"
kind = "constant"
value = 9.81

[[scenario.signal]]
address = "D110"
type = "int16"
kind = "constant"
value = -42

[[scenario.signal]]
address = "D120"
type = "uint32"
kind = "constant"
value = 100000

[[scenario.link]]
address = "CIO2.00"
type = "bool"
expr = "D110 < 0"

[[scenario.event]]
name = "spike"
at_s = 1000
duration_s = 5
fault = "set"
address = "D110"
value = 7
"""


def start(finsd_factory, tmp_path, *args, token=None):
    path = Path(tmp_path) / "scenario.toml"
    path.write_text(SCENARIO)
    return finsd_factory("--scenario", str(path), *args, token=token)


def get(finsd, route):
    with urllib.request.urlopen(finsd.url + route.lstrip("/"), timeout=10) as r:
        return json.loads(r.read())


def status(finsd):
    return get(finsd, "/api/status")["scenario"]


def tag_row(page, address):
    return page.find_element(By.CSS_SELECTOR, f"#scenario-tags tr[data-address='{address}']")


def row_cells(page, address):
    return [td.text for td in tag_row(page, address).find_elements(By.TAG_NAME, "td")]


def test_the_scenario_api_lists_tags_with_types_and_events(finsd_factory, tmp_path):
    finsd = start(finsd_factory, tmp_path)
    j = get(finsd, "/api/scenario")
    assert [(t["address"], t["type"], t["words"]) for t in j["tags"]] == [
        ("D100", "float", 2), ("D110", "int16", 1), ("D120", "uint32", 2), ("CIO2.00", "bool", 0)]
    assert j["tags_total"] == 4
    assert j["events"][0]["name"] == "spike"
    assert j["events"][0]["fault"] == "set"
    assert j["events"][0]["next_start_s"] == 1000
    assert j["events"][0]["active"] is False
    assert j["status"]["time"] == "virtual"
    # A finsd without a scenario answers 404 with the reason.
    plain = finsd_factory()
    try:
        urllib.request.urlopen(plain.url + "api/scenario", timeout=10)
        raise AssertionError("GET /api/scenario without a scenario answered 2xx")
    except urllib.error.HTTPError as e:
        assert e.code == 404
        assert "runs no scenario" in json.loads(e.read())["error"]


def test_the_scenario_panel_shows_tags_in_their_types_and_its_buttons_work(finsd_factory, tmp_path, page):
    finsd = start(finsd_factory, tmp_path, "--http-control")
    open_page(page, finsd.url)
    panel = wait_for(lambda: page.find_element(By.ID, "scenario-panel").is_displayed()
                     and page.find_element(By.ID, "scenario-panel"), 10, "the Scenario panel")
    wait_for(lambda: len(page.find_elements(By.CSS_SELECTOR, "#scenario-tags tr[data-address]")) == 4, 10,
             "the four tags")
    assert row_cells(page, "D100")[:2] == ["D100", "float"]
    assert row_cells(page, "D110")[:2] == ["D110", "int16"]
    assert row_cells(page, "D120")[:2] == ["D120", "uint32"]
    assert row_cells(page, "CIO2.00")[:2] == ["CIO2.00", "bool"]
    # Virtual time: nothing ran yet. Advance 10 s with the panel's button.
    assert status(finsd)["time_s"] == 0
    box = page.find_element(By.ID, "scenario-seconds")
    box.clear()
    box.send_keys("10")
    page.find_element(By.CSS_SELECTOR, "[data-test=scenario-advance]").click()
    wait_for(lambda: status(finsd)["time_s"] == 10, 10, "the scenario 10 s on")
    # Each value in its own type: the float is a float near 9.81 (not 9.8e-45 of a word).
    def near(text, expected):
        try:
            return math.isclose(float(text), expected, rel_tol=1e-6)
        except ValueError:
            return False

    wait_for(lambda: near(row_cells(page, "D100")[2], 9.81), 10, "D100 as a float near 9.81")
    wait_for(lambda: row_cells(page, "D110")[2] == "-42", 10, "D110 as int16")
    wait_for(lambda: row_cells(page, "D120")[2] == "100000", 10, "D120 as uint32")
    wait_for(lambda: row_cells(page, "CIO2.00")[2].startswith("ON"), 10, "CIO2.00 as a bit")
    # The event with its state and next start; the status line shows the time.
    event = page.find_element(By.CSS_SELECTOR, "#scenario-events tr[data-test='scenario-event-spike']")
    assert "idle" in event.text and "16 min 40 s" in event.text, event.text  # 1000 s
    wait_for(lambda: "10 s" in page.find_element(By.CSS_SELECTOR, "[data-test=scenario-time]").text, 10,
             "the panel's time")
    # Pause, then resume: read back from the API.
    page.find_element(By.ID, "scenario-pause").click()
    wait_for(lambda: status(finsd)["paused"] is True, 10, "the scenario paused")
    wait_for(lambda: page.find_element(By.ID, "scenario-pause").text == "Resume", 10, "the Resume button")
    page.find_element(By.ID, "scenario-pause").click()
    wait_for(lambda: status(finsd)["paused"] is False, 10, "the scenario running again")
    # Trigger starts the event now: D110 becomes 7.
    event.find_element(By.CSS_SELECTOR, "[data-test=scenario-trigger]").click()
    wait_for(lambda: status(finsd)["events"][0]["active"] is True, 10, "the event active")
    wait_for(lambda: "active" in event.text, 10, "the event shown active")
    box.clear()
    box.send_keys("1")  # within the event's 5 s
    page.find_element(By.CSS_SELECTOR, "[data-test=scenario-advance]").click()
    wait_for(lambda: row_cells(page, "D110")[2] == "7", 10, "the spike's value")
    # The trend button adds the float tag to the trend, as a float.
    tag_row(page, "D100").find_element(By.CSS_SELECTOR, "[data-test=scenario-trend]").click()
    wait_for(lambda: "D100" in page.find_element(By.ID, "trend-tags").text, 10, "D100 in the trend")
    assert "float" in page.find_element(By.ID, "trend-tags").text
    # The grid's "Tag types" shows D100's two words as the tag's float; hover tells the tag.
    page.find_element(By.ID, "tag-types").click()
    cell = wait_for(lambda: page.find_element(By.CSS_SELECTOR, "#grid-rows .cell[data-word='100']"), 5, "D100's cell")
    wait_for(lambda: near(cell.text, 9.81), 10, "D100 as a float in the grid")
    assert "tag D100 (float)" in cell.get_attribute("title")
    screenshot(page, "scenario-panel")
    assert severe_console_errors(page) == []


def test_read_only_disables_the_scenario_buttons(finsd_factory, tmp_path, page):
    finsd = start(finsd_factory, tmp_path)
    open_page(page, finsd.url)
    wait_for(lambda: page.find_elements(By.CSS_SELECTOR, "#scenario-events [data-test=scenario-trigger]"), 10,
             "the events")
    for sel in ["#scenario-pause", "[data-test=scenario-advance]", "[data-test=scenario-trigger]"]:
        b = page.find_element(By.CSS_SELECTOR, sel)
        assert not b.is_enabled(), sel
        assert "Read only" in b.get_attribute("title")
    # The tags and values are still shown.
    wait_for(lambda: len(page.find_elements(By.CSS_SELECTOR, "#scenario-tags tr[data-address]")) == 4, 10, "tags")


PANELS_JS = """
const ids = ['top', 'side', 'grid', 'lower', 'right'];
const out = {};
for (const id of ids) {
  const e = document.getElementById(id);
  const r = e.getBoundingClientRect();
  out[id] = {x: r.left + scrollX, y: r.top + scrollY, w: r.width, h: r.height,
             shown: getComputedStyle(e).display !== 'none' && r.width > 0 && r.height > 0};
}
const cell = document.querySelector('#grid-rows .cell[data-word]');
const cr = cell ? cell.getBoundingClientRect() : null;
out.cell = cr ? {w: cr.width, h: cr.height} : null;
out.viewport = innerWidth;
out.scrollWidth = Math.max(document.documentElement.scrollWidth, document.body.scrollWidth);
// No panel scrolls sideways: its content fits its width.
out.wide = [...document.querySelectorAll('#side, #right, .panel, #lower .tab-body, .toolbar')]
  .filter((e) => e.offsetParent !== null && e.scrollWidth > e.clientWidth + 1)
  .map((e) => `${e.id || e.className} ${e.scrollWidth}>${e.clientWidth}`);
return out;
"""


def overlap(a, b):
    return (min(a["x"] + a["w"], b["x"] + b["w"]) - max(a["x"], b["x"]) > 0.5 and
            min(a["y"] + a["h"], b["y"] + b["h"]) - max(a["y"], b["y"]) > 0.5)


def set_size(page, width, height):
    page.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                         {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})


def test_the_page_at_every_size(finsd_factory, tmp_path, page):
    finsd = start(finsd_factory, tmp_path, "--http-control")
    open_page(page, finsd.url)
    wait_for(lambda: len(page.find_elements(By.CSS_SELECTOR, "#scenario-tags tr[data-address]")) == 4, 10, "tags")
    req = urllib.request.Request(finsd.url + "api/control", method="POST",
                                 data=b'{"cmd":"scenario","action":"advance","seconds":10}',
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=10) as r:
        assert r.status == 200
    # The header names the FINS node address as such.
    address = page.find_element(By.ID, "unit-address").text
    assert address.startswith("node 0."), address
    assert "FINS" not in address
    try:
        for width, height in [(1280, 800), (900, 800), (420, 800)]:
            set_size(page, width, height)
            page.execute_script("scrollTo(0, 0)")
            # The trend has no series: it folds to its hint line and the grid gets the room.
            wait_for(lambda: page.execute_script("return innerWidth") == width, 5, f"{width} px")
            r = wait_for(lambda: (lambda x: x if x["cell"] and x["lower"]["h"] < 90 else None)(
                page.execute_script(PANELS_JS)), 5, f"the layout at {width} px")
            assert not page.find_element(By.ID, "trend-canvas").is_displayed()
            for id_ in ["top", "side", "grid", "lower", "right"]:
                assert r[id_]["shown"], (width, id_, r)
            names = ["top", "side", "grid", "lower", "right"]
            for i, a in enumerate(names):
                for b in names[i + 1:]:
                    assert not overlap(r[a], r[b]), (width, a, b, r[a], r[b])
            # The grid is there and readable, and nothing runs off the side of the page.
            assert r["grid"]["w"] >= min(width - 20, 400) * 0.9 or width > 900, (width, r["grid"])
            assert r["grid"]["h"] >= 150, (width, r["grid"])
            assert r["cell"]["w"] >= 48, (width, r["cell"])  # 5 words a row when narrow
            assert r["scrollWidth"] <= width + 1, (width, r["scrollWidth"])
            assert r["wide"] == [], (width, r["wide"])
            if width <= 900:  # stacked: the side, the grid, the lower tabs, the right column
                assert r["side"]["y"] < r["grid"]["y"] < r["lower"]["y"] < r["right"]["y"], r
            screenshot(page, f"page-{width}x{height}")
            if width <= 900:  # the panels below the grid
                page.execute_script("document.getElementById('scenario-panel').scrollIntoView()")
                screenshot(page, f"page-{width}x{height}-scenario")
                page.execute_script("scrollTo(0, 0)")
        # A trend with a series opens again.
        set_size(page, 1280, 800)
        tag_row(page, "D110").find_element(By.CSS_SELECTOR, "[data-test=scenario-trend]").click()
        wait_for(lambda: page.execute_script(PANELS_JS)["lower"]["h"] > 150, 5, "the trend opened")
        assert page.find_element(By.ID, "trend-canvas").is_displayed()
        screenshot(page, "page-1280x800-trend")
    finally:
        set_size(page, 1440, 900)
    assert severe_console_errors(page) == []


def test_the_scenario_buttons_send_the_token(finsd_factory, tmp_path, page):
    from selenium.webdriver.common.keys import Keys
    finsd = start(finsd_factory, tmp_path, "--http-control", token="scenario-token")
    open_page(page, finsd.url)
    wait_for(lambda: page.find_element(By.ID, "scenario-pause").is_displayed(), 10, "the Pause button")
    page.execute_script("sessionStorage.removeItem('finsd-token')")
    page.find_element(By.ID, "scenario-pause").click()
    wait_for(lambda: page.execute_script("return document.getElementById('token-dialog').open"), 5,
             "the token dialog")
    page.find_element(By.ID, "token-input").send_keys("scenario-token", Keys.ENTER)
    wait_for(lambda: status(finsd)["paused"] is True, 10, "the scenario paused with the token")
    # Without the token nothing reaches the scenario (a POST of another client).
    req = urllib.request.Request(finsd.url + "api/control", method="POST",
                                 data=b'{"cmd":"scenario","action":"resume"}',
                                 headers={"Content-Type": "application/json"})
    try:
        urllib.request.urlopen(req, timeout=10)
        raise AssertionError("a POST without the token was taken")
    except urllib.error.HTTPError as e:
        assert e.code == 403
    assert status(finsd)["paused"] is True
