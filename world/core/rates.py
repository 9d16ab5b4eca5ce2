"""Every rate of the program, in one table; each divides the 240 Hz physics rate (checked).

Time is counted in physics steps (`world.core.client.Clock`): a `Rate` of ``hz`` fires at
every step that is a multiple of ``PHYSICS_RATE / hz``, so nothing drifts. Nothing else in
the program declares a rate; everything reads it from here.

| rate                | Hz  | what runs at it                                             |
|---------------------|-----|-------------------------------------------------------------|
| physics             | 240 | `World.step`: Bullet's fixed step                           |
| NPC triggers        | 40  | NPC actions' and ego events' triggers checked (`World.step`)  |
| NPC motion          | 120 | NPC motion integrated, bodies moved (`World.step`)          |
| control             | 40  | the sensor loop and the stack decide, the command is applied |
| criteria            | 40  | criteria sample ground truth (at contact checks)            |
| contacts            | 120 | collision onsets                                            |
| recording           | 20  | ego pose, scalars and the plan logged (at control ticks)    |
| recording (actors)  | 10  | NPC boxes logged (at recording ticks)                       |
| GNSS                | 10  | a position / heading fix, delivered at once                 |
| odometry            | 40  | wheel, gyro, steering and pedal signals, delivered at once  |
| truth               | 40  | privileged truth mode only: the ground truth, at once       |
| cameras, LiDAR      | per profile (`PROFILE_SENSORS`), delivered `FRAME_LATENCY` late |

Each sensor's entry (`SensorTiming`) also says when its capture reaches the stack (the
latency) and which of its frames the recording keeps (`record_every`: 2 Hz of the front
camera at 10 Hz, 0.5 Hz of the side cameras at 2 Hz, 1 Hz of the LiDAR).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

PHYSICS_RATE = 240  # [Hz] the fixed physics step


@dataclass(frozen=True, slots=True)
class Rate:
    """A rate that divides the physics rate: it fires every `PHYSICS_RATE / hz` steps."""

    name: str
    hz: int  # [Hz]
    every: int = field(init=False)  # [steps] between firings

    def __post_init__(self) -> None:
        if self.hz <= 0 or PHYSICS_RATE % self.hz:
            raise ValueError(f"rate {self.name} = {self.hz} Hz must divide {PHYSICS_RATE} Hz")
        object.__setattr__(self, "every", PHYSICS_RATE // self.hz)

    @property
    def period(self) -> float:
        """[s] between firings."""
        return self.every / PHYSICS_RATE

    def fires(self, step: int) -> bool:
        return step % self.every == 0


@dataclass(frozen=True, slots=True)
class SensorTiming:
    """When one sensor captures, when its capture reaches the stack, and which of its frames
    the recording keeps."""

    rate: Rate  # captures
    latency: float = 0.0  # [s] from a capture to its delivery to the stack, whole steps
    record_every: int = 0  # [-] the recording keeps every n-th frame (the first one
    #   included); 0: none

    def __post_init__(self) -> None:
        steps = self.latency * PHYSICS_RATE
        if self.latency < 0.0 or abs(steps - round(steps)) > 1e-9:
            raise ValueError(f"latency of {self.rate.name} = {self.latency} s must be a whole "
                             f"number of physics steps (1/{PHYSICS_RATE} s)")
        if self.record_every < 0:
            raise ValueError(f"record_every of {self.rate.name} must be >= 0")

    @property
    def latency_steps(self) -> int:
        """[steps] the latency in physics steps."""
        return round(self.latency * PHYSICS_RATE)


# -- the world (`world.world`) ----------------------------------------------------------------
TRIGGER_RATE = Rate("npc_triggers", 40)  # NPC actions' and ego events' triggers checked
ACTOR_RATE = Rate("npc_motion", 120)  # NPC motion integrated and bodies moved

# -- the closed loop (`avsim.run.runner`) -----------------------------------------------------
CONTROL_RATE = Rate("control", 40)  # sensors delivered, the stack decides, command applied
CRITERIA_RATE = Rate("criteria", 40)  # criteria sample ground truth (at contact checks)
CONTACT_RATE = Rate("contacts", 120)  # collision onsets
RECORD_RATE = Rate("record", 20)  # ego pose, scalars and plan logged (at control ticks)
ACTOR_RECORD_RATE = Rate("record_actors", 10)  # NPC boxes logged (at recording ticks)

# -- the sensors ------------------------------------------------------------------------------
FRAME_LATENCY = 0.1  # [s] a camera frame or LiDAR scan reaches the stack this long after its
#   capture: the time a real pipeline needs to expose, read out and hand over a frame (one
#   period of the 10 Hz sensors)
GNSS = SensorTiming(Rate("gnss", 10))  # fixes, delivered at once
ODOMETRY = SensorTiming(Rate("odometry", 40))  # vehicle signals, delivered at once
CAR_SENSORS: Mapping[str, SensorTiming] = {"gnss": GNSS, "odometry": ODOMETRY}  # on every
#   car, with or without a sensor profile
TRUTH = SensorTiming(Rate("truth", 40))  # privileged truth mode only: the ground truth at
#   the control rate, delivered at once (no latency: it is no sensor's measurement)

_FRONT = SensorTiming(Rate("front", 10), FRAME_LATENCY, record_every=5)  # recorded at 2 Hz
_LIDAR = SensorTiming(Rate("lidar", 10), FRAME_LATENCY, record_every=10)  # recorded at 1 Hz
PROFILE_SENSORS: Mapping[str, Mapping[str, SensorTiming]] = {  # by `Profile` value
    "fast": {"front": _FRONT, "lidar": _LIDAR},
    "default": {"front": _FRONT,
                "left": SensorTiming(Rate("left", 2), FRAME_LATENCY, record_every=4),
                "right": SensorTiming(Rate("right", 2), FRAME_LATENCY, record_every=4),
                "lidar": _LIDAR},
    "paper": {"front": _FRONT,
              "left": SensorTiming(Rate("left", 10), FRAME_LATENCY, record_every=4),
              "right": SensorTiming(Rate("right", 10), FRAME_LATENCY, record_every=4),
              "lidar": _LIDAR},
}

# Rates only looked at on another rate's steps must be multiples of it: (rate, checked on).
NESTED = ((CRITERIA_RATE, CONTACT_RATE), (RECORD_RATE, CONTROL_RATE),
          (ACTOR_RECORD_RATE, RECORD_RATE))


def check_nested(pairs: tuple[tuple[Rate, Rate], ...] = NESTED) -> None:
    """Raise unless each rate's period is a whole number of the periods it is checked on."""
    for rate, on in pairs:
        if rate.every % on.every:
            raise ValueError(f"rate {rate.name} ({rate.hz} Hz) is checked on the steps of "
                             f"{on.name} ({on.hz} Hz): its period must be a multiple of those")


check_nested()
