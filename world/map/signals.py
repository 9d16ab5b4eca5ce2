"""Traffic-light timing: which lamp is lit when (ground truth).

The world lights the lamps by it and the criteria judge by it; the stack never reads it
(it sees the lamps only through the camera, `perception.lights`).
"""

from __future__ import annotations

from world.spec import LightColour, TrafficLight


def light_colour(light: TrafficLight, t: float) -> LightColour:
    """The lit lamp of `light` at simulated time t [s]: the cycle starts green, then
    yellow, then red; `phase` is the time into the cycle at t = 0."""
    into = (t + light.phase) % light.cycle
    if into < light.green:
        return LightColour.GREEN
    if into < light.green + light.yellow:
        return LightColour.YELLOW
    return LightColour.RED
