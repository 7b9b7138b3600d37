"""finsd's page in the documented remote set-up (issue 25, docs/web.md "Remote set-up"):
the token prompt of a finsd started with --http-token-file, the read-only page, the badge
after finsd restarts with other options, and a page of another origin that tries to
change the PLC through the user's browser. Each test starts its own finsd; screenshots go
to the build's artifacts."""
import http.server
import json
import socket
import threading
import urllib.request

from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys

from conftest import cell_text, free_port, open_page, screenshot, wait_for

TOKEN = "k9-remote-token"


def click_cell(driver, word):
    cell = wait_for(lambda: driver.find_element(By.CSS_SELECTOR, f"#grid-rows .cell[data-word='{word}']"),
                    5, f"the cell of word {word}")
    cell.click()
    return cell


def start_edit(driver, word, text):
    click_cell(driver, word)
    driver.switch_to.active_element.send_keys(Keys.ENTER)
    box = wait_for(lambda: driver.find_element(By.CSS_SELECTOR, "#grid-rows input.edit"), 5, "the editor")
    box.send_keys(Keys.CONTROL, "a")
    box.send_keys(text, Keys.ENTER)


def token_dialog(driver):
    return wait_for(lambda: driver.execute_script(
        "return document.getElementById('token-dialog').open"), 5, "the token dialog")


def give_token(driver, token):
    token_dialog(driver)
    box = driver.find_element(By.ID, "token-input")
    box.clear()
    box.send_keys(token, Keys.ENTER)


def test_token_prompt_then_writes_with_the_token(finsd_factory, page):
    finsd = finsd_factory("--http-control", token=TOKEN)
    with urllib.request.urlopen(finsd.url + "api/plcs", timeout=10) as r:
        assert json.load(r)["token_required"] is True
    open_page(page, finsd.url)
    assert page.find_element(By.ID, "control-badge").text == "control"
    wait_for(lambda: cell_text(page, 10) == "0", 5, "D10 shown")
    # The first write asks for the token; a wrong one is refused and asked for again.
    start_edit(page, 10, "4321")
    token_dialog(page)
    assert not page.find_element(By.ID, "token-refused").is_displayed()
    screenshot(page, "page-token-prompt")
    give_token(page, "not-the-token")
    wait_for(lambda: page.find_element(By.ID, "token-refused").is_displayed(), 5,
             "the dialog to say the token was refused")
    screenshot(page, "page-token-refused")
    assert finsd.read("D10") == [0]
    give_token(page, TOKEN)
    wait_for(lambda: finsd.read("D10") == [4321], 5, "D10 = 4321 over FINS")
    assert page.execute_script("return sessionStorage.getItem('finsd-token')") == TOKEN
    # Kept for the tab: the next write and a control command go without asking.
    start_edit(page, 11, "99")
    wait_for(lambda: finsd.read("D11") == [99], 5, "D11 = 99 over FINS")
    page.find_element(By.CSS_SELECTOR, "[data-test='mode-program']").click()
    wait_for(lambda: finsd.fins("status")[1]["mode"] == "program", 5, "PROGRAM over FINS")
    assert not page.execute_script("return document.getElementById('token-dialog').open")
    # Cancelled: nothing is sent, and the page says why.
    page.execute_script("sessionStorage.removeItem('finsd-token')")
    page.find_element(By.CSS_SELECTOR, "[data-test='mode-run']").click()
    token_dialog(page)
    page.find_element(By.ID, "token-cancel").click()
    assert "No token" in wait_for(lambda: page.find_element(By.ID, "toast").text, 5, "the message")
    assert finsd.fins("status")[1]["mode"] == "program"
    assert page.find_element(By.ID, "control-badge").text == "control"


def test_read_only_page_shows_its_controls_disabled(finsd_factory, page):
    finsd = finsd_factory()  # no --http-control
    open_page(page, finsd.url)
    wait_for(lambda: page.find_element(By.ID, "control-badge").text == "read only", 5, "the badge")
    wait_for(lambda: page.find_elements(By.CSS_SELECTOR, "[data-test='switch-battery_low']"), 5,
             "the switches")
    # Read in one script: the switches re-render on every status message, and an element
    # found first and read after would be stale by then.
    controls = page.execute_script(
        "return Array.from(document.querySelectorAll('#mode-buttons button, #fal-form input, "
        "#fal-form select, #fal-form button, #switches input')).map(e => ({disabled: "
        "e.hasAttribute('disabled'), title: e.title || '', test: e.dataset.test || '', "
        "html: e.outerHTML}));")
    assert len(controls) >= 3 + 5 + 4
    for c in controls:
        assert c["disabled"], c["html"]
        assert "--http-control" in c["title"] or c["test"] == "switch-dip_write", c["html"]
    # A click on a disabled button sends nothing.
    page.execute_script("document.querySelector(\"[data-test='mode-program']\").click()")
    assert finsd.fins("status")[1]["mode"] == "run"
    screenshot(page, "page-read-only")


