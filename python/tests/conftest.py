# Loads the plugin from the build tree too (installed, the pytest11 entry point does it).
pytest_plugins = ["finskit.pytest_plugin"]
