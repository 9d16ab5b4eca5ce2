"""The sensing workers' own forkserver: every worker is forked from a server that has
imported exactly `PRELOAD`, whatever else the starting process has done.

Why a server of their own. multiprocessing keeps one ``forkserver`` per process, with the
preload of whoever started it first. A local batch starts it with its runs' preload
(`avsim.run.warm`: the runner, Open3D, matplotlib); a sensing worker forked from that
server starts with another heap than one forked from a server that imported only the
pipeline. The mirror world it builds then differs in the last bits of some vertices (numpy's
vectorised sums depend on the alignment of their arrays), its frames differ, and so did a
town run's trajectory (a golden result written in a test process that had run a batch
first differed from the same run elsewhere). With a server of its own, a worker's start is
the same in `avsim run`, in a batch's run, in Ray and in a test process.

The server is multiprocessing's own (`multiprocessing.forkserver.ForkServer`, a second
instance); only the step that asks it for a child (`popen_forkserver.Popen._launch`) is
redone here against that instance, as the standard library writes it. The children are
ordinary forkserver children (their pipes and fds are passed the standard way).
"""

from __future__ import annotations

import io
import os
from multiprocessing import forkserver, popen_forkserver, process, reduction, spawn, util
from multiprocessing.context import set_spawning_popen
from typing import Any

PRELOAD = ("world.sensors.warm",)  # what the server imports once (`world.sensors.warm`)

_SERVER = forkserver.ForkServer()
_SERVER.set_forkserver_preload(list(PRELOAD))


class _Popen(popen_forkserver.Popen):
    """`popen_forkserver.Popen` whose child comes from `_SERVER`."""

    def _launch(self, process_obj: Any) -> None:
        prep_data = spawn.get_preparation_data(process_obj._name)
        buf = io.BytesIO()
        set_spawning_popen(self)
        try:
            reduction.dump(prep_data, buf)
            reduction.dump(process_obj, buf)
        finally:
            set_spawning_popen(None)
        fds: list[int] = self._fds  # type: ignore[attr-defined]  # (set by Popen, untyped)
        self.sentinel, w = _SERVER.connect_to_new_process(fds)
        parent_w = os.dup(w)  # the child's sentinel of its parent (as the stdlib keeps it)
        self.finalizer = util.Finalize(self, util.close_fds,  # type: ignore[attr-defined]
                                       (parent_w, self.sentinel))
        with open(w, "wb", closefd=True) as f:
            f.write(buf.getbuffer())
        self.pid = forkserver.read_signed(self.sentinel)


class SensingProcess(process.BaseProcess):
    """A `multiprocessing.Process` forked from the sensing workers' own server."""

    _start_method = "forkserver"

    @staticmethod
    def _Popen(process_obj: Any) -> _Popen:  # noqa: N802 (the stdlib's name)
        return _Popen(process_obj)
