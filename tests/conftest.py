"""Test-session wide: the order in which `make test`'s two workers take the test files."""

from __future__ import annotations

import pytest

from world.core.simd import pin_numpy_dispatch

pin_numpy_dispatch()  # before any test module imports numpy; xdist's workers inherit it

LONG_FIRST = (
    "tests/scenarios/",  # closed-loop runs: few tests sharing runs of a minute or more
    "tests/test_docs.py",  # every command of the pages, one test of minutes
    "tests/avsim/batch/",  # suites, sweeps and campaigns through real workers
    "tests/avsim/run/test_interrupts.py",  # batches interrupted by real signals
    "tests/avsim/test_cli.py",  # real processes
    "tests/conformance/",  # the OpenSCENARIO sets played against esmini's
)  # the files that take longest, by path prefix, in the order they start


def _rank(item: pytest.Item) -> int:
    """The index of the first of `LONG_FIRST` the item's file is in; the rest after them."""
    return next((k for k, prefix in enumerate(LONG_FIRST) if item.nodeid.startswith(prefix)),
                len(LONG_FIRST))


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The longest files first (`LONG_FIRST`), the rest after, each in collection order.

    `make test` gives whole files to its two workers (``--dist loadfile``), in this order
    (``--no-loadscope-reorder``; xdist's own order puts the files with the most tests first,
    which left the scenario files, few tests of a minute or more each, for the end, and one
    worker finished minutes before the other). Longest first, the many short unit-test
    files fill the gaps at the end."""
    items.sort(key=_rank)
