"""What every sensing worker needs before it builds its world, done once in the forkserver it
is forked from (`world.sensors.pipeline.SensingWorker`): the pipeline's modules imported
(PyBullet's build banner silenced) and the EGL plugin's symbol table read (about 1 s of
pyelftools, `world.core.rendering.read_plugin_symbols`). Importing this module does it;
nothing here creates a PyBullet client, a GL context or a thread, and Mesa is not loaded (it
loads with the EGL plugin, in the worker, after ``LP_NUM_THREADS`` is set), so a forked
worker starts as clean as a spawned one."""

from __future__ import annotations

from world.core.quiet import quiet_c_output

with quiet_c_output():
    import world.sensors.pipeline  # noqa: F401  (imported for the workers)
    from world.core.rendering import read_plugin_symbols

read_plugin_symbols()
