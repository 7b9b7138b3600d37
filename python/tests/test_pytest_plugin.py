"""The virtual_plc fixture reaches a user's tests with no conftest and no `-p` option,
installed (package_test.sh) and from the build tree (PYTHONPATH=<build>/python): both
carry a finskit-*.dist-info whose pytest11 entry point loads finskit.pytest_plugin."""
import os
import subprocess
import sys

import finskit

USER_TEST = '''
import finskit

def test_user_code(virtual_plc):
    with finskit.Client(virtual_plc.host, virtual_plc.port, protocol="tcp") as c:
        c.write_words("D0", [7])
        assert c.read_words("D0", 1) == [7]

@__import__("pytest").mark.virtual_plc(profile="cj1m", mode="program")
def test_marker_options(virtual_plc):
    with finskit.Client(virtual_plc.host, virtual_plc.port) as c:
        assert c.status().mode == "program"
'''


def test_fixture_without_conftest_or_p_option(tmp_path):
    (tmp_path / "test_user.py").write_text(USER_TEST)
    # The directory finskit was imported from (build tree or dist-packages), absolute:
    # the child runs in tmp_path.
    here = os.path.dirname(os.path.dirname(os.path.abspath(finskit.__file__)))
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1",
               PYTHONPATH=os.pathsep.join([here, os.environ.get("PYTHONPATH", "")]))
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_user.py"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "2 passed" in result.stdout
