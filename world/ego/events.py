"""The ego's scripted events (the scenario's `events:`): triggers fire them, the world shows them.

The car is drive-by-wire. An `accelerator_override` (the ICCAS "external disturbance": an
external acceleration command from the gas pedal or a control device) is the accelerator
pedal being pressed, and the pedal is a SENSOR that the stack reads
(`world.frames.Odometry.accelerator_pedal`) and arbitrates (its speed limiter). The world adds
no torque for it: it holds the pedal position from the trigger for `duration` seconds, then
releases it to 0. What the car does about it is the stack's decision.

A `flat_tire` punctures one tyre: the world hands the wheel to the ego body
(`world.ego.body.EgoBody.puncture`), which deflates it physically (a smaller rolling radius, more
rolling resistance, the corner sinks). Nothing tells the stack: it must notice from the
car's own signals (the wheel speeds). A puncture is an instant: the event ends when it fires
(so `after: i` counts from it). A later override does not replace it, nor it an override.

Triggers mean what they mean for the NPC actions and are evaluated by the same code
(`world.actors.behaviour.trigger_holds`), at the same checks
(`world.core.rates.TRIGGER_RATE`): `time` [s], `ego_s` (the ego's centre station on the route)
and `after: i, delay: t` (event i ended t seconds ago; an override ends when its duration is
over, or when a later override replaces it). `gap` needs an actor: the loader refuses it for
events, and so does this class. Each event fires once, at the first check where its trigger
holds.

A sensor fault (`camera_blackout`, `camera_freeze`, `lidar_outage`, `gnss_outage`,
`gnss_jump`: `world.spec.SensorFault`) runs from the check it fires at for its `duration`,
alongside any other event (faults do not replace each other); the sensing pipeline applies
the faults running at each capture's instant to the data it hands the stack
(`world.sensors.faults`). Nothing tells the stack: it must notice from its data.

Pure (no PyBullet) and deterministic: the state is a function of the checks' (t, ego_s).
"""

from __future__ import annotations

import math

from world.actors.behaviour import TriggerContext, trigger_holds
from world.frames import Wheel
from world.spec import (
    SENSOR_FAULTS,
    AcceleratorOverride,
    AfterTrigger,
    EventSpec,
    FlatTire,
    GapTrigger,
    SensorFault,
)

RELEASE_TOLERANCE = 1e-9  # [s] so that fired + duration summed in floats lands on its check


class EgoEvents:
    """The ego's events: which fired and ended when, and the accelerator pedal they hold."""

    def __init__(self, events: tuple[EventSpec, ...]) -> None:
        for i, event in enumerate(events):
            key = f"events.{i}"
            if isinstance(event.trigger, GapTrigger):
                raise ValueError(f"{key}.trigger.gap: only for actors (the gap to the ego)")
            if isinstance(event.trigger, AfterTrigger) and not 0 <= event.trigger.index < i:
                raise ValueError(f"{key}.trigger.after: must refer to an earlier event")
            if not isinstance(event.event, (AcceleratorOverride, FlatTire, *SENSOR_FAULTS)):
                raise ValueError(f"{key}: {type(event.event).__name__} is not simulated yet")
        self.events = events
        self._fired_at: list[float | None] = [None] * len(events)  # [s]
        self._ended_at: list[float | None] = [None] * len(events)  # [s]
        self._override: int | None = None  # the override holding the pedal now
        self._started: tuple[int, ...] = ()
        self._flats: list[Wheel] = []  # punctured tyres, in the order they fired
        self._faults: list[int] = []  # the sensor faults running now, in the order they fired

    def update(self, t: float, ego_s: float) -> tuple[int, ...]:
        """One check at sim time `t` [s], the ego's centre at station `ego_s` [m].

        First the running override whose duration is over ends (the pedal is released),
        then every event whose trigger holds fires, in list order (so `after: i, delay: 0`
        fires at the check where event i ended; a flat tyre ends as it fires). Returns the
        indices fired now."""
        running = self._override
        if running is not None:
            override = self._accelerator(running)
            fired = self._fired_at[running]
            assert fired is not None
            if t >= fired + override.duration - RELEASE_TOLERANCE:
                self._ended_at[running] = t
                self._override = None
        self._end_faults(t)
        ctx = TriggerContext(t=t, ego_s=ego_s, gap=math.inf)  # no actor: no gap
        started = []
        for i, event in enumerate(self.events):
            if self._fired_at[i] is None and trigger_holds(event.trigger, ctx, self._ended_at):
                self._fired_at[i] = t
                started.append(i)
                if isinstance(event.event, FlatTire):  # an instant: it ends as it fires
                    self._ended_at[i] = t
                    self._flats.append(event.event.wheel)
                    continue
                if isinstance(event.event, SENSOR_FAULTS):  # runs beside everything else
                    self._faults.append(i)
                    continue
                if self._override is not None:  # replaced, as a running NPC action is
                    self._ended_at[self._override] = t
                self._override = i
        self._started = tuple(started)
        return self._started

    def _end_faults(self, t: float) -> None:
        """End the running sensor faults whose duration is over at `t` [s]."""
        running = []
        for i in self._faults:
            fired = self._fired_at[i]
            assert fired is not None
            if t >= fired + self._fault(i).duration - RELEASE_TOLERANCE:
                self._ended_at[i] = t
            else:
                running.append(i)
        self._faults = running

    def _fault(self, index: int) -> SensorFault:
        event = self.events[index].event
        assert isinstance(event, SENSOR_FAULTS)
        return event

    @property
    def faults(self) -> tuple[SensorFault, ...]:
        """The sensor faults running now, in the order they fired."""
        return tuple(self._fault(i) for i in self._faults)

    def _accelerator(self, index: int) -> AcceleratorOverride:
        event = self.events[index].event
        assert isinstance(event, AcceleratorOverride)
        return event

    @property
    def pedal(self) -> float:
        """[-] 0..1, the accelerator pedal position now (0 when no override holds it)."""
        return 0.0 if self._override is None else self._accelerator(self._override).pedal

    @property
    def fired_at(self) -> tuple[float | None, ...]:
        """[s] per event (in the scenario's order): when it fired, None if not yet."""
        return tuple(self._fired_at)

    @property
    def ended_at(self) -> tuple[float | None, ...]:
        """[s] per event: when it ended (an override: the pedal released; a flat tyre: as it
        fired; a sensor fault: its duration over), None while not."""
        return tuple(self._ended_at)

    @property
    def started(self) -> tuple[int, ...]:
        """Indices of the events that fired at the last check."""
        return self._started

    @property
    def flat_tires(self) -> tuple[Wheel, ...]:
        """The punctured tyres so far, in the order they fired (a wheel may repeat)."""
        return tuple(self._flats)

    @property
    def started_flats(self) -> tuple[Wheel, ...]:
        """The tyres punctured at the last check (the world passes them to the ego body)."""
        events = (self.events[i].event for i in self._started)
        return tuple(event.wheel for event in events if isinstance(event, FlatTire))
