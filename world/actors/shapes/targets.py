"""Euro NCAP's test targets: their dimensions and where they come from.

Euro NCAP's AEB test protocols (AEB Car-to-Car v4.3.1, AEB/LSS VRU v4.5.1) use the targets
of ISO 19206: the Global Vehicle Target (ISO 19206-3, "Requirements for passenger vehicle 3D
targets"), the adult and child pedestrian targets EPTa / EPTc (ISO 19206-2, "Requirements
for pedestrian targets"), the bicyclist target EBTa (ISO 19206-4, "Requirements for
bicyclist targets") and the motorcyclist target EMT (ISO 19206-5, "Requirements for
powered-two-wheeler targets"). The figures below are those of the targets' entries in the
Euro NCAP OpenSCENARIO catalogues ("Vehicle Catalog for NCAP Scenarios" and its pedestrian
catalogue, Vector Informatik, MPL-2.0, vendored in `tests/data/ncap/`): bounding box,
wheelbase and wheel diameter. Those catalogues give the bicycle and the motorcycle without
their rider; the riders' head heights below are derived here (an EPTa-proportioned adult
seated on the vehicle), not published figures.
"""

from __future__ import annotations

from dataclasses import dataclass

CATALOGUE = "Euro NCAP OpenSCENARIO catalogue (Vector, 2024-2026), entry "


@dataclass(frozen=True, slots=True)
class Target:
    """A target's envelope [m] and its source."""

    name: str
    length: float  # [m] along x
    width: float  # [m] along y
    height: float  # [m]
    source: str


GVT = Target("ncap_gvt", 4.023, 1.712, 1.427,
             "ISO 19206-3 Global Vehicle Target; " + CATALOGUE + "NCAP_GlobalVehicleTarget: "
             "4.023 x 1.712 x 1.427 m, wheelbase 2.475 m, wheels 0.656 m, track 1.434 m, "
             "rear overhang 0.6835 m")
GVT_WHEELBASE, GVT_WHEEL_DIAMETER, GVT_REAR_OVERHANG = 2.475, 0.656, 0.6835  # [m]

EPTA = Target("ncap_epta", 0.60, 0.50, 1.80,
              "ISO 19206-2 adult pedestrian target EPTa; " + CATALOGUE + "NCAP_Adult: "
              "0.6 x 0.5 x 1.8 m")
EPTC = Target("ncap_eptc", 0.711, 0.298, 1.154,
              "ISO 19206-2 child pedestrian target EPTc; " + CATALOGUE + "NCAP_Child: "
              "0.711 x 0.298 x 1.154 m")

EBTA = Target("ncap_ebta", 1.89, 0.50, 1.75,
              "ISO 19206-4 bicyclist target EBTa; " + CATALOGUE + "NCAP_Bicycle: 1.89 x 0.5 x "
              "1.2 m, wheelbase 1.21 m, wheels 0.68 m; rider: an EPTa-proportioned adult "
              "(1.80 m), head top at 1.75 m (derived)")
EBTA_BARS, EBTA_WHEELBASE, EBTA_WHEEL_DIAMETER = 1.2, 1.21, 0.68  # [m]

EMT = Target("ncap_emt", 2.08, 0.79, 1.55,
             "ISO 19206-5 motorcyclist target EMT; " + CATALOGUE + "NCAP_Motorcycle: 2.08 x "
             "0.79 x 1.06 m, wheelbase 1.41 m, wheels 0.606 m (front) and 0.62 m (rear); "
             "rider: an EPTa-proportioned adult (1.80 m), head top at 1.55 m (derived)")
EMT_BIKE_HEIGHT, EMT_WHEELBASE = 1.06, 1.41  # [m]
EMT_FRONT_WHEEL, EMT_REAR_WHEEL = 0.606, 0.62  # [m] diameters
RIDER_STATURE = 1.80  # [m] the EPTa's
