"""finskit.VirtualPlc and the virtual_plc fixture."""
import pytest

import finskit


def test_fixture_yields_a_running_plc_on_a_free_port(virtual_plc):
    assert virtual_plc.running
    assert virtual_plc.host == "127.0.0.1"
    assert 0 < virtual_plc.port < 65536
    assert virtual_plc.profile == "cj2h"


@pytest.mark.virtual_plc(profile="cj1m", mode="program")
def test_marker_chooses_profile_and_mode(virtual_plc):
    assert virtual_plc.profile == "cj1m"
    with finskit.Client(virtual_plc.host, virtual_plc.port) as c:
        assert c.status().mode == "program"


def test_direct_memory_access_is_seen_over_fins(virtual_plc):
    virtual_plc.write_words("D10", [7, 8])
    with finskit.Client(virtual_plc.host, virtual_plc.port) as c:
        assert c.read_words("D10", 2) == [7, 8]
        c.write_words("W5", [42])
    assert virtual_plc.read_words("W5") == [42]


def test_direct_access_keeps_the_area_rules(virtual_plc):
    with pytest.raises(finskit.FinsError) as info:
        virtual_plc.write_words("A0", [1])
    assert info.value.code == 0x2101


def test_injected_battery_error_sets_the_non_fatal_flag(virtual_plc):
    virtual_plc.inject(battery_error=True, messages=[(0, "HELLO")])
    with finskit.Client(virtual_plc.host, virtual_plc.port) as c:
        status = c.status()
    assert status.non_fatal_errors & (1 << 4)  # 06 01 non-fatal bit 4: battery


def test_retained_memory_survives_a_restart(tmp_path):
    data = str(tmp_path / "state")
    with finskit.VirtualPlc(data_dir=data) as plc:
        plc.write_words("D0", [0xBEEF])
    with finskit.VirtualPlc(data_dir=data) as plc:
        assert plc.read_words("D0") == [0xBEEF]


def test_unknown_profile_is_value_error():
    with pytest.raises(ValueError, match="unknown profile"):
        finskit.VirtualPlc(profile="cj9z")


def test_two_plcs_at_once():
    with finskit.VirtualPlc() as a, finskit.VirtualPlc(profile="cs1h") as b:
        assert a.port != b.port
        with finskit.Client(b.host, b.port) as c:
            c.write_words("D0", [5])
        assert b.read_words("D0") == [5] and a.read_words("D0") == [0]