def test_reconnect_after_a_restart_reads_the_control_setting_again(finsd_factory, page):
    port = free_port()
    first = finsd_factory("--http-control", http=f"127.0.0.1:{port}")
    open_page(page, first.url)
    wait_for(lambda: page.find_element(By.ID, "control-badge").text == "control", 5, "control")
    assert page.find_element(By.CSS_SELECTOR, "[data-test='mode-program']").is_enabled()
    first.stop()
    wait_for(lambda: page.find_element(By.ID, "link").get_attribute("data-state") != "live", 10,
             "the page to see finsd gone")
    # Back on the same port, read only this time.
    second = finsd_factory(http=f"127.0.0.1:{port}")
    assert second.http_port == port
    # The WebSocket retries after 1, 2, 4 ... s (at most 10 s).
    wait_for(lambda: page.find_element(By.ID, "link").get_attribute("data-state") == "live", 30,
             "the WebSocket back")
    wait_for(lambda: page.find_element(By.ID, "control-badge").text == "read only", 10,
             "the badge to say read only")
    wait_for(lambda: not page.find_element(By.CSS_SELECTOR, "[data-test='mode-program']").is_enabled(),
             5, "the mode buttons disabled")
    screenshot(page, "page-reconnected-read-only")


# ---- a page of another origin ----------------------------------------------------------

ATTACK = """<!doctype html>
<html><head><meta charset="utf-8"><title>another origin</title></head><body>
<h1>another origin</h1>
<iframe id="framed" src="{finsd}" width="600" height="300"></iframe>
<iframe name="sink" id="sink" width="300" height="100"></iframe>
<form id="form" method="POST" action="{finsd}api/write" enctype="text/plain" target="sink">
<input type="hidden" name='{{"address":"D500","values":[666],"x":"' value='"}}'>
</form>
<script>
const results = {{}};
window.attack = results;
const note = (k, v) => {{ results[k] = v; }};
const target = '{finsd}';
const write = JSON.stringify({{address: 'D500', values: [666]}});
const mode = JSON.stringify({{cmd: 'mode', mode: 'program'}});
// A JSON POST (the browser asks OPTIONS first) ...
fetch(target + 'api/write', {{method: 'POST', headers: {{'Content-Type': 'application/json'}}, body: write}})
  .then((r) => note('json_write', 'status ' + r.status), (e) => note('json_write', 'failed'));
fetch(target + 'api/control', {{method: 'POST', headers: {{'Content-Type': 'application/json'}}, body: mode}})
  .then((r) => note('json_control', 'status ' + r.status), (e) => note('json_control', 'failed'));
// ... and "simple" POSTs the browser sends without asking: text/plain bodies of JSON.
fetch(target + 'api/write', {{method: 'POST', mode: 'no-cors', headers: {{'Content-Type': 'text/plain'}}, body: write}})
  .then(() => note('plain_write', 'sent'), () => note('plain_write', 'failed'));
fetch(target + 'api/control', {{method: 'POST', mode: 'no-cors', body: mode}})
  .then(() => note('plain_control', 'sent'), () => note('plain_control', 'failed'));
document.getElementById('sink').addEventListener('load', () => note('form', 'loaded'));
document.getElementById('form').submit();
const ws = new WebSocket(target.replace('http', 'ws') + 'ws');
ws.onopen = () => {{
  note('ws', 'open');
  ws.send(JSON.stringify({{op: 'subscribe', id: 'st', topic: 'status'}}));
}};
ws.onclose = () => {{ if (!results.ws) note('ws', 'refused'); }};
</script>
</body></html>
"""


class _Origin(http.server.BaseHTTPRequestHandler):
    body = b""

    def do_GET(self):
        self.send_response(200)
        self.send_header("Content-Type", "text/html; charset=utf-8")
        self.send_header("Content-Length", str(len(self.body)))
        self.end_headers()
        self.wfile.write(self.body)

    def log_message(self, *args):
        pass


def serve_origin(host, html):
    handler = type("Origin", (_Origin,), {"body": html.encode()})
    server = http.server.ThreadingHTTPServer((host, 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def loopback_alias():
    """127.0.0.2 when it can be bound (Linux: all of 127/8 is loopback), else 127.0.0.1."""
    try:
        with socket.socket() as s:
            s.bind(("127.0.0.2", 0))
        return "127.0.0.2"
    except OSError:
        return "127.0.0.1"


def test_a_page_of_another_origin_changes_nothing(finsd_factory, page):
    finsd = finsd_factory("--http-control")
    # What finsd's own page gets: no framing by anyone (CSP frame-ancestors, X-Frame-Options).
    with urllib.request.urlopen(finsd.url, timeout=10) as r:
        assert "frame-ancestors 'none'" in r.headers["Content-Security-Policy"]
        assert r.headers["X-Frame-Options"] == "DENY"
    origin = serve_origin(loopback_alias(), ATTACK.format(finsd=finsd.url))
    try:
        url = f"http://{origin.server_address[0]}:{origin.server_address[1]}/"
        page.get(url)
        keys = {"json_write", "json_control", "plain_write", "plain_control", "form", "ws"}
        results = wait_for(lambda: (lambda r: r if r and keys <= set(r) else None)(
            page.execute_script("return window.attack")), 15, "every attempt to finish")
        assert results["ws"] == "refused", results
        assert results["json_write"] == "failed" and results["json_control"] == "failed", results
        # The framed page: blocked, so finsd's page never ran inside it.
        frame = page.find_element(By.ID, "framed")
        page.switch_to.frame(frame)
        try:
            assert page.find_elements(By.ID, "grid") == []
            assert page.execute_script("return document.body && document.body.dataset.ready") != "true"
        finally:
            page.switch_to.default_content()
        screenshot(page, "page-another-origin")
        # Every request above has had its answer (or its refusal): what it did is done.
        assert finsd.read("D500") == [0]
        assert finsd.fins("status")[1]["mode"] == "run"
    finally:
        origin.shutdown()
        origin.server_close()
