"""finsd's page in a real browser (issue 16 "Tested in a real browser"): it loads, shows
what FINS writes, writes what is edited, and its buttons and switches change what FINS
answers. Each test starts its own finsd; screenshots go to the build's artifacts."""
import json
import re
import socket
import struct
import time
import urllib.request
from pathlib import Path

from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys

from conftest import (cell_text, click_css, go_to, open_page, screenshot, severe_console_errors,
                      wait_for, _chrome)


def click_cell(driver, word):
    cell = wait_for(lambda: driver.find_element(By.CSS_SELECTOR, f"#grid-rows .cell[data-word='{word}']"),
                    5, f"the cell of word {word}")
    cell.click()
    return cell


def edit_cell(driver, word, text):
    click_cell(driver, word)
    driver.switch_to.active_element.send_keys(Keys.ENTER)
    box = wait_for(lambda: driver.find_element(By.CSS_SELECTOR, "#grid-rows input.edit"), 5, "the editor")
    box.send_keys(Keys.CONTROL, "a")
    box.send_keys(text, Keys.ENTER)


def test_page_loads(finsd_factory, page):
    finsd = finsd_factory()
    with urllib.request.urlopen(finsd.url, timeout=10) as r:
        assert r.status == 200
        assert "default-src 'self'" in r.headers["Content-Security-Policy"]
        assert r.headers["Content-Type"].startswith("text/html")
    open_page(page, finsd.url)
    # It opens on the DM area from D0, with the CPU Unit panel filled in.
    assert page.find_element(By.CSS_SELECTOR, "#area-list button.current").get_attribute("data-prefix") == "D"
    first = page.find_element(By.CSS_SELECTOR, "#grid-rows .row .addr").text
    assert first == "D0"
    wait_for(lambda: page.find_element(By.ID, "cpu-model").text.startswith("CJ2H"), 5, "the model")
    wait_for(lambda: cell_text(page, 0) == "0", 5, "D0's value")
    assert page.find_element(By.ID, "mode-badge").text == "RUN"
    # The clock ticks (the CPU Unit's, as 07 01 reads it) and the cycle time is shown.
    clock = wait_for(lambda: re.fullmatch(r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d",
                                          page.find_element(By.ID, "cpu-clock").text), 5, "the clock")
    assert clock.group(0)[:10] == finsd.fins("clock")[1]["time"][:10]  # unless run at midnight
    assert "ms" in page.find_element(By.ID, "cpu-cycle").text
    # The areas are the model's: a CJ2H has H0-H511 (its profile), 25 EM banks.
    h = page.find_element(By.CSS_SELECTOR, "#area-list button[data-prefix='H']")
    assert h.get_attribute("title") == "H0 - H511"
    assert len(page.find_elements(By.CSS_SELECTOR, "#bank-list button")) == 25
    assert page.find_element(By.ID, "control-badge").text == "read only"
    # The script and stylesheet came from finsd itself (CSP) and nothing failed.
    assert severe_console_errors(page) == []
    screenshot(page, "page-light")


def test_page_dark_theme(finsd_factory):
    finsd = finsd_factory("--http-control")
    driver = _chrome(dark=True)
    try:
        finsd.fins("write", "D0", 1234, 0x4142, 7, 99)
        open_page(driver, finsd.url)
        wait_for(lambda: cell_text(driver, 0) == "1234", 5, "D0 = 1234")
        background = driver.execute_script("return getComputedStyle(document.body).backgroundColor")
        # Dark: every channel of the page's background is low.
        channels = [int(x) for x in background[background.index("(") + 1:background.index(")")].split(",")[:3]]
        assert max(channels) < 60, background
        screenshot(driver, "page-dark")
    finally:
        driver.quit()


def test_value_written_over_fins_appears_on_the_page(finsd_factory, page):
    finsd = finsd_factory()
    open_page(page, finsd.url)
    wait_for(lambda: cell_text(page, 3) == "0", 5, "D3 shown")
    finsd.fins("write", "D3", 12345)
    # Bounded wait, no timing asserted: how fast (issue 16: within 1 s) is measured by
    # bench/web_page.py and written in docs/benchmarks.md.
    wait_for(lambda: cell_text(page, 3) == "12345", 10, "D3 = 12345 on the page")
    # Far down the area too: going there subscribes those rows.
    finsd.fins("write", "D32000", 777)
    go_to(page, "D32000")
    wait_for(lambda: cell_text(page, 32000) == "777", 5, "D32000 = 777 on the page")


