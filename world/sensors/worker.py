"""Entry point of the sensing worker process (`world.sensors.pipeline.ProcessSensing`).

Kept free of heavy imports so that the worker can silence the native libraries' output
(PyBullet's banner, the EGL plugin's reports) before importing them: the worker reports
through its pipe, never on the terminal.

Mesa's llvmpipe rasterises on as many threads as there are cores. Beside a main process that
keeps a core busy, its second thread only takes that core away: on 2 cores, one thread
(``LP_NUM_THREADS=1``, set before Mesa loads, unless the environment sets it) made
`default` 6 % and `paper` 3 % faster and used 5-10 % less CPU in all (three interleaved
runs each). The images are the same: llvmpipe splits the frame into tiles, not the work on
a pixel.
"""

from __future__ import annotations

import os
from multiprocessing.connection import Connection
from typing import Any


def main(conn: Connection, spec: Any, setup: Any, slots_file: Any) -> None:
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    os.environ.setdefault("LP_NUM_THREADS", "1")
    from world.sensors.pipeline import serve

    serve(conn, spec, setup, slots_file)
