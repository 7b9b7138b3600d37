#!/usr/bin/env python3
"""The page's cost (issue 16, docs/benchmarks.md "The page"): how soon it is interactive on
loopback (Navigation Timing through Selenium), and what an idle page costs finsd.

  /usr/bin/python3 bench/web_page.py [--bin build/bin] [--runs 20] [--idle 30]

Interactive = the moment the grid holds the first values from the WebSocket (the page's
performance mark "finsd-first-values"), measured from the start of the navigation; the
Navigation Timing points before it are printed too. Write to screen = from the FINS
answer to a MEMORY AREA WRITE of D3 (a datagram this script sends to finsd's FINS/UDP
port) to the moment the grid cell of D3 shows the value (polled through the driver,
which adds a few ms), --writes times (issue 16: "within 1 s"). Idle cost = finsd's CPU time
(/proc/PID/stat utime + stime) over --idle seconds with no page, then with the page open
and nothing changing in the PLC, and the WebSocket messages the idle page received.
"""
import argparse
import os
import re
import json
import signal
import socket
import statistics
import struct
import urllib.request
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from selenium import webdriver
from selenium.webdriver.chrome.service import Service

ROOT = Path(__file__).resolve().parents[1]


def start_finsd(bin_dir, workdir):
    cmd = [str(bin_dir / "finsd"), "--port", "0", "--http", "127.0.0.1:0",
           "--control", str(Path(workdir) / "finsd.sock")]
    log = Path(workdir) / "stderr.txt"
    with open(log, "w") as err:
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err)
    http = None
    deadline = time.monotonic() + 20
    while http is None and time.monotonic() < deadline and proc.poll() is None:
        # finsd logs "finsd: HTTP on ADDRESS port N" (docs/web.md "Starting it").
        m = re.search(r"HTTP on \S+ port (\d+)", log.read_text(errors="replace"))
        if m:
            http = int(m.group(1))
        time.sleep(0.05)
    if http is None:
        proc.kill()
        sys.exit(f"finsd logged no HTTP port: {log.read_text()[-2000:]}")
    return proc, f"http://127.0.0.1:{http}/"


def cpu_seconds(pid):
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def chrome():
    o = webdriver.ChromeOptions()
    o.binary_location = "/usr/bin/chromium"
    for a in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--no-first-run", "--disable-extensions", "--disable-background-networking",
              "--disable-component-update", "--disable-sync", "--window-size=1440,900"]:
        o.add_argument(a)
    return webdriver.Chrome(service=Service(executable_path="/usr/bin/chromedriver"), options=o)


TIMING = """
const n = performance.getEntriesByType('navigation')[0];
const m = performance.getEntriesByName('finsd-first-values')[0];
const h = performance.getEntriesByName('finsd-hello')[0];
return m ? {response: n.responseEnd, interactive: n.domInteractive,
            dcl: n.domContentLoadedEventEnd, load: n.loadEventEnd, hello: h ? h.startTime : 0,
            values: m.startTime} : null;
"""


def load_once(driver, url):
    driver.get("about:blank")
    driver.get(url)
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        t = driver.execute_script(TIMING)
        if t and t["load"] > 0:
            return t
        time.sleep(0.01)
    sys.exit("the page did not show values within 10 s")


CELL = ("const c = document.querySelector(`#grid-rows .cell[data-word='${arguments[0]}']`);"
        "return c ? c.textContent : null;")


def fins_write_word(sock, port, node, word, value, sid):
    """MEMORY AREA WRITE (01 02) of one DM word over FINS/UDP; returns once answered 0000."""
    frame = bytes([0x80, 0, 2, 0, node, 0, 0, 254, 0, sid & 0xFF, 0x01, 0x02, 0x82]) + \
        struct.pack(">HBHH", word, 0, 1, value)
    sock.sendto(frame, ("127.0.0.1", port))
    answer = sock.recv(64)
    if answer[12:14] != b"\x00\x00":
        sys.exit(f"finsd answered the write with {answer[12:14].hex()}")


def write_to_screen(driver, url, writes):
    """Milliseconds from each FINS write's answer to the value in the grid."""
    plc = json.load(urllib.request.urlopen(url + "api/plcs"))["plcs"][0]
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.settimeout(2)
    driver.get(url)
    deadline = time.monotonic() + 10
    while driver.execute_script(CELL, 3) is None and time.monotonic() < deadline:
        time.sleep(0.01)
    out = []
    for i in range(writes):
        value = 1000 + i
        fins_write_word(sock, plc["udp_port"], plc["node"], 3, value, i)
        written = time.monotonic()
        while driver.execute_script(CELL, 3) != str(value):
            if time.monotonic() - written > 10:
                sys.exit(f"D3 = {value} did not show within 10 s")
        out.append((time.monotonic() - written) * 1000)
        time.sleep(0.137)  # land the next write elsewhere in the 100 ms tick
    sock.close()
    return sorted(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", type=Path, default=ROOT / "build" / "bin")
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--idle", type=float, default=30.0)
    ap.add_argument("--writes", type=int, default=20)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as workdir:
        proc, url = start_finsd(args.bin, workdir)
        driver = chrome()
        try:
            cold = load_once(driver, url)
            warm = [load_once(driver, url) for _ in range(args.runs)]
            print(f"finsd {args.bin / 'finsd'}, {url}")
            print(f"first load (empty cache): values at {cold['values']:.1f} ms "
                  f"(DOM interactive {cold['interactive']:.1f}, load {cold['load']:.1f})")
            for key, name in [("response", "HTML received"), ("interactive", "DOM interactive"),
                              ("dcl", "DOMContentLoaded end"), ("load", "load end"),
                              ("hello", "WebSocket hello"),
                              ("values", "first values in the grid")]:
                xs = sorted(t[key] for t in warm)
                print(f"{args.runs} reloads, {name:26}: median {statistics.median(xs):6.1f} ms, "
                      f"max {xs[-1]:6.1f} ms")
            shown = write_to_screen(driver, url, args.writes)
            print(f"{args.writes} FINS writes to the screen: median "
                  f"{statistics.median(shown):6.1f} ms, max {shown[-1]:6.1f} ms")
            driver.get("about:blank")
            time.sleep(1)
            before = cpu_seconds(proc.pid)
            time.sleep(args.idle)
            alone = cpu_seconds(proc.pid) - before
            driver.get(url)
            time.sleep(3)
            seq = driver.execute_script("return window.finsd.live.seq")
            before = cpu_seconds(proc.pid)
            time.sleep(args.idle)
            with_page = cpu_seconds(proc.pid) - before
            messages = driver.execute_script("return window.finsd.live.seq") - seq
            print(f"finsd CPU over {args.idle:.0f} s: no page {alone * 1000:.0f} ms "
                  f"({alone / args.idle * 100:.2f} %), idle page open {with_page * 1000:.0f} ms "
                  f"({with_page / args.idle * 100:.2f} %); WebSocket messages to the idle page: "
                  f"{messages}")
        finally:
            driver.quit()
            proc.send_signal(signal.SIGTERM)
            proc.wait(timeout=10)


if __name__ == "__main__":
    main()
