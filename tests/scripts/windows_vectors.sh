#!/usr/bin/env bash
# finsd.exe under wine answering the conformance vectors byte for byte (tests/vectors/,
# the frames test_codec checks the codec against), sent from the host over loopback:
# - memory_area_read_d10_frame.txt over FINS/UDP: the MEMORY AREA READ of D10..D19 (after
#   the host's Linux fins wrote 1..10 there) answered with exactly the vector's response;
# - tcp_handshake.txt over FINS/TCP: the node address request (client node 0) answered
#   with the vector's response but for the client node finsd allocates; asked for node 0A,
#   exactly the vector's response; then the vector's FRAME SEND answered with the FRAME
#   SEND that carries the UDP vector's response.
# Usage: windows_vectors.sh WINDOWS_BIN_DIR HOST_BIN_DIR (WINEPREFIX and WINEDEBUG from
# ctest's environment). Every wait is for a condition, bounded in time; every process
# started is ended on exit (only those: wineserver is left to wine).
set -euo pipefail
vectors="$(cd "$(dirname "$0")/../vectors" && pwd)"
source "$(dirname "$0")/round_trip_lib.sh"  # windows_test, free_port, wait_for
windows_test "windows vectors" "$1" "$2" "$2/fins" "$1/finsd.exe"

port=$(free_port)
"$wine" "$bin/finsd.exe" --bind 127.0.0.1 --port "$port" >"$work/finsd.log" 2>&1 &
pids+=($!)
wait_for 120 grep -q "^listening $port" "$work/finsd.log" || fail "finsd.exe did not listen"
"$host_bin/fins" --port "$port" write D10 1 2 3 4 5 6 7 8 9 10 >/dev/null || fail "write D10"

/usr/bin/python3 - "$vectors" "$port" <<'EOF' || fail "a vector was not answered as written"
import socket, sys

vectors, port = sys.argv[1], int(sys.argv[2])
address = ("127.0.0.1", port)

def load(name):  # the data lines of a vector file, as bytes
    with open(f"{vectors}/{name}") as f:
        return [bytes.fromhex(line) for line in f if line.strip() and not line.startswith("#")]

def recv_exactly(sock, n):
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise SystemExit(f"connection closed after {len(data)} of {n} bytes")
        data += chunk
    return data

def recv_tcp_frame(sock):  # "FINS", length, then length bytes
    head = recv_exactly(sock, 8)
    return head + recv_exactly(sock, int.from_bytes(head[4:8], "big"))

failures = 0
def expect(what, got, want):
    global failures
    ok = got == want
    print(f"{'ok' if ok else 'FAILED'}: {what}")
    if not ok:
        print(f"  got  {got.hex(' ')}\n  want {want.hex(' ')}")
        failures += 1

request, response = load("memory_area_read_d10_frame.txt")
with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as udp:
    udp.settimeout(10)
    udp.sendto(request, address)
    expect("FINS/UDP memory area read D10", udp.recv(4096), response)

node_request, node_response, frame_send, *_ = load("tcp_handshake.txt")
with socket.create_connection(address, timeout=10) as tcp:
    tcp.sendall(node_request)
    got = recv_tcp_frame(tcp)
    # The vector's response with the client node finsd chose (byte 19).
    want = node_response[:19] + got[19:20] + node_response[20:] if len(got) == 24 else node_response
    expect(f"FINS/TCP node address request, node 0 (allocated {got[19:20].hex()})", got, want)
with socket.create_connection(address, timeout=10) as tcp:
    tcp.sendall(node_request[:19] + node_response[19:20])  # ask for the vector's node, 0A
    expect("FINS/TCP node address request, node 0A", recv_tcp_frame(tcp), node_response)
    tcp.sendall(frame_send)
    carried = (b"FINS" + (8 + len(response)).to_bytes(4, "big") + (2).to_bytes(4, "big")
               + bytes(4) + response)
    expect("FINS/TCP frame send: memory area read D10", recv_tcp_frame(tcp), carried)
sys.exit(1 if failures else 0)
EOF
echo "windows vectors: every vector answered byte for byte"
