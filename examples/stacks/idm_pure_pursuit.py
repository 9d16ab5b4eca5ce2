"""A whole stack in privileged truth mode: IDM on the lead, pure pursuit on the map's lane.

Longitudinal, the Intelligent Driver Model (Treiber, Hennecke & Helbing 2000, "Congested
traffic states in empirical observations and microscopic simulations", Phys. Rev. E 62):

    a = A_MAX [1 - (v / v0)^DELTA - (s* / s)^2],  s* = S0 + v T + v dv / (2 sqrt(A_MAX B))

on the nearest object ahead in the car's lane of the HD map (s the bumper-to-bumper gap
along the lane, dv the closing speed); it brakes harder than B only when the kinematics need
it (dv^2 / 2 s, the lead at constant speed), and stops and holds behind a standing lead.
Lateral, pure pursuit (Coulter 1992, "Implementation of the Pure Pursuit Path Tracking
Algorithm", CMU-RI-TR-92-01) from the rear axle to the lane centre's point one look-ahead
L = K v + L0 down the lane. Run it with
``avsim run sudden_stop --stack examples/stacks/idm_pure_pursuit.py:make --privileged``.
"""

from __future__ import annotations

import math

from avsim.stack import Frames, GroundTruth, SensorKind, StackContext, StackStep, drive_by_wire

__version__ = "1.0"

A_MAX, B, S0, T, DELTA = 1.5, 3.0, 4.0, 1.5, 4.0  # [m/s^2], [m/s^2], [m], [s], [-] IDM
K, L0 = 0.3, 4.0  # [s], [m] pure pursuit's look-ahead


class IdmPurePursuit:
    reads = frozenset({"truth"})

    def __init__(self, ctx: StackContext) -> None:
        if not any(s.kind is SensorKind.TRUTH for s in ctx.sensors):
            raise ValueError("idm_pure_pursuit reads the ground truth: run it --privileged")
        self.ctx, self.lane = ctx, ctx.road.lane(ctx.start_lane)
        self.truth: GroundTruth | None = None

    def on_frames(self, t: float, frames: Frames) -> None:
        truth = frames.get("truth")
        self.truth = truth if isinstance(truth, GroundTruth) else self.truth

    def lead(self, g: GroundTruth, s: float) -> tuple[float, float] | None:
        """(gap [m], speed along the lane [m/s]) of the nearest object ahead in the lane."""
        ahead = []
        for o in g.objects:
            so, ro = (float(x) for x in self.lane.local_coordinates((o.x, o.y)))
            h = float(self.lane.heading_at(so))
            if so > s and abs(ro) < float(self.lane.width_at(so)) / 2:
                gap = so - s - (self.ctx.vehicle.length + o.length) / 2
                ahead.append((gap, o.vx * math.cos(h) + o.vy * math.sin(h)))
        return min(ahead, default=None)

    def tick(self, t: float, dt: float) -> StackStep:
        g, v = self.truth, 0.0 if self.truth is None else self.truth.speed
        if g is None:
            return StackStep(drive_by_wire(0.0, -B, 0.0, self.ctx.vehicle))
        s = float(self.lane.local_coordinates((g.x, g.y))[0])
        v0 = max(0.1, min(self.ctx.set_speed, float(self.ctx.road.speed_limit_at(s))))
        accel, lead = A_MAX * (1.0 - (v / v0) ** DELTA), self.lead(g, s)
        if lead is not None:
            gap, dv = max(lead[0], 0.1), v - lead[1]
            s_star = S0 + max(0.0, v * T + v * dv / (2.0 * math.sqrt(A_MAX * B)))
            accel -= A_MAX * (s_star / gap) ** 2
            need = dv * dv / (2.0 * max(gap - 1.0, 0.1)) if dv > 0.0 else 0.0  # [m/s^2]
            accel = max(accel, -max(B, need))  # no harder than B unless kinematics need it
            if v < 1.0 and lead[1] < 0.5 and gap < S0 + 1.0:  # behind a standing lead:
                accel = -B  # stop and hold (the IDM only nears s0 asymptotically)
        rear = self.ctx.vehicle.rear_axle
        rx, ry = g.x - rear * math.cos(g.heading), g.y - rear * math.sin(g.heading)
        look = K * v + L0
        px, py = (float(p) for p in self.lane.position(s + look, 0.0))
        alpha = math.atan2(py - ry, px - rx) - g.heading
        steer = math.atan2(2.0 * self.ctx.vehicle.wheelbase * math.sin(alpha),
                           math.hypot(px - rx, py - ry))
        steer = max(-self.ctx.vehicle.max_steer, min(steer, self.ctx.vehicle.max_steer))
        command = drive_by_wire(steer, max(-8.0, accel), v, self.ctx.vehicle)
        return StackStep(command, channels={"idm_accel": accel, "lookahead": look})


def make(ctx: StackContext) -> IdmPurePursuit:
    return IdmPurePursuit(ctx)
