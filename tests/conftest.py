"""Session hook: the files with the most tests marked slow are collected first.

``make test`` hands whole files to the pytest-xdist workers (``--dist loadfile``) in collection
order; a long file collected last would run alone at the end while the other worker idles.
Sorting files by their count of slow tests (stable: the order within a file and among equal
files is kept) starts the long ones first.
"""

from __future__ import annotations

from collections import Counter

import pytest


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Reorder ``items`` in place: files with more slow tests first."""
    slow = Counter(item.path for item in items if item.get_closest_marker("slow"))
    items.sort(key=lambda item: -slow[item.path])
