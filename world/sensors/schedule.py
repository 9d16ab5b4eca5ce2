"""The sensor schedule: which sensors capture at a physics step, and when each capture
reaches the stack.

Built from the rates table's entries (`world.core.rates.SensorTiming`, as
`world.sensors.setup.sensor_timings` lists them): a sensor captures at the steps where its
rate fires, and its capture is delivered `latency` later. The sensors due at one step with
the same latency form one `Due`: they are captured together and reach the stack together.
The schedule is consulted on the steps of a `tick` rate (the control rate), so every sensor's
period and latency must be whole numbers of the tick's period (checked).

A sensor nobody reads at its full rate captures less: `keep` gives, per sensor, every how
many of its rate's firings it captures (the first one included; 0: never). The sensor loop
asks the full rate of what the stack reads, the recording's `record_every` of what only the
recording shows, and nothing of the rest.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from world.core.rates import PHYSICS_RATE, Rate, SensorTiming


@dataclass(frozen=True, slots=True)
class Due:
    """Sensors that capture at one physics step and reach the stack together."""

    step: int  # [steps] the physics step of the capture
    deliver: int  # [steps] the physics step at which the capture reaches the stack
    sensors: tuple[str, ...]  # their names, in the schedule's order

    @property
    def t(self) -> float:
        """[s] sim time of the capture (as `world.core.client.Clock.t`)."""
        return self.step / PHYSICS_RATE


class SensorSchedule:
    """The sensors' rates and latencies as physics-step counters."""

    def __init__(self, sensors: Iterable[tuple[str, SensorTiming]], tick: Rate,
                 keep: Mapping[str, int] | None = None) -> None:
        """`sensors`: (name, timing) in the order captures list them; `tick`: the rate at
        whose steps `due` is asked; `keep`: per sensor, capture every n-th firing of its rate
        (0: never; a sensor not in it: every firing)."""
        entries = tuple(sensors)
        self.timings = dict(entries)
        self.tick = tick
        self.keep = {name: (keep or {}).get(name, 1) for name in self.timings}
        if keep is not None and (unknown := set(keep) - set(self.timings)):
            raise ValueError(f"keep names sensors not in the schedule: {sorted(unknown)}")
        if any(n < 0 for n in self.keep.values()):
            raise ValueError(f"keep must be >= 0 for every sensor: {self.keep}")
        if len(entries) != len(self.timings):
            raise ValueError(f"sensor names must be unique: {[n for n, _ in entries]}")
        for name, timing in self.timings.items():
            if timing.rate.every % tick.every or timing.latency_steps % tick.every:
                raise ValueError(
                    f"sensor {name}: its period ({timing.rate.every} steps) and latency "
                    f"({timing.latency_steps} steps) must be a multiple of the {tick.name} "
                    f"period ({tick.every} steps), the steps the schedule is asked at")

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.timings)

    def due(self, step: int) -> tuple[Due, ...]:
        """The captures due at physics step `step`: one per latency among the sensors that
        fire, in the order of their first sensor in the schedule."""
        groups: dict[int, list[str]] = {}
        for name, timing in self.timings.items():
            if timing.rate.fires(step) and self._kept(name, step // timing.rate.every):
                groups.setdefault(timing.latency_steps, []).append(name)
        return tuple(Due(step, step + latency, tuple(names))
                     for latency, names in groups.items())

    def _kept(self, name: str, firing: int) -> bool:
        n = self.keep[name]
        return n > 0 and firing % n == 0
