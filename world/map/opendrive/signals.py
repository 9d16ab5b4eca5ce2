"""OpenDRIVE road signals (`<signals>/<signal>`) as frozen dataclasses (SI units: m, rad, m/s).

A signal stands at road coordinates (s, t) of its road [m], its sign `z_offset` above the
road surface [m]. `orientation` says which traffic it is for: "+" the traffic in the road's
direction of increasing s, "-" the other way, "none" both. A static speed-limit sign (German
StVO type 274, the type the real files post) carries its limit in `value` / `unit`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

SPEED_LIMIT_TYPE = "274"  # StVO 274 "Zulässige Höchstgeschwindigkeit": the limit from here on


@dataclass(frozen=True, slots=True)
class RoadSignal:
    """One static `<signal>` of a road (module doc)."""

    id: str
    name: str
    s: float  # [m] on its road
    t: float  # [m] left-positive
    z_offset: float  # [m] of the sign's bottom above the road surface
    orientation: Literal["+", "-", "none"]
    country: str  # "DE", "OpenDRIVE", ... ("" not given)
    type: str  # "274", ...
    subtype: str  # "-1", "62", ...
    value: float | None  # [m/s] for a speed limit (its `value` in its `unit`), else as given
    height: float | None  # [m] of the sign
    width: float | None  # [m] of the sign

    @property
    def speed_limit(self) -> float | None:
        """[m/s] the limit a speed-limit sign posts (None: another kind of signal)."""
        return self.value if self.type == SPEED_LIMIT_TYPE else None

    def applies_forward(self) -> bool:
        """Whether it is for the traffic in the direction of increasing s."""
        return self.orientation in ("+", "none")
