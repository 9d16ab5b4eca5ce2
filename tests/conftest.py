"""Test-session wide: the order in which `make test`'s two workers take the test files."""

from __future__ import annotations

import pytest

from world.core.simd import pin_numpy_dispatch

pin_numpy_dispatch()  # before any test module imports numpy; xdist's workers inherit it

CLOSED_LOOP = "tests/scenarios/"  # the modules whose few tests share minutes-long runs


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The closed-loop scenario modules first, the rest after, each in collection order.

    `make test` gives whole files to its two workers (``--dist loadfile``), in this order
    (``--no-loadscope-reorder``; xdist's own order puts the files with the most tests first,
    which left the scenario files, few tests of a minute or more each, for the end, and one
    worker finished minutes before the other). Longest first, the many short unit-test
    files fill the gaps at the end."""
    items.sort(key=lambda item: not item.nodeid.startswith(CLOSED_LOOP))
