"""The Rerun recording: recorder, blueprint, headless snapshots."""

import os

# The recording's libraries allocate through mimalloc (Rerun's SDK, and pyarrow's default
# pool here), which by default keeps freed pages for 10 ms of its own clock before giving
# them back, and over an hour's run the kept pages showed as steady growth of resident
# memory (bench/bench_soak.py). Give them back at once; a user's own setting wins. Set
# before the first import of rerun or pyarrow: mimalloc reads it when it starts.
os.environ.setdefault("MIMALLOC_PURGE_DELAY", "0")
