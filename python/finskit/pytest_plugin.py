"""pytest plugin: the `virtual_plc` fixture, a running finskit.VirtualPlc per test.

Registered automatically when finskit is installed or on PYTHONPATH (entry point pytest11,
through finskit_pytest, which skips it when the extension cannot be imported), or with
`pytest_plugins = ["finskit.pytest_plugin"]`. Options come from a marker:

    @pytest.mark.virtual_plc(profile="cj1m", mode="program")
    def test_x(virtual_plc): ...

The PLC listens on 127.0.0.1, port 0 (a free port: virtual_plc.port), with its data
directory in the test's tmp_path, and is stopped after the test. A scenario comes the same
way, as a file (relative to the test file's folder) or as TOML text:

    @pytest.mark.virtual_plc(scenario="tank.toml")
    def test_tank(virtual_plc):
        virtual_plc.advance(60)
"""
import os

import pytest

from finskit import VirtualPlc


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "virtual_plc(**kwargs): arguments of finskit.VirtualPlc for the fixture")


@pytest.fixture
def virtual_plc(request, tmp_path):
    marker = request.node.get_closest_marker("virtual_plc")
    kwargs = dict(marker.kwargs) if marker else {}
    kwargs.setdefault("data_dir", str(tmp_path / "virtual_plc"))
    scenario = kwargs.get("scenario")
    if isinstance(scenario, (str, os.PathLike)) and "\n" not in str(scenario):
        path = os.fspath(scenario)
        if not os.path.isabs(path):
            kwargs["scenario"] = os.path.join(os.path.dirname(str(request.path)), path)
    with VirtualPlc(**kwargs) as plc:
        yield plc
