"""The pytest11 entry point of finskit (dist-info entry_points.txt): registers
finskit.pytest_plugin (the virtual_plc fixture) when the finskit extension imports.

When it does not (the module not built for this interpreter, a Python of another
version, a build tree whose extension failed), pytest still runs every other test: only
a test that asks for virtual_plc fails, saying why. The entry point is this module, not
finskit.pytest_plugin, because importing that imports finskit and its extension first.
"""
import pytest

try:
    from finskit.pytest_plugin import pytest_configure, virtual_plc  # noqa: F401
except ImportError as error:
    _why = f"finskit cannot be imported: {error}"

    def pytest_configure(config):
        config.addinivalue_line(
            "markers", "virtual_plc(**kwargs): arguments of finskit.VirtualPlc for the fixture")

    @pytest.fixture
    def virtual_plc():
        pytest.fail(_why, pytrace=False)
