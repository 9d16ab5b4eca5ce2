"""The car's sensor rig in one physics client: its sensors by name, captured on request.

`SensorRig.capture` has the named sensors capture from the ego's TRUE state (the sensors are
on the real body) and returns their readings: the frames for the stack, each with its
ground truth beside it for scoring and the recording.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence

from world.core.stopwatch import Stopwatch
from world.ego.body import EgoTruth
from world.sensors.sensor import Reading, Sensor


class SensorRig:
    """The sensors of one world (one client), by name."""

    def __init__(self, sensors: Iterable[Sensor]) -> None:
        self._sensors: dict[str, Sensor] = {}
        for sensor in sensors:
            if sensor.name in self._sensors:
                raise ValueError(f"two sensors named {sensor.name!r}")
            self._sensors[sensor.name] = sensor

    def __contains__(self, name: object) -> bool:
        return name in self._sensors

    def __iter__(self) -> Iterator[Sensor]:
        return iter(self._sensors.values())

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self._sensors)

    def sensor(self, name: str) -> Sensor:
        try:
            return self._sensors[name]
        except KeyError:
            raise KeyError(f"no sensor {name!r} in this rig ({', '.join(self._sensors)})") \
                from None

    def capture(self, names: Sequence[str], t: float, ego: EgoTruth,
                watch: Stopwatch | None = None) -> tuple[Reading, ...]:
        """The readings of the sensors `names` (in that order) at time `t` [s]; each
        capture timed as the stage "sensor <name>" of `watch`, if given."""
        if watch is None:
            return tuple(self.sensor(name).capture(t, ego) for name in names)
        readings = []
        for name in names:
            with watch(f"sensor {name}"):
                readings.append(self.sensor(name).capture(t, ego))
        return tuple(readings)
