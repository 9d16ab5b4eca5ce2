"""What every local worker needs before its run, done once in the workers' forkserver
(`avsim.batch.executors.PRELOAD`): the runner's modules imported, Open3D imported (1.5 s:
it pulls in Plotly and Dash), the EGL plugin's symbols read. Importing this module does it;
nothing here creates a PyBullet client, a GL context or a thread (only numpy's OpenBLAS
pool runs, and it is fork-safe), so a forked worker starts as clean as a spawned one."""

from __future__ import annotations

import avsim.batch.jobs
import avsim.report.speed_plot
import avsim.run.result
import avsim.run.runner  # noqa: F401  (imported for the workers)
from world.core.rendering import read_plugin_symbols
from world.frames import import_open3d

import_open3d()
read_plugin_symbols()
