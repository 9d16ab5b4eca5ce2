"""Entry point of the sensing worker process (`world.sensors.pipeline.ProcessSensing`).

Kept free of heavy imports so that the worker can silence the native libraries' output
(PyBullet's banner, the EGL plugin's reports) before importing them: the worker reports
through its pipe, never on the terminal.

Mesa's llvmpipe rasterises on as many threads as there are cores; the worker is told how
many to use (`world.sensors.pipeline.render_threads`) and sets ``LP_NUM_THREADS`` before
Mesa loads, unless the environment sets it. The images are the same whatever the count:
llvmpipe splits the frame into tiles, not the work on a pixel.
"""

from __future__ import annotations

import os
import signal
from multiprocessing.connection import Connection
from typing import Any


def main(conn: Connection, spec: Any, setup: Any, slots_file: Any, render_threads: int,
         environ: dict[str, str], cwd: str) -> None:
    """Serve `conn` (`world.sensors.pipeline.serve`) in the environment `environ` and the
    directory `cwd` of the process that started the worker (a forked worker has its
    forkserver's otherwise)."""
    for sig in (signal.SIGINT, signal.SIGTERM):  # the main process ends the run and then
        signal.signal(sig, signal.SIG_IGN)  # the worker (Ctrl-C reaches the whole group)
    os.environ.clear()
    os.environ.update(environ)
    os.chdir(cwd)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    if render_threads > 0:
        os.environ.setdefault("LP_NUM_THREADS", str(render_threads))
    from world.sensors.pipeline import serve

    serve(conn, spec, setup, slots_file)
