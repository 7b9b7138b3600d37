"""finskit.VirtualPlc(scenario=...): a scenario in virtual time, moved from Python."""
import os
import pathlib

import pytest

import finskit

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples" / "scenarios"

RAMP = """
[scenario]
seed = 1
tick_ms = 100
time = "virtual"

[[scenario.signal]]
address = "D100"
kind = "ramp"
min = 0
max = 1000
period_s = 10

[[scenario.link]]
address = "D101"
expr = "2 * D100"

[[scenario.event]]
name = "hold"
at_s = 100
duration_s = 5
fault = "set"
address = "D100"
value = 7
"""


def test_virtual_time_moves_only_when_the_test_advances_it():
    with finskit.VirtualPlc(scenario=RAMP) as plc:
        assert plc.has_scenario
        with finskit.Client(plc.host, plc.port) as c:
            assert c.read_words("D100", 2) == [0, 0]  # the ramp at t = 0
            assert plc.advance(5) == 50
            # Ticks at 0.1 ... 5.0 s: the ramp's value at 5 s, and its double.
            assert c.read_words("D100", 2) == [500, 1000]
        status = plc.scenario_status()
        assert status["virtual_time"] is True
        assert status["ticks"] == 50
        assert status["time_s"] == pytest.approx(5.0)
        assert [e["name"] for e in status["events"]] == ["hold"]


def test_an_event_triggered_from_python_faults_the_tag():
    with finskit.VirtualPlc(scenario=RAMP) as plc:
        plc.advance(2)
        plc.trigger("hold")
        plc.advance(1)
        assert plc.read_words("D100") == [7]
        assert plc.scenario_status()["events"][0]["active"] is True
        with pytest.raises(ValueError, match="no event named jam"):
            plc.trigger("jam")


def test_a_scenario_file_and_a_pathlike(tmp_path):
    tank = EXAMPLES / "tank.toml"
    for source in (str(tank), tank):
        with finskit.VirtualPlc(scenario=source) as plc:
            with finskit.Client(plc.host, plc.port) as c:
                c.write_bits("CIO0.00", [True])  # the HMI switches the pump on
                plc.advance(60)
                assert c.read_words("D14")[0] > 0  # the tank filled


@pytest.mark.virtual_plc(scenario=str(EXAMPLES / "temperature.toml"))
def test_the_fixture_takes_a_scenario(virtual_plc):
    virtual_plc.write_words("D200", [500])  # SP 50.0 degC
    virtual_plc.advance(120)  # six time constants
    assert abs(virtual_plc.read_words("D201")[0] - 500) < 15


def test_a_bad_scenario_is_a_value_error_with_its_position():
    with pytest.raises(ValueError, match=r"<scenario>:\d+:\d+: .*A10 is in a read-only area"):
        finskit.VirtualPlc(scenario=RAMP.replace('"D101"', '"A10"'))
    with pytest.raises(ValueError, match="cannot read the file"):
        finskit.VirtualPlc(scenario=os.path.join("no", "such", "scenario.toml"))
    with pytest.raises(ValueError, match="file path or TOML text"):
        finskit.VirtualPlc(scenario=42)


def test_scenario_verbs_without_a_scenario_say_so(virtual_plc):
    assert not virtual_plc.has_scenario
    with pytest.raises(ValueError, match="runs no scenario"):
        virtual_plc.advance(1)
