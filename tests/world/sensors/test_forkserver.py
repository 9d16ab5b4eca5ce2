"""The sensing workers' own forkserver: a worker starts with the same modules whatever
forkserver the process started before (a batch's imports Open3D and matplotlib)."""

from __future__ import annotations

import multiprocessing as mp
import sys
from multiprocessing.connection import Connection

from world.sensors.forkserver import SensingProcess


def _report_modules(conn: Connection) -> None:
    conn.send(sorted(sys.modules))
    conn.close()


def _modules_of(start: type[mp.Process] | type[SensingProcess]) -> list[str]:
    parent, child = mp.Pipe()
    proc = start(target=_report_modules, args=(child,))
    proc.start()
    child.close()
    modules: list[str] = parent.recv()
    proc.join(timeout=30)
    assert proc.exitcode == 0
    return modules


def test_a_sensing_worker_is_not_forked_from_a_batchs_forkserver() -> None:
    ctx = mp.get_context("forkserver")
    ctx.set_forkserver_preload(["avsim.run.warm"])  # what a local batch starts it with
    batch = _modules_of(ctx.Process)
    assert "open3d" in batch and "matplotlib" in batch  # the batch's server is running
    sensing = _modules_of(SensingProcess)
    assert "world.sensors.pipeline" in sensing  # its own preload (`world.sensors.warm`)
    assert "open3d" not in sensing and "matplotlib" not in sensing