def test_connections_show_the_udp_peers_and_tcp_nodes(finsd_factory, page):
    finsd = finsd_factory()
    with urllib.request.urlopen(finsd.url + "api/plcs", timeout=10) as r:
        plc = json.load(r)["plcs"][0]
    finsd.fins("read", "D0")  # a FINS/UDP peer
    # A FINS/TCP client that asks for client node 42 (NODE ADDRESS DATA SEND, command 0).
    tcp = socket.create_connection(("127.0.0.1", plc["tcp_port"]), timeout=10)
    try:
        tcp.sendall(b"FINS" + struct.pack(">IIII", 12, 0, 0, 42))
        answer = b""
        while len(answer) < 24:
            chunk = tcp.recv(24 - len(answer))
            assert chunk, "finsd closed the FINS/TCP connection"
            answer += chunk
        assert struct.unpack(">IIIII", answer[4:24])[1:4] == (1, 0, 42)  # command 1, node 42
        open_page(page, finsd.url)
        page.find_element(By.CSS_SELECTOR, "button[data-tab='connections']").click()

        def rows(table):
            return [[td.text for td in tr.find_elements(By.TAG_NAME, "td")]
                    for tr in page.find_elements(By.CSS_SELECTOR, f"#{table} tbody tr")]
        tcp_rows = wait_for(lambda: [r for r in rows("tcp-table") if "42" in r], 10,
                            "the FINS/TCP client with node 42")
        assert "127.0.0.1" in tcp_rows[0] and "established" in tcp_rows[0]
        udp_rows = wait_for(lambda: [r for r in rows("udp-table") if "127.0.0.1" in r], 10,
                            "the FINS/UDP peer")
        assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", udp_rows[0][-1]), udp_rows
        assert page.find_element(By.ID, "conn-count").text == "2"
        screenshot(page, "page-connections")
    finally:
        tcp.close()


def test_typed_views_show_the_words(finsd_factory, page):
    finsd = finsd_factory()
    finsd.fins("write", "D100", "--as", "float", 21.5)
    finsd.fins("write", "D102", 0x1234, 0x4142)
    open_page(page, finsd.url + "#addr=D100&as=float")
    wait_for(lambda: cell_text(page, 100) == "21.5", 5, "D100 as float")
    for view, word, text in [("hex", 102, "1234"), ("bcd", 102, "1234"), ("ascii", 103, "AB"),
                             ("int32", 100, str(0x41AC0000))]:
        page.find_element(By.CSS_SELECTOR, f"#views button[data-view='{view}']").click()
        wait_for(lambda: cell_text(page, word) == text, 5, f"D{word} as {view} = {text}")
    page.find_element(By.CSS_SELECTOR, "#views button[data-view='bits']").click()
    bits = page.find_elements(By.CSS_SELECTOR, "#grid-rows .cell[data-word='103'] i.on")
    assert len(bits) == bin(0x4142).count("1")


def test_value_edited_on_the_page_is_read_back_over_fins(finsd_factory, page):
    finsd = finsd_factory("--http-control")
    open_page(page, finsd.url)
    wait_for(lambda: cell_text(page, 10) == "0", 5, "D10 shown")
    edit_cell(page, 10, "4242")
    wait_for(lambda: finsd.read("D10") == [4242], 5, "D10 = 4242 over FINS")
    wait_for(lambda: cell_text(page, 10) == "4242", 5, "D10 = 4242 on the page")
    # A typed edit: the server converts (the same code as `fins write --as float`).
    page.find_element(By.CSS_SELECTOR, "#views button[data-view='float']").click()
    edit_cell(page, 20, "-3.25")
    wait_for(lambda: finsd.read("D20", as_="float") == [-3.25], 5, "D20 = -3.25 over FINS")
    # The bits view: a click on bit 3 of D40 sets it.
    page.find_element(By.CSS_SELECTOR, "#views button[data-view='bits']").click()
    bit = wait_for(lambda: page.find_element(By.CSS_SELECTOR, "#grid-rows .cell[data-word='40'] i[data-bit='3']"),
                   5, "bit 3 of D40")
    bit.click()
    wait_for(lambda: finsd.read("D40") == [8], 5, "D40 = 8 over FINS")
    wait_for(lambda: "on" in bit.get_attribute("class"), 5, "the bit lit")
    # A value the view cannot hold is refused with the server's message; nothing written.
    page.find_element(By.CSS_SELECTOR, "#views button[data-view='uint16']").click()
    edit_cell(page, 30, "70000")
    toast = wait_for(lambda: page.find_element(By.ID, "toast").text, 5, "an error message")
    assert "70000" in toast
    assert finsd.read("D30") == [0]
    screenshot(page, "page-edited")


