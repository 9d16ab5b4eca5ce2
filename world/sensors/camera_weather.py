"""What a camera makes of the environment (`world.environment.SceneEnvironment`): fog and
precipitation from the depth buffer, darkness through its auto-exposure, and the sensor's
noise at the gain it needs.

Applied to each rendered image, in this order, all vectorised over the image:

1. Extinction (fog, rain, snow): Koschmieder's model of a uniformly lit atmosphere. The
   depth buffer b (0..1) Bullet returns with the image is linearised with the projection's
   near and far planes, z = far near / (far - (far - near) b) [m] along the optical axis, and
   made the distance along each pixel's ray, d = z sqrt(1 + x^2 + y^2) (x, y the pixel's
   normalised image coordinates, tan of its angles). The scene's light is attenuated by the
   transmission t = exp(-alpha d) and the airlight fills the rest:
   pixel = t pixel + (1 - t) `AIRLIGHT`; the sky (nothing drawn: beyond the far plane) is
   airlight alone. alpha is the environment's extinction (fog 3.912 / V plus the
   precipitation's, `world.environment`). Falling drops are not drawn (no streaks, no
   drops on the lens): precipitation is a loss of contrast with distance only.
2. Darkness: an automotive camera's auto-exposure keeps the daylight image's brightness by
   its exposure time down to `FULL_EXPOSURE` lux, then by its analogue gain
   g = FULL_EXPOSURE / E up to `MAX_GAIN` (36 dB); below FULL_EXPOSURE / MAX_GAIN (16 lx)
   the image darkens in proportion to the light, brightness = MAX_GAIN E / FULL_EXPOSURE.
   On a log scale of illuminance: full brightness down to 16 lx, then 1 decade of light per
   decade of brightness. The airlight darkens with the scene (there is no other light: the
   car's headlights are not modelled, nor street lights).
3. Noise: photon shot noise and read noise in digital numbers (DN, 0..255), the full well
   `FULL_WELL` electrons at 255 DN at unit gain, so k0 = 255 / FULL_WELL DN per electron. At
   gain g a signal of s DN holds s / (g k0) electrons: shot variance g k0 s, read variance
   (g k0 READ_NOISE)^2. The renderer's daylight image is taken as the unit-gain image (its
   noise, 1-2 DN, below what it resolves), so what is added is the difference: a Gaussian
   of variance (g - 1) k0 s + (g^2 - 1) (k0 READ_NOISE)^2, none at unit gain. Its unit
   normal samples are a window into a bank of `BANK_EXTRA` more than a frame's samples drawn
   once per camera (drawing a frame's worth cost 19 ms, more than the rest together), at
   an offset drawn per frame: neighbouring pixels' noise is independent, and a frame's
   differs from the last's. Bank and offset come from generators seeded by the run's seed,
   the camera and the frame's time: the same run gives the same images, bit for bit, in
   whichever process renders them.

The image in clear daylight (no extinction, at least FULL_EXPOSURE lux) is returned
untouched: not even rounded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from world.environment import SceneEnvironment
from world.frames import CameraInfo

FULL_EXPOSURE = 1000.0  # [lx] the auto-exposure's longest exposure reaches daylight's image
#   brightness down to this (an overcast day's light)
MAX_GAIN = 64.0  # [-] the analogue gain's top (36 dB)
FULL_WELL = 10000.0  # [e-] electrons at 255 DN at unit gain
READ_NOISE = 5.0  # [e-] 1-sigma read noise
BANK_EXTRA = 1 << 16  # [samples] the noise bank's length beyond a frame's samples
AIRLIGHT = np.array([200.0, 204.0, 210.0], dtype=np.float32)  # [DN] the fog's colour in
#   daylight: a bright, slightly blue grey


@dataclass(frozen=True, slots=True)
class Exposure:
    """The auto-exposure's answer to the scene's light."""

    gain: float  # [-] analogue gain, 1 to MAX_GAIN
    brightness: float  # [-] the image's brightness relative to the daylight image, 0 to 1


def exposure(illuminance: float) -> Exposure:
    """The auto-exposure at `illuminance` [lx] (module doc, step 2)."""
    light = max(illuminance, 0.0) / FULL_EXPOSURE
    if light >= 1.0:
        return Exposure(1.0, 1.0)
    gain = min(1.0 / light, MAX_GAIN) if light > 0.0 else MAX_GAIN
    return Exposure(gain, min(1.0, gain * light))


def noise_sigma(signal: NDArray[np.float32] | float, gain: float) -> NDArray[np.float32] | float:
    """[DN] 1-sigma of the noise added at `gain` to a signal of `signal` [DN] (step 3)."""
    k0 = 255.0 / FULL_WELL
    variance = np.multiply(signal, np.float32((gain - 1.0) * k0))
    variance += np.float32((gain * gain - 1.0) * (k0 * READ_NOISE) ** 2)
    return np.sqrt(variance)


def affects(env: SceneEnvironment) -> bool:
    """Whether the camera's image differs from the clear daylight one in `env`."""
    return env.extinction > 0.0 or env.illuminance < FULL_EXPOSURE


