"""Entry point of the sensing worker process (`world.sensors.pipeline.ProcessSensing`).

Kept free of heavy imports so that the worker can silence the native libraries' output
(PyBullet's banner, the EGL plugin's reports) before importing them: the worker reports
through its pipe, never on the terminal.
"""

from __future__ import annotations

import os
from multiprocessing.connection import Connection
from typing import Any


def main(conn: Connection, spec: Any, setup: Any, slots_file: Any) -> None:
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    from world.sensors.pipeline import serve

    serve(conn, spec, setup, slots_file)