def test_read_only_page_writes_nothing(finsd_factory, page):
    finsd = finsd_factory()  # no --http-control
    open_page(page, finsd.url)
    wait_for(lambda: cell_text(page, 10) == "0", 5, "D10 shown")
    click_cell(page, 10)
    page.switch_to.active_element.send_keys("5", Keys.ENTER)
    assert "Read only" in wait_for(lambda: page.find_element(By.ID, "toast").text, 5, "the read-only message")
    # The mode buttons are disabled (test_remote.py checks every control); a click on
    # one sends nothing.
    program = page.find_element(By.CSS_SELECTOR, "[data-test='mode-program']")
    assert not program.is_enabled()
    page.execute_script("arguments[0].click()", program)
    time.sleep(0.3)  # give a wrongly accepted request time to land before checking it did not
    assert finsd.read("D10") == [0]
    assert finsd.fins("status")[1]["mode"] == "run"


def test_mode_buttons_change_what_06_01_answers(finsd_factory, page):
    finsd = finsd_factory("--http-control")
    open_page(page, finsd.url)
    assert finsd.fins("status")[1]["mode"] == "run"
    for mode in ["program", "monitor", "run"]:
        page.find_element(By.CSS_SELECTOR, f"[data-test='mode-{mode}']").click()
        wait_for(lambda: finsd.fins("status")[1]["mode"] == mode, 5, f"06 01 to answer {mode}")
        wait_for(lambda: page.find_element(By.ID, "mode-badge").text == mode.upper(), 5,
                 f"the page to show {mode}")
    page.find_element(By.CSS_SELECTOR, "[data-test='mode-program']").click()
    wait_for(lambda: finsd.fins("status")[1]["mode"] == "program", 5, "PROGRAM")
    # In PROGRAM mode the CPU Unit is not running: 06 01 says so.
    assert finsd.fins("status")[1]["running"] is False
    screenshot(page, "page-program-mode")


def test_fault_switches_change_what_fins_answers(finsd_factory, page):
    finsd = finsd_factory("--http-control")
    open_page(page, finsd.url)
    assert finsd.fins("write", "D5", 1, check=False)[0] == 0
    # Network write protection: FINS writes are refused (end code 2102).
    click_css(page, "[data-test='switch-network_write_protection']", "the protection switch")
    wait_for(lambda: finsd.fins("write", "D5", 2, check=False)[0] == 4, 5, "FINS writes refused")
    code, out = finsd.fins("write", "D5", 2, check=False)
    assert "2102" in str(out)
    assert finsd.read("D5") == [1]
    # Battery error: 06 01 reports error 00F7 and a non-fatal error.
    click_css(page, "[data-test='switch-battery_low']", "the battery switch")
    wait_for(lambda: finsd.fins("status")[1]["error_code"] == "00F7", 5, "06 01 error code 00F7")
    assert "battery error" in finsd.fins("status")[1]["non_fatal"]
    wait_for(lambda: "00F7" in page.find_element(By.ID, "cpu-errors").text, 5, "the error on the page")
    screenshot(page, "page-faults")
    # And off again.
    click_css(page, "[data-test='switch-network_write_protection']", "the protection switch")
    wait_for(lambda: finsd.fins("write", "D5", 3, check=False)[0] == 0, 5, "FINS writes accepted")
    assert finsd.read("D5") == [3]


def test_fal_raised_on_the_page_reaches_fins(finsd_factory, page):
    finsd = finsd_factory("--http-control")
    open_page(page, finsd.url)
    page.find_element(By.ID, "fal-number").clear()
    page.find_element(By.ID, "fal-number").send_keys("7")
    page.find_element(By.ID, "fal-message").send_keys("LOW PRESSURE", Keys.ENTER)
    wait_for(lambda: finsd.fins("status")[1]["error_code"] == "4107", 5, "06 01 error code 4107 (FAL 7)")
    wait_for(lambda: "4107" in page.find_element(By.ID, "cpu-errors").text, 5, "FAL 7 on the page")
    page.find_element(By.ID, "clear-errors").click()
    wait_for(lambda: finsd.fins("status")[1]["error_code"] == "0000", 5, "errors cleared")


def test_scenario_panel_shows_the_running_scenario(finsd_factory, page):
    conveyor = str(Path(__file__).resolve().parents[2] / "examples" / "scenarios" / "conveyor.toml")
    finsd = finsd_factory("--http-control", "--scenario", conveyor)
    open_page(page, finsd.url)
    panel = wait_for(lambda: (lambda p: p if p.is_displayed() else None)(
        page.find_element(By.ID, "scenario-panel")), 10, "the Scenario panel")
    # The conveyor's virtual time stands until advanced; its events are listed by name.
    wait_for(lambda: "jam_alarm" in panel.text, 10, "the conveyor's events in the panel")
    finsd.ctl("scenario", "advance", "4")
    wait_for(lambda: re.search(r"time\s*4 s · 40 ticks", panel.text), 10, "4 s, 40 ticks in the panel")
    screenshot(page, "page-scenario")