class CameraWeather:
    """The module's steps for one camera's images (its rays' lengths computed once)."""

    def __init__(self, info: CameraInfo) -> None:
        self.info = info
        u = (np.arange(info.width, dtype=np.float64) + 0.5 - info.cx) / info.fx
        v = (np.arange(info.height, dtype=np.float64) + 0.5 - info.cy) / info.fy
        self._ray = np.sqrt(1.0 + u[None, :] ** 2 + v[:, None] ** 2).astype(np.float32)
        #   [-] a pixel's ray length per metre of depth along the optical axis
        self._bank: NDArray[np.float32] | None = None  # unit normal samples (module doc)

    def distance(self, depth_buffer: NDArray[np.float32]) -> NDArray[np.float32]:
        """[m] along each pixel's ray to what it sees (inf: the sky, beyond the far plane),
        from Bullet's depth buffer (0..1) by the projection's near and far planes."""
        near, far = self.info.near, self.info.far
        d = np.multiply(depth_buffer, np.float32(-(far - near)))
        d += np.float32(far)
        np.divide(np.float32(far * near), d, out=d)  # z along the optical axis
        d *= self._ray
        d[depth_buffer >= 1.0] = np.inf
        return d

    def apply(self, rgb: NDArray[np.uint8], depth_buffer: NDArray[np.float32],
              env: SceneEnvironment, seed: tuple[int, ...]) -> NDArray[np.uint8]:
        """The image `rgb` (height, width, 3) with its depth buffer (height, width) seen in
        `env`; `seed`: the noise generator's entropy (the run's seed, the camera, the
        frame)."""
        if not affects(env):
            return rgb
        image = rgb.astype(np.float32)
        alpha = env.extinction
        if alpha > 0.0:
            t = self.distance(depth_buffer)
            t *= np.float32(-alpha)
            np.exp(t, out=t)  # the sky's inf -> 0: airlight alone
            image -= AIRLIGHT  # t pixel + (1 - t) airlight, in place
            image *= t[..., None]
            image += AIRLIGHT
        exp = exposure(env.illuminance)
        if exp.brightness < 1.0:
            image *= np.float32(exp.brightness)
        if exp.gain > 1.0:
            sigma = noise_sigma(image, exp.gain)
            sigma *= self._unit_noise(image.size, seed).reshape(image.shape)
            image += sigma
        np.clip(image, 0.0, 255.0, out=image)
        image += np.float32(0.5)  # rounded to the nearest DN by the truncation below
        return image.astype(np.uint8)

    def _unit_noise(self, size: int, seed: tuple[int, ...]) -> NDArray[np.float32]:
        """`size` unit normal samples for the frame of `seed` (module doc, step 3): the bank
        is drawn from the camera's part of the seed (all but the frame's time) once."""
        if self._bank is None or len(self._bank) < size + BANK_EXTRA:
            bank = np.random.default_rng(np.random.SeedSequence(list(seed[:-1]), spawn_key=(1,)))
            self._bank = bank.standard_normal(size + BANK_EXTRA, dtype=np.float32)
        offset = int(np.random.default_rng(np.random.SeedSequence(list(seed))).integers(
            0, BANK_EXTRA + 1))
        return self._bank[offset:offset + size]


def frame_key(t: float) -> int:
    """[us] a frame's time as a non-negative integer (part of its noise seed)."""
    return max(0, math.floor(t * 1.0e6 + 0.5))
