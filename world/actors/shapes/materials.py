"""The materials bodies are made of: a flat colour for the cameras and a LiDAR reflectivity.

Reflectivity is the diffuse (Lambertian) reflectance at a LiDAR's near-infrared wavelength
(905 nm), in [0, 1]: the share of the beam a surface facing it returns. The figures are
representative round values, not a measurement of one vehicle: what matters for the stack
is their order (retro-reflective plates and light paint return much, skin and cloth about
half, black rubber, trim and glass little: glass mostly transmits or mirrors the beam away).
ISO 19206-2 / -3 / -4 / -5 ask the Euro NCAP targets to return what the real road user
returns, so the targets use the same table.

Colours are linear RGB in [0, 1] (the renderer's flat material colour).
"""

from __future__ import annotations

from dataclasses import dataclass

Rgb = tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class Material:
    """One material: its name, colour and LiDAR reflectivity."""

    name: str
    rgb: Rgb  # [-] linear RGB, each in [0, 1]
    reflectivity: float  # [-] diffuse reflectance at 905 nm, in [0, 1]
    what: str  # what it stands for


MATERIALS: dict[str, Material] = {m.name: m for m in (
    Material("paint", (0.55, 0.57, 0.60), 0.50, "body paint (mid grey; the world may recolour)"),
    Material("glass", (0.04, 0.06, 0.08), 0.05, "tinted glazing: dark to a camera, weak return"),
    Material("tyre", (0.03, 0.03, 0.03), 0.05, "carbon-black rubber"),
    Material("trim", (0.08, 0.08, 0.09), 0.10, "black plastic: bumpers' lower band, grilles, "
             "mirrors, saddles, handlebars"),
    Material("lamp", (0.95, 0.92, 0.80), 0.30, "lamp lens (head and tail lamps alike)"),
    Material("plate", (0.95, 0.95, 0.90), 0.90, "retro-reflective licence plate"),
    Material("metal", (0.70, 0.70, 0.72), 0.50, "bare or painted metal: frames, forks, rims"),
    Material("skin", (0.80, 0.62, 0.50), 0.45, "skin: face and hands"),
    Material("cloth", (0.15, 0.20, 0.35), 0.40, "clothing"),
    Material("hair", (0.10, 0.07, 0.05), 0.15, "hair, or a helmet's dark shell"),
)}


def material(name: str) -> Material:
    """The material `name` (KeyError naming the known ones otherwise)."""
    try:
        return MATERIALS[name]
    except KeyError:
        raise KeyError(f"unknown material {name!r} "
                       f"(expected one of {', '.join(MATERIALS)})") from None
