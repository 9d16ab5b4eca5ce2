"""Traffic-light timing: which lamp is lit when (ground truth).

The world lights the lamps by it and the criteria judge by it; the stack never reads it
(it sees the lamps only through the camera, `perception.lights`).
"""

from __future__ import annotations

from dataclasses import replace

from world.hdmap import LightColour, RoadMap
from world.map.road import light_head
from world.spec import RoadSpec, TrafficLightSpec


def light_colour(light: TrafficLightSpec, t: float) -> LightColour:
    """The lit lamp of `light` at simulated time t [s]: the cycle starts green, then
    yellow, then red; `phase` is the time into the cycle at t = 0."""
    into = (t + light.phase) % light.cycle
    if into < light.green:
        return LightColour.GREEN
    if into < light.green + light.yellow:
        return LightColour.YELLOW
    return LightColour.RED


def route_signals(spec: RoadSpec, road: RoadMap) -> tuple[TrafficLightSpec, ...]:
    """The traffic lights of the route road `spec` with their signal plans, by station, each
    with its head where the map (`road`, built from `spec`) placed it."""
    lights = sorted((f for f in spec.features if isinstance(f, TrafficLightSpec)),
                    key=lambda f: f.s)
    return tuple(replace(f, head=light_head(road, f)) for f in lights)
