"""The notebooks run by nbmake (``pytest --nbmake notebooks``); the slow ones are marked so
that the default run leaves them to ``make test-slow``."""

from pathlib import Path

import pytest

HERE = Path(__file__).parent
SLOW = {"transfer.ipynb", "your_agent.ipynb"}  # train end to end: transfer.ipynb the longest test of all


@pytest.hookimpl(tryfirst=True)  # before ``-m`` deselects by marker
def pytest_collection_modifyitems(items):
    for item in items:
        if item.path.parent == HERE and item.path.name in SLOW:
            item.add_marker(pytest.mark.slow)
