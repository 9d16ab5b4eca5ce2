"""The driver's controls under the stack besides the accelerator pedal
(`planner.driver_override`): the cruise set speed buttons and the brake pedal
(`world.frames.DriverControls`, read with the odometry). Speeds [m/s], accelerations
[m/s^2], times [s].

- Set speed: the last one the driver chose, else the configured one, at most the vehicle's
  maximum. It is the ACC's target: how the car gets there is the ACC's own law, not the
  driver's.
- While the function is off (its switch off, or overridden by the brake), the driver
  drives: the speed he holds moves to his set speed at ``rate`` (a comfortable change),
  never in a step; the plan's source is DRIVER.
- Brake: a pedal position p above ``threshold`` is the driver overriding the system (UN
  R157's driver input to the braking control: the system hands over). While it is pressed
  the car brakes at ``p * a_full`` (the plan's reference leads the speed down by that over
  ``horizon``); the function is off from the first press until the driver switches it on
  again (`DriverControls.activations` grows), and after the release he holds the speed he
  released the pedal at, until he chooses another set speed.
- After an emergency stop (the AEB braked the car to a standstill while he drove): the
  AEB's standstill hold keeps the car stopped, and the driver, who has just been stopped
  short of a vehicle, holds 0 until the way ahead is clear (`way_clear`: no vehicle ahead
  in the lane, or the one ahead moving away at ``clear_speed`` or more); then he moves off
  towards his set speed at ``rate``. Driving off at once into the car the AEB stopped for
  would only make it brake again (a Euro NCAP CCRb run never reached its standstill stop
  trigger). With the function engaged the ACC's own stop-and-go law moves off instead.
"""

from __future__ import annotations

from dataclasses import dataclass

from planner.messages import SpeedSource
from planner.speed import PlannedSpeed, SpeedRef
from world.frames import DriverControls


@dataclass(frozen=True, slots=True)
class DriverParams:
    rate: float = 1.0  # [m/s^2] the driver changes his held speed at this (comfortable)
    threshold: float = 0.05  # [-] brake pedal positions above this override the system
    a_full: float = 8.0  # [m/s^2] the deceleration the full brake pedal asks for (a
    #   passenger car's full braking on dry asphalt)
    horizon: float = 0.5  # [s] braking, the reference leads the speed by a_brake * horizon
    clear_speed: float = 1.0  # [m/s] after an emergency stop, the vehicle ahead moving away
    #   at this or faster clears the way (a car moving off in a queue: 1 m/s within ~1 s)


class DriverInputs:
    """The driver's set speed, held speed and brake override, for one run (module doc)."""

    def __init__(self, set_speed: float, max_speed: float,
                 params: DriverParams | None = None) -> None:
        self.params = params if params is not None else DriverParams()
        self.max_speed = max_speed  # [m/s]
        self.set_speed = set_speed  # [m/s] the ACC's target now
        self.held = set_speed  # [m/s] the speed the driver holds while the function is off
        self._want = set_speed  # [m/s] the speed the driver drives at while it is off
        self._chosen: float | None = None  # [m/s] the set speed signal last read
        self._activations = 0  # the switch presses seen
        self.overridden = False  # a brake press turned the function off
        self._braked = False  # the brake was pressed at the last tick
        self.aeb_hold = False  # the AEB stopped the car: held at 0 until the way is clear

    def update(self, controls: DriverControls, v: float, dt: float) -> None:
        """Read the controls at speed `v`, `dt` since the last tick."""
        if controls.set_speed is not None and controls.set_speed != self._chosen:
            self._chosen = controls.set_speed
            self.set_speed = min(controls.set_speed, self.max_speed)
            self._want = self.set_speed
        if controls.activations != self._activations:
            self._activations = controls.activations
            self.overridden = False
        braking = self.braking(controls)
        if braking or self._braked:  # pressed, or released this tick: at the speed now
            self.overridden = True
            self.held = self._want = v
            self._braked = braking
            return
        step = self.params.rate * dt
        self.held = min(max(self._want, self.held - step), self.held + step)

    def emergency_stopped(self) -> None:
        """The AEB has braked the car to a standstill: hold it there (module doc)."""
        self.aeb_hold = True
        self.held = self._want = 0.0

    def way_clear(self, lead_speed: float | None) -> None:
        """After an emergency stop, the vehicle ahead in the lane moves at `lead_speed`
        [m/s] along the car's direction (None: none ahead): a clear way ends the hold and
        the driver moves off towards his set speed."""
        if self.aeb_hold and (lead_speed is None or lead_speed >= self.params.clear_speed):
            self.aeb_hold = False
            self._want = self.set_speed

    def braking(self, controls: DriverControls) -> bool:
        """Whether the driver's brake overrides the system now."""
        return controls.brake > self.params.threshold

    def driving(self, controls: DriverControls, v: float) -> PlannedSpeed:
        """The driver's speed while the function is off: his brake, else his held speed
        ramping to what he wants (module doc)."""
        p = self.params
        if self.braking(controls):
            a = min(controls.brake, 1.0) * p.a_full
            return PlannedSpeed(SpeedRef(max(v - a * p.horizon, 0.0), -a), SpeedSource.DRIVER)
        accel = 0.0 if self.held == self._want else (
            p.rate if self._want > self.held else -p.rate)
        return PlannedSpeed(SpeedRef(self.held, accel), SpeedSource.DRIVER)
