"""finskit.Client against the in-process virtual PLC (loopback, port 0)."""
import math
import threading

import pytest

import finskit


@pytest.fixture(params=["udp", "tcp"])
def client(request, virtual_plc):
    with finskit.Client(virtual_plc.host, virtual_plc.port, protocol=request.param,
                        timeout=2.0) as c:
        yield c


def test_write_then_read_words(client):
    client.write_words("D100", [1, 2, 0xFFFF])
    assert client.read_words("D100", 3) == [1, 2, 0xFFFF]


def test_reads_above_999_words_are_split_and_joined(client):
    values = [i & 0xFFFF for i in range(1500)]
    client.write_words("D1000", values)
    assert client.read_words("D1000", 1500) == values


def test_float_in_omron_word_order(client, virtual_plc):
    client.write_float("D200", 1.5)
    assert client.read_float("D200") == 1.5
    # 1.5f = 0x3FC00000: least significant word first (fins/values.hpp).
    assert virtual_plc.read_words("D200", 2) == [0x0000, 0x3FC0]


def test_typed_values(client):
    client.write_int32("D300", -123456)
    assert client.read_int32("D300") == -123456
    client.write_double("D310", math.pi)
    assert client.read_double("D310") == math.pi
    client.write_string("D320", "HELLO")
    assert client.read_string("D320", 3) == "HELLO"


def test_bits_fill_transfer_multiple(client):
    client.write_bits("CIO10.13", [True, False, True])
    assert client.read_bits("CIO10.13", 3) == [True, False, True]
    client.fill("D400", 10, 0x1234)
    client.transfer("D400", "H0", 10)
    assert client.read_words("H0", 10) == [0x1234] * 10
    assert client.read_multiple(["D400", "CIO10.13"]) == [0x1234, 1]


def test_read_many_pipelines_in_order(client):
    client.write_words("D0", list(range(64)))
    result = client.read_many([f"D{i}" for i in range(64)], count=1, in_flight=32)
    assert result == [[i] for i in range(64)]


def test_end_code_raises_fins_error_with_code_name_meaning(client):
    # W342 5-2-2: A000-A447 are read-only, 01 02 answers 2101.
    with pytest.raises(finskit.FinsError) as info:
        client.write_words("A10", [1])
    assert info.value.code == 0x2101
    assert info.value.name == "write not possible: read-only"
    assert "read-only" in info.value.meaning


def test_read_past_the_end_is_1104(client):
    with pytest.raises(finskit.FinsError) as info:
        client.read_words("D32760", 20)
    assert info.value.code == 0x1104


def test_bad_address_is_value_error(client):
    with pytest.raises(ValueError):
        client.read_words("D99999", 1)
    with pytest.raises(ValueError):
        finskit.Client("127.0.0.1", protocol="serial")


def test_raw_returns_the_end_code_instead_of_raising(client):
    code, data = client.raw(0x0101, bytes.fromhex("82000A00000A"))
    assert code == 0 and len(data) == 20
    # 01 02 to A10 (area B3): read-only, 2101 comes back as a value.
    code, data = client.raw(0x0102, bytes.fromhex("B3000A000001") + b"\x00\x01")
    assert code == 0x2101 and data == b""


def test_controller_commands(client):
    client.stop()
    assert client.status().mode == "program"
    client.run()
    status = client.status()
    assert status.mode == "run" and status.running


def test_clock_write_then_read(client):
    import datetime
    client.set_clock(datetime.datetime(2031, 5, 17, 8, 30, 12))
    now = client.clock()
    # The virtual clock keeps running from what was written.
    assert datetime.datetime(2031, 5, 17, 8, 30, 12) <= now
    assert now - datetime.datetime(2031, 5, 17, 8, 30, 12) < datetime.timedelta(seconds=30)
    with pytest.raises(ValueError):
        client.set_clock(datetime.datetime(2100, 1, 1))


def test_timeout_raises_timeout_error():
    # A bound UDP socket that never answers: each attempt waits 50 ms.
    import socket
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as mute:
        mute.bind(("127.0.0.1", 0))
        port = mute.getsockname()[1]
        with finskit.Client("127.0.0.1", port, timeout=0.05, retries=1) as c:
            with pytest.raises(TimeoutError):
                c.read_words("D0", 1)


def test_gil_is_released_while_waiting():
    import socket
    import time
    ticks = []
    stop = threading.Event()

    def ticker():
        while not stop.is_set() and len(ticks) < 10_000:
            ticks.append(time.monotonic())
            stop.wait(0.001)

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as mute:
        mute.bind(("127.0.0.1", 0))
        with finskit.Client("127.0.0.1", mute.getsockname()[1], timeout=0.3) as c:
            t = threading.Thread(target=ticker)
            t.start()
            begin = time.monotonic()
            with pytest.raises(TimeoutError):
                c.read_words("D0", 1)
            end = time.monotonic()
            stop.set()
            t.join()
    # The other thread ran while the read waited; holding the GIL, it could not have.
    assert any(begin + 0.05 < tick < end - 0.05 for tick in ticks)
