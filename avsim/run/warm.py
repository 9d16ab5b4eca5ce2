"""What every run needs before it starts, done once in the forkserver that local batch
workers are forked from (`avsim.batch.executors.PRELOAD`): the runner's modules imported,
Open3D imported (1.5 s: it pulls in Plotly and Dash), and the sensing pipeline's own
warm-up (`world.sensors.warm`: the EGL plugin's symbols read, for a run that renders in its
own process). A run's sensing worker is not forked from this server but from one of its
own (`world.sensors.forkserver`), so that it starts the same as in `avsim run`. Importing
this module does it; nothing here creates a PyBullet client, a GL context or a thread (only
numpy's OpenBLAS pool runs, and it is fork-safe), so a forked worker starts as clean as a
spawned one."""

from __future__ import annotations

import avsim.batch.jobs
import avsim.report.speed_plot
import avsim.run.result
import avsim.run.runner  # noqa: F401  (imported for the workers)
import world.sensors.warm  # noqa: F401  (the sensing workers' own warm-up)
from world.frames import import_open3d

import_open3d()
