"""Sensing pipelines: inline and in a worker process give bitwise the same data, one
sensor period late; worker failures surface as errors, not hangs."""

from __future__ import annotations

import numpy as np
import pytest

from avsim.scenario.load import load_scenario
from world.sensors.pipeline import InlineSensing, ProcessSensing, SensingError
from world.sensors.rig import SensorData, SensorSchedule
from world.sensors.setup import Profile, sensor_setup
from world.world import World


def drive(mode: str, seconds: float = 2.0) -> list[tuple[float, SensorData]]:
    """(delivery time, data) of a car accelerating on normal_driving for `seconds`."""
    spec = load_scenario("normal_driving").world
    setup = sensor_setup(Profile.DEFAULT)
    world = World(spec, setup, cameras=mode == "inline")
    sensing = InlineSensing(world) if mode == "inline" else ProcessSensing(world, setup)
    schedule = SensorSchedule(setup)
    out = []
    try:
        world.ego.apply(0.0, 1500.0 * 2.0 * 0.33, 0.0)
        for _ in range(round(seconds * 240)):
            world.step()
            due = schedule.due(world.clock.step)
            if due:
                data = sensing.collect()
                if data is not None:
                    out.append((world.t, data))
                sensing.submit(world.t, due)
    finally:
        sensing.close()
        world.close()
    return out


def test_inline_and_process_sensing_are_bitwise_equal() -> None:
    inline, process = drive("inline"), drive("process")
    assert len(inline) == len(process) == 19  # 10 Hz over 2 s, the first one still pending
    for (t_a, a), (t_b, b) in zip(inline, process, strict=True):
        assert t_a == t_b and a.t == b.t
        assert t_a == pytest.approx(a.t + 0.1)  # delivered one sensor period late
        assert [f.info.name for f in a.frames] == [f.info.name for f in b.frames]
        for fa, fb in zip(a.frames, b.frames, strict=True):
            assert np.array_equal(fa.rgb, fb.rgb)
        assert a.scan is not None and b.scan is not None
        assert np.array_equal(a.scan.points, b.scan.points)
        assert np.array_equal(a.scan.ring, b.scan.ring)
        assert a.scan_truth is not None and b.scan_truth is not None
        assert np.array_equal(a.scan_truth.actor, b.scan_truth.actor)
    names = [tuple(f.info.name for f in d.frames) for _, d in inline]
    # the sides at 2 Hz: captured at t = 0.5, 1.0, 1.5 and 2.0 (still pending at the end)
    assert names.count(("front", "left", "right")) == 3
    assert all(n[0] == "front" for n in names)


def test_a_failing_worker_raises() -> None:
    spec = load_scenario("normal_driving").world
    setup = sensor_setup(Profile.DEFAULT)
    world = World(spec, setup, cameras=False)
    sensing = ProcessSensing(world, setup)
    try:
        schedule = SensorSchedule(setup)
        due = schedule.due(0)
        sensing._conn.send(("capture", 0.0, "not a snapshot", due.cameras))  # a broken request
        sensing._pending = world.rig.capture(0.0, world.ego_truth, (), True)  # type: ignore[union-attr]
        with pytest.raises(SensingError, match="sensing worker failed"):
            sensing.collect()
    finally:
        sensing.close()
        world.close()
