"""The environment the world's sensors and road meet: light, visibility, precipitation and the
road's friction.

A `SceneEnvironment` is what the world renders and simulates; the scenario (an OpenSCENARIO
storyboard's EnvironmentAction, `avsim.run.environment`) sets it at run time. `CLEAR` (the
default) is clear daylight on dry asphalt: the cameras render exactly as without any
environment, the LiDAR meets clear air, and the road has its dry friction.

The laws, each a function here:

- Koschmieder's law: a black object is seen against the horizon sky down to a contrast of
  2 %, so the meteorological visual range V [m] and the atmosphere's extinction coefficient
  alpha [1/m] are related by alpha = -ln(0.02) / V = 3.912 / V; light crossing a distance d
  keeps the fraction exp(-alpha d) (Beer-Lambert).
- Rain and snow: ITU-R P.1814's specific attenuations for optical wavelengths, rain
  gamma = 1.076 R^0.67 dB/km and dry snow gamma = a S^0.72 dB/km with a = 1.023e-4 lambda
  + 3.7855 (lambda [nm], 3.84 at 550 nm), R and S the water-equivalent rate [mm/h]; as an
  extinction coefficient alpha = gamma / (10 log10 e) [1/km]. Extinctions add up (fog and
  rain together).
- Light: the scene's horizontal illuminance [lx]. Where the scenario gives none, it follows
  the sun's elevation through daylight and twilight (`sky_illuminance`: typical clear-sky
  values, about 400 lx at sunset, 3 lx at the end of civil twilight, -6 deg, a thousandth
  of a lux at night), reduced by clouds by Kasten and Czeplak's (1980) factor
  1 - 0.75 (N / 8)^3.4 (N the cloud cover in oktas); the sun's elevation, where only a time
  of day is given, is the solar elevation at `REFERENCE_LATITUDE` with the clock taken as
  local solar time and Cooper's (1969) declination.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

KOSCHMIEDER = -math.log(0.02)  # [-] 3.912: the 2 % contrast threshold of the visual range
DAYLIGHT = 1.0e5  # [lx] a clear sky's horizontal illuminance at a high sun (the default)
NO_FOG = math.inf  # [m] the visual range of clear air (no extinction)
MIN_VISUAL_RANGE = 0.1  # [m] a visual range below this is taken as this (a finite extinction)
DB_PER_NEPER = 10.0 * math.log10(math.e)  # [dB] 4.343: dB of attenuation per unit of optical depth
RAIN_GAMMA = (1.076, 0.67)  # ITU-R P.1814 rain: gamma [dB/km] = k R^a, R [mm/h]
SNOW_GAMMA = (1.023e-4 * 550.0 + 3.7855466, 0.72)  # ITU-R P.1814 dry snow at 550 nm
REFERENCE_LATITUDE = math.radians(48.0)  # [rad] where a bare time of day places the sun
#   (central Europe: the NCAP and UN R157 test sites)
TWILIGHT = (  # (sun elevation [deg], log10 of the clear-sky horizontal illuminance [lx])
    (-18.0, -3.0),  # astronomical night: starlight and airglow, 0.001 lx
    (-12.0, -2.0),  # end of nautical twilight
    (-6.0, 0.53),  # end of civil twilight: 3.4 lx
    (0.0, 2.6),  # sunset: 400 lx
    (5.0, 3.7),
    (10.0, 4.2),
    (20.0, 4.55),
    (40.0, 4.85),
    (90.0, 5.0),  # high sun: 100 klx
)


@dataclass(frozen=True, slots=True)
class SceneEnvironment:
    """The environment in effect (module doc). SI units; frames: the map's (x east, y north
    for the sun's azimuth only as a recorded quantity: nothing casts shadows)."""

    illuminance: float = DAYLIGHT  # [lx] horizontal illuminance of the scene
    sun_elevation: float = math.radians(60.0)  # [rad] above the horizon
    sun_azimuth: float = 0.0  # [rad] from north, clockwise seen from above
    fog_visual_range: float = NO_FOG  # [m] meteorological visual range of the fog
    precipitation: float = 0.0  # [mm/h] water-equivalent precipitation rate
    snow: bool = False  # the precipitation is snow (else rain)
    friction_scale: float = 1.0  # [-] on the road's dry friction (ground, bumps, kerbs)

    @property
    def extinction(self) -> float:
        """[1/m] the air's extinction coefficient: fog's (Koschmieder) plus the
        precipitation's (ITU-R P.1814)."""
        fog = 0.0 if math.isinf(self.fog_visual_range) else fog_extinction(
            self.fog_visual_range)
        return fog + precipitation_extinction(self.precipitation, self.snow)

    @property
    def visual_range(self) -> float:
        """[m] the meteorological visual range of the air, fog and precipitation together
        (inf: clear air)."""
        alpha = self.extinction
        return KOSCHMIEDER / alpha if alpha > 0.0 else NO_FOG


CLEAR = SceneEnvironment()  # clear daylight, dry road: what a world has unless told


def fog_extinction(visual_range: float) -> float:
    """[1/m] Koschmieder: alpha = 3.912 / V for a visual range V [m] (at least
    `MIN_VISUAL_RANGE`)."""
    return KOSCHMIEDER / max(visual_range, MIN_VISUAL_RANGE)


def precipitation_extinction(rate: float, snow: bool = False) -> float:
    """[1/m] the extinction of rain (or dry snow) falling at `rate` [mm/h] water equivalent,
    ITU-R P.1814 (module doc); 0 for no precipitation."""
    if rate <= 0.0:
        return 0.0
    k, a = SNOW_GAMMA if snow else RAIN_GAMMA
    return float(k * rate**a / DB_PER_NEPER / 1000.0)


def transmission(distance: float, extinction: float) -> float:
    """[-] Beer-Lambert: the fraction of light left after `distance` [m] through air of
    `extinction` [1/m]."""
    return math.exp(-extinction * distance)


def sky_illuminance(elevation: float) -> float:
    """[lx] a clear sky's horizontal illuminance with the sun `elevation` [rad] above the
    horizon (below: twilight, night), interpolated in log10 over `TWILIGHT`."""
    degrees, logs = zip(*TWILIGHT, strict=True)
    return float(10.0 ** np.interp(math.degrees(elevation), degrees, logs))


def cloud_factor(oktas: float) -> float:
    """[-] Kasten and Czeplak (1980): the share of the clear sky's light left under `oktas`
    (0 to 8) of cloud cover."""
    return float(1.0 - 0.75 * (min(max(oktas, 0.0), 8.0) / 8.0) ** 3.4)


def solar_elevation(epoch: float, latitude: float = REFERENCE_LATITUDE) -> float:
    """[rad] the sun's elevation at `epoch` [s since 1970-01-01 UTC, its clock taken as local
    solar time] at `latitude` [rad]: sin e = sin(phi) sin(delta) + cos(phi) cos(delta) cos(h),
    delta Cooper's declination 23.45 deg sin(2 pi (284 + N) / 365) on day N of the year, h the
    hour angle 15 deg per hour from noon."""
    days, seconds = divmod(epoch, 86400.0)
    day_of_year = days % 365.2425 + 1.0  # [days] 1970-01-01 is day 1
    declination = math.radians(23.45) * math.sin(2.0 * math.pi * (284.0 + day_of_year) / 365.0)
    hour_angle = 2.0 * math.pi * (seconds / 86400.0 - 0.5)
    sine = (math.sin(latitude) * math.sin(declination)
            + math.cos(latitude) * math.cos(declination) * math.cos(hour_angle))
    return math.asin(max(-1.0, min(1.0, sine)))
