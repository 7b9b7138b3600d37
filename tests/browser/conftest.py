"""Fixtures of the browser tests: finsd processes with --http, the fins CLI, and one
headless Chromium driven by Debian's chromedriver (given by path, so Selenium never
looks for or downloads a driver). Everything runs on loopback; every wait is bounded.

Environment (set by ctest, see tests/CMakeLists.txt):
  FINS_BIN_DIR        the build's bin/ (finsd, fins)
  FINS_ARTIFACTS_DIR  where screenshots go (default <bin>/../artifacts/screenshots)
  FINS_FINSD          (opt-in) the command that runs finsd instead of <bin>/finsd, split as
                      a shell would: "/usr/lib/wine/wine64 .../finsd.exe" in the Windows
                      tree's windows_browser_page. That finsd gets more time to start, and
                      `finsd ctl` runs through the same command: finsd.exe's channel is
                      loopback TCP with a token file (docs/windows.md), which the host's
                      finsd cannot read; a program ending in .exe is given its --control
                      path as wine sees it (the Unix root is drive Z:).
"""
import json
import os
import re
import select
import shlex
import shutil
import signal
import subprocess
import tempfile
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("FINS_BIN_DIR", ROOT / "build-asan" / "bin"))
ARTIFACTS = Path(os.environ.get("FINS_ARTIFACTS_DIR", BIN.parent / "artifacts" / "screenshots"))
CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
FINSD = shlex.split(os.environ.get("FINS_FINSD", "")) or [str(BIN / "finsd")]
FOREIGN_FINSD = "FINS_FINSD" in os.environ and FINSD != [str(BIN / "finsd")]
# An ASan finsd on a busy 2-core machine; finsd.exe under wine starts slower still.
START_TIMEOUT = 60.0 if FOREIGN_FINSD else 20.0
# A Windows finsd under wine reads the host's paths on drive Z:.
FINSD_PATH_PREFIX = "Z:" if FINSD[-1].lower().endswith(".exe") else ""


def free_port(host="127.0.0.1"):
    """A TCP port free on `host` now (for a server that must come back on the same one)."""
    import socket
    with socket.socket() as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def _need(path):
    if not Path(path).exists():
        pytest.skip(f"{path} is not installed (Debian packages chromium, chromium-driver)")


class Finsd:
    """One finsd process: FINS on a free port, HTTP on a free port, a control socket."""

    def __init__(self, args, config=None, http="127.0.0.1:0", token=None):
        self.dir = Path(tempfile.mkdtemp(prefix="finsd-browser-"))
        self.control = FINSD_PATH_PREFIX + str(self.dir / "finsd.sock")
        cmd = FINSD + ["--port", "0", "--control", self.control, "--http", http] + list(args)
        if token is not None:  # POSTs need "Authorization: Bearer TOKEN"
            token_file = self.dir / "token"
            token_file.write_text(token + "\n")
            token_file.chmod(0o600)
            cmd += ["--http-token-file", str(token_file)]
        if config is not None:
            path = self.dir / "finsd.toml"
            path.write_text(config)
            cmd += ["--config", str(path)]
        self.stderr_path = self.dir / "stderr.txt"
        self.stderr = open(self.stderr_path, "w")
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=self.stderr)
        self.port = None
        self.http_port = None
        deadline = time.monotonic() + START_TIMEOUT
        # Raw reads: a buffered readline() would hide the second line from select().
        fd = self.proc.stdout.fileno()
        out = b""
        while self.port is None or self.http_port is None:
            left = deadline - time.monotonic()
            if left <= 0 or self.proc.poll() is not None:
                stderr = self.stderr_path.read_text()[-2000:]
                self.stop()
                if "does not serve HTTP yet" in stderr:
                    # Until the Boost.Asio move puts the HTTP server on finsd's io_context.
                    pytest.skip("this finsd build does not serve HTTP yet: " + stderr.strip())
                raise RuntimeError(f"finsd did not start: {' '.join(cmd)}\nstdout: {out!r}\n"
                                   f"stderr: {stderr}")
            ready, _, _ = select.select([fd], [], [], min(left, 0.5))
            if ready:
                out += os.read(fd, 4096)
            m = re.search(r"^listening (\d+)\r?$", out.decode(errors="replace"), re.M)
            if m:
                self.port = int(m.group(1))
            # finsd logs "finsd: HTTP on ADDRESS port N" (docs/web.md "Starting it").
            m = re.search(r"HTTP on \S+ port (\d+)", self.stderr_path.read_text(errors="replace"))
            if m:
                self.http_port = int(m.group(1))
        self.url = f"http://127.0.0.1:{self.http_port}/"

    def unit_port(self, name):
        """The FINS port of a plant CPU Unit's first unit (from finsd's log)."""
        deadline = time.monotonic() + START_TIMEOUT
        pattern = re.compile(rf'plc "{re.escape(name)}" unit \d+ is FINS node \S+ on \S+ port (\d+)')
        while time.monotonic() < deadline:
            m = pattern.search(self.stderr_path.read_text())
            if m:
                return int(m.group(1))
            time.sleep(0.05)
        raise RuntimeError(f"no port for plc {name} in finsd's log")

    def fins(self, *args, port=None, check=True):
        """Runs the fins CLI against this finsd; returns (exit code, parsed JSON or text)."""
        cmd = [str(BIN / "fins"), "--port", str(port or self.port), "--json"] + [str(a) for a in args]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=20)
        try:
            out = json.loads(r.stdout)
        except ValueError:
            out = r.stdout + r.stderr
        if check and r.returncode != 0:
            raise AssertionError(f"{' '.join(cmd)} exited {r.returncode}: {r.stdout} {r.stderr}")
        return r.returncode, out

    def ctl(self, *args):
        """Runs `finsd ctl ARGS` (the same program as this finsd) on its control channel."""
        cmd = FINSD + ["ctl", "--socket", self.control] + [str(a) for a in args]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=START_TIMEOUT)
        if r.returncode != 0:
            raise AssertionError(f"{' '.join(cmd)} exited {r.returncode}: {r.stdout} {r.stderr}")
        return r.stdout

    def read(self, address, count=1, as_=None, port=None):
        args = ["read", address, count] + (["--as", as_] if as_ else [])
        return self.fins(*args, port=port)[1]["values"]

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=10)
        self.proc.stdout.close()
        self.stderr.close()
        shutil.rmtree(self.dir, ignore_errors=True)


