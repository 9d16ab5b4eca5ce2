"""The fuzzers' shared Hypothesis settings.

Derandomized (the same examples on every machine and run), no example database and no
shrinking (bounded time), no deadline (timing is `make bench`'s, not a test's). `make test`
tries `EXAMPLES` inputs per fuzzer; `make fuzz` sets ``AVSIM_FUZZ_EXAMPLES`` for a longer
search (and a seed of its own through ``AVSIM_FUZZ_SEED``, which turns derandomizing off).
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, Phase, settings

EXAMPLES = int(os.environ.get("AVSIM_FUZZ_EXAMPLES", "100"))  # [-] inputs per fuzzer
_SEEDED = "AVSIM_FUZZ_SEED" in os.environ  # `make fuzz`: a fresh search each time

FUZZ = settings(derandomize=not _SEEDED, deadline=None, max_examples=EXAMPLES, database=None,
                phases=[Phase.explicit, Phase.generate],
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                       HealthCheck.filter_too_much])


def scaled(n: int) -> settings:
    """`FUZZ` with `n` examples in `make test` (a slow fuzzer's share), scaled as `EXAMPLES`
    is by `make fuzz`."""
    return settings(FUZZ, max_examples=max(1, n * EXAMPLES // 100))
