"""The car's sensors: one `Sensor` interface (`sensor`); cameras, LiDAR (+ culling), GNSS,
odometry; the rig; the schedule; the inline / process pipelines.

A new sensor is a module implementing `Sensor` (its frame type in `world.frames`), its entry
in the rates table (`world.core.rates`), its place in the rig (`World._build_rig`), and the
stack's consumer of its frames (`avsim.run.stack.Stack.on_frames`).
"""