@pytest.fixture
def finsd_factory():
    started = []

    def start(*args, config=None, http="127.0.0.1:0", token=None):
        f = Finsd(args, config, http, token)
        started.append(f)
        return f

    yield start
    for f in started:
        f.stop()


def _chrome(dark=False):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--no-first-run", "--disable-extensions", "--disable-background-networking",
              "--disable-component-update", "--disable-sync", "--window-size=1440,900"]:
        options.add_argument(a)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=options)
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           {"width": 1440, "height": 900, "deviceScaleFactor": 1, "mobile": False})
    driver.execute_cdp_cmd("Emulation.setEmulatedMedia", {"features": [
        {"name": "prefers-color-scheme", "value": "dark" if dark else "light"}]})
    return driver


@pytest.fixture(scope="session")
def browser():
    _need(CHROMIUM)
    _need(CHROMEDRIVER)
    driver = _chrome()
    yield driver
    driver.quit()


@pytest.fixture
def page(browser):
    """The browser, with the console log of the previous test drained."""
    browser.get_log("browser")
    yield browser
    browser.get("about:blank")


def screenshot(driver, name):
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    path = ARTIFACTS / f"{name}.png"
    driver.save_screenshot(str(path))
    return path


def wait_for(predicate, timeout, what, interval=0.02):
    """Polls predicate() until it returns something truthy; bounded by `timeout` seconds."""
    deadline = time.monotonic() + timeout
    last = None
    while True:
        try:
            last = predicate()
            if last:
                return last
        except Exception as e:  # a stale element while the grid re-renders
            last = e
        if time.monotonic() >= deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what} (last: {last!r})")
        time.sleep(interval)


def click_css(driver, css, what, timeout=5):
    """Clicks the element `css` selects, found and clicked in one script: a part of the page
    that re-renders between a find_element and a click (the switches do, on every status
    message) would leave a stale reference in the test's hand. Waits up to `timeout` s for
    the element to be there."""
    return wait_for(lambda: driver.execute_script(
        "const e = document.querySelector(arguments[0]); if (!e) return false; e.click(); return true;",
        css), timeout, what)


def open_page(driver, url):
    driver.get(url)
    wait_for(lambda: driver.execute_script("return document.body.dataset.ready === 'true'"), 15,
             "the page to start")
    wait_for(lambda: driver.execute_script(
        "return document.getElementById('link').dataset.state === 'live'"), 15, "the WebSocket")


def cell_text(driver, word):
    """The text of the grid cell of `word` in the area on screen ('' when not rendered)."""
    return driver.execute_script(
        "const c = document.querySelector(`#grid-rows .cell[data-word='${arguments[0]}']`);"
        "return c ? c.textContent : null;", word)


def severe_console_errors(driver):
    return [e for e in driver.get_log("browser") if e.get("level") == "SEVERE"]


def go_to(driver, address):
    """Types an address into the address box, as a user does after pressing g."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    box = driver.find_element(By.ID, "goto")
    box.clear()
    box.send_keys(address, Keys.ENTER)
