"""The agent's stack: a `DrivingStack` that keeps the newest frame of each sensor for the
agent to observe and drives with the action the agent gave (`AgentStack.action`), through
the car's drive-by-wire interface (`avsim.stack.drive_by_wire`)."""

from __future__ import annotations

from dataclasses import dataclass

from avsim.stack import Frame, Frames, Odometry, StackContext, StackStep, drive_by_wire


@dataclass(frozen=True, slots=True)
class Action:
    """What the agent asks of the car for one step."""

    steering_angle: float = 0.0  # [rad] road-wheel angle of the bicycle model, left +
    accel: float = 0.0  # [m/s^2] longitudinal acceleration


class AgentStack:
    """Drives with `action` at every control tick; `latest` holds each sensor's newest frame
    by sensor name (a frame arrives when the sensor loop delivers it: at its rate, a camera or
    LiDAR one latency after its capture)."""

    reads = None  # every sensor

    def __init__(self, ctx: StackContext) -> None:
        self.ctx = ctx
        self.action = Action()
        self.latest: dict[str, Frame] = {}

    def on_frames(self, t: float, frames: Frames) -> None:
        self.latest.update(frames)

    def tick(self, t: float, dt: float) -> StackStep:
        odometry = self.latest.get("odometry")
        speed = odometry.speed if isinstance(odometry, Odometry) else 0.0  # [m/s] the
        #   wheels' (the drive-by-wire model's drag and rolling terms depend on it)
        a = self.action
        return StackStep(drive_by_wire(a.steering_angle, a.accel, speed, self.ctx.vehicle),
                         channels={"agent_steering": a.steering_angle, "agent_accel": a.accel})
