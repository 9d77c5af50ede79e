import os
import sys

import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import imgutil  # noqa: E402


def pytest_configure(config):
    config.addinivalue_line("markers", "png: needs PNG decoding (skipped when the tool is built without libpng)")


def pytest_collection_modifyitems(config, items):
    if not os.access(imgutil.tool_path(), os.X_OK):
        skip = pytest.mark.skip(reason="amscr tool not built at %s (set AMSCR_TOOL)" % imgutil.tool_path())
        for item in items:
            item.add_marker(skip)
        return
    if not imgutil.have_png():
        skip = pytest.mark.skip(reason="the amscr tool was built without libpng")
        for item in items:
            if item.get_closest_marker("png"):
                item.add_marker(skip)
