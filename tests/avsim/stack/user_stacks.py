"""Stacks and stages of a user's own, as a test names them (`tests.avsim.stack.user_stacks:
NAME`): each imports only the public stack API."""

from __future__ import annotations

from avsim.stack import (
    Frames,
    GnssFix,
    Indicator,
    Odometry,
    Plan,
    PlannerInput,
    StackContext,
    StackStep,
    VehicleCommand,
    bundled,
    by_pedals,
    drive_by_wire,
)


class CountingPlanner:
    """The bundled planner, counting its ticks."""

    def __init__(self, ctx: StackContext) -> None:
        self.inner = bundled.planner(ctx)
        self.ticks = 0
        COUNTERS.append(self)

    def update(self, inp: PlannerInput) -> Plan:
        self.ticks += 1
        return self.inner.update(inp)


COUNTERS: list[CountingPlanner] = []


def counting_planner(ctx: StackContext) -> CountingPlanner:
    return CountingPlanner(ctx)


class Cruise:
    """A whole stack: wheels straight, the set speed held by a proportional drive torque on
    the odometry's speed; it shows no plan, one diagnostic channel."""

    def __init__(self, ctx: StackContext) -> None:
        self.set_speed = ctx.set_speed
        self.speed = 0.0
        self.names: list[str] = []

    @property
    def reads(self) -> frozenset[str] | None:
        return None

    def on_frames(self, t: float, frames: Frames) -> None:
        for name, frame in frames.items():
            self.names.append(name)
            if isinstance(frame, Odometry):
                self.speed = frame.speed
            assert not isinstance(frame, GnssFix) or name == "gnss"

    def tick(self, t: float, dt: float) -> StackStep:
        error = self.set_speed - self.speed
        drive, brake = (300.0 * error, 0.0) if error > 0 else (0.0, -300.0 * error)
        return StackStep(VehicleCommand(0.0, drive, brake, 0.0), None,
                         {"speed_error": error})


def cruise(ctx: StackContext) -> Cruise:
    return Cruise(ctx)


class Broken(Cruise):
    """`Cruise`, raising at its tick at 0.5 s."""

    def tick(self, t: float, dt: float) -> StackStep:
        if t >= 0.5:
            raise RuntimeError("a bug in the user's stack")
        return super().tick(t, dt)


def broken(ctx: StackContext) -> Broken:
    return Broken(ctx)


def not_a_stack(ctx: StackContext) -> object:
    return object()


__version__ = "0.0.7"


class Accelerate(Cruise):
    """Wheels straight, 1 m/s^2 asked through `drive_by_wire` at every tick."""

    def __init__(self, ctx: StackContext) -> None:
        super().__init__(ctx)
        self.vehicle = ctx.vehicle

    def tick(self, t: float, dt: float) -> StackStep:
        return StackStep(drive_by_wire(0.0, 1.0, self.speed, self.vehicle))


def accelerate(ctx: StackContext) -> Accelerate:
    return Accelerate(ctx)


class Chatty(Cruise):
    """`Cruise`, its `on_frames` returning a dict (not a report)."""

    def on_frames(self, t: float, frames: Frames) -> dict[str, float]:  # type: ignore[override]
        super().on_frames(t, frames)
        return {"t": t}


def chatty(ctx: StackContext) -> Chatty:
    return Chatty(ctx)


class FrameLog(Cruise):
    """A cruise control that keeps the names of the frames of every delivery and the
    sensors it was told of."""

    def __init__(self, ctx: StackContext) -> None:
        super().__init__(ctx)
        self.ctx = ctx
        self.deliveries: list[tuple[float, tuple[str, ...]]] = []
        self.frames: list[object] = []
        FRAME_LOGS.append(self)

    def on_frames(self, t: float, frames: Frames) -> None:
        self.deliveries.append((t, tuple(frames)))
        self.frames.extend(frames.values())
        super().on_frames(t, frames)


FRAME_LOGS: list[FrameLog] = []


def frame_log(ctx: StackContext) -> FrameLog:
    return FrameLog(ctx)


class Pedals(Cruise):
    """Half throttle for 1 s with the left indicator on, then full brake with the right."""

    def tick(self, t: float, dt: float) -> StackStep:
        if t < 1.0:
            return StackStep(by_pedals(0.0, 0.5, 0.0, indicator=Indicator.LEFT))
        return StackStep(by_pedals(0.0, 0.0, 1.0, indicator=Indicator.RIGHT))


def pedals(ctx: StackContext) -> Pedals:
    return Pedals(ctx)
