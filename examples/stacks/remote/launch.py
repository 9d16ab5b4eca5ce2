"""The factory that names the remote example's command line: the lane keeper of
`lane_keeper.py`, run by this Python in its own process (`avsim.stack.remote`).

``avsim run normal_driving --profile none --stack examples/stacks/remote/launch.py:make``
"""

from __future__ import annotations

import sys
from pathlib import Path

from avsim.stack import StackContext
from avsim.stack.remote import RemoteStack, remote

__version__ = "1.0"

CHILD = Path(__file__).resolve().with_name("lane_keeper.py")


def make(ctx: StackContext) -> RemoteStack:
    return remote(ctx, [sys.executable, str(CHILD)])
