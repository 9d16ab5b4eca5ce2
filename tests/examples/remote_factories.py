"""Factories of misbehaving remote stacks (`remote_child.py`), with short waits."""

from __future__ import annotations

import sys
from pathlib import Path

from avsim.stack import StackContext
from avsim.stack.remote import RemoteStack, remote

CHILD = Path(__file__).resolve().with_name("remote_child.py")
TIMEOUT = 0.5  # [s] a reply's wait, short for the tests


def _child(ctx: StackContext, mode: str) -> RemoteStack:
    return remote(ctx, [sys.executable, str(CHILD), mode], timeout=TIMEOUT,
                  start_timeout=TIMEOUT if mode == "silent" else 30.0)


def crash(ctx: StackContext) -> RemoteStack:
    return _child(ctx, "crash")


def hang(ctx: StackContext) -> RemoteStack:
    return _child(ctx, "hang")


def huge(ctx: StackContext) -> RemoteStack:
    return _child(ctx, "huge")


def notmap(ctx: StackContext) -> RemoteStack:
    return _child(ctx, "notmap")


def nan(ctx: StackContext) -> RemoteStack:
    return _child(ctx, "nan")


def silent(ctx: StackContext) -> RemoteStack:
    return _child(ctx, "silent")
