#!/usr/bin/env python3
"""1-word MEMORY AREA READs from Python (finskit) vs the C++ client, same run, same finsd.

    PYTHONPATH=build-pkg/python python3 bench/python_client.py \
        --finsd build/bin/finsd --cpp build/bin/fins_client_rate [--seconds 2] [--runs 3]

Starts one finsd (port 0), then for UDP and TCP at 1 and 32 in flight measures
fins_client_rate (C++ fins::Client, async_send) and finskit.Client (read_words for 1 in
flight, read_many(in_flight=32) for 32) back to back, and prints the rates and the
Python/C++ ratio. Timing only: nothing here is a pass/fail test.
"""
import argparse
import statistics
import subprocess
import time

import finskit


def cpp_rate(binary, port, protocol, in_flight, seconds):
    out = subprocess.run([binary, "127.0.0.1", str(port), protocol, str(in_flight),
                          str(seconds)], check=True, capture_output=True, text=True).stdout
    requests, took = out.split()
    return int(requests) / float(took)


def python_rate(port, protocol, in_flight, seconds):
    with finskit.Client("127.0.0.1", port, protocol=protocol) as c:
        done = 0
        start = time.perf_counter()
        end = start + seconds
        if in_flight == 1:
            while time.perf_counter() < end:
                c.read_words("D0", 1)
                done += 1
        else:
            batch = ["D0"] * (in_flight * 32)
            while time.perf_counter() < end:
                c.read_many(batch, 1, in_flight)
                done += len(batch)
        return done / (time.perf_counter() - start)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--finsd", required=True)
    parser.add_argument("--cpp", required=True)
    parser.add_argument("--seconds", type=float, default=2.0)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    finsd = subprocess.Popen([args.finsd, "--port", "0", "--log-level", "warn"],
                             stdout=subprocess.PIPE, text=True)
    try:
        port = None
        for _ in range(100):
            line = finsd.stdout.readline()
            if line.startswith("listening"):
                port = int(line.split()[1])
                break
        assert port, "finsd did not start"
        print("| transport | in flight | C++ req/s | Python req/s | Python / C++ |")
        print("| --- | ---: | ---: | ---: | ---: |")
        medians = []
        for protocol in ("udp", "tcp"):
            for in_flight in (1, 32):
                ratios = []
                for _ in range(args.runs):
                    cpp = cpp_rate(args.cpp, port, protocol, in_flight, args.seconds)
                    py = python_rate(port, protocol, in_flight, args.seconds)
                    ratios.append(py / cpp)
                    print(f"| {protocol.upper()} | {in_flight} | {cpp:,.0f} | {py:,.0f} | "
                          f"{py / cpp:.2f} |", flush=True)
                medians.append((protocol, in_flight, statistics.median(ratios)))
        for protocol, in_flight, ratio in medians:
            print(f"median Python/C++ {protocol.upper()} {in_flight} in flight: {ratio:.2f}")
    finally:
        finsd.terminate()
        finsd.wait(timeout=10)


if __name__ == "__main__":
    main()
