"""The bodies' shapes (`world.actors.shapes`): dimensions, convex parts, silhouettes, gait,
materials, and the committed OBJ files in `assets/shapes/`."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import ConvexHull as Qhull

from world.actors.catalogue import CATALOGUE
from world.actors.shapes import targets
from world.actors.shapes.body import Body
from world.actors.shapes.catalogue import GAIT_PHASES, bodies, pedestrian
from world.actors.shapes.export import export
from world.actors.shapes.humans import pedestrian_parts
from world.actors.shapes.materials import MATERIALS
from world.actors.shapes.measure import bounds, filled_fraction, first_hit, triangle_count
from world.actors.shapes.parts import points
from world.scene.solids import Cylinder

REPO = Path(__file__).resolve().parents[3]
ASSETS = REPO / "assets" / "shapes"
BODIES = bodies()
RIGID = [b for b in BODIES.values() if "_phase" not in b.name]
WALKERS = [b for b in BODIES.values() if "_phase" in b.name]
MM = 1e-3  # [m]


def test_every_catalogue_model_and_target_has_a_shape() -> None:
    names = set(BODIES)
    assert set(CATALOGUE) <= names
    assert {"ncap_gvt", "ncap_ebta", "ncap_emt"} <= names
    for target in (targets.EPTA, targets.EPTC):
        assert {f"{target.name}_phase{k}" for k in range(GAIT_PHASES)} <= names


@pytest.mark.parametrize("body", RIGID, ids=lambda b: b.name)
def test_the_bounding_box_is_the_published_one(body: Body) -> None:
    lo, hi = bounds(body.parts)
    np.testing.assert_allclose(lo, [-body.length / 2, -body.width / 2, 0.0], atol=MM)
    np.testing.assert_allclose(hi, [body.length / 2, body.width / 2, body.height], atol=MM)


def test_catalogue_dimensions_are_the_models() -> None:
    for m in CATALOGUE.values():
        b = BODIES[m.name]
        assert (b.length, b.width, b.height) == (m.length, m.width, m.height)


@pytest.mark.parametrize("body", list(BODIES.values()), ids=lambda b: b.name)
def test_every_part_is_a_solid_convex_body_with_a_known_material(body: Body) -> None:
    names = [p.name for p in body.parts]
    assert len(names) == len(set(names))
    for part in body.parts:
        assert Qhull(points(part)).volume > 1e-6, part.name
        m = MATERIALS[part.material]
        assert all(0.0 <= c <= 1.0 for c in m.rgb) and 0.0 <= m.reflectivity <= 1.0


@pytest.mark.parametrize("body", list(BODIES.values()), ids=lambda b: b.name)
def test_each_body_stays_under_the_triangle_budget(body: Body) -> None:
    assert triangle_count(body.parts) < 2000


def _wheels(body: Body) -> list[tuple[float, float]]:
    """(x, bottom z) of each wheel."""
    return [(float(p.position[0]), float(points(p)[:, 2].min()))
            for p in body.parts if isinstance(p.solid, Cylinder) and p.material == "tyre"]


@pytest.mark.parametrize("name", sorted(CATALOGUE))
def test_wheels_stand_on_the_ground_at_the_wheelbase(name: str) -> None:
    body, model = BODIES[name], CATALOGUE[name]
    wheels = _wheels(body)
    assert len(wheels) >= (2 if name == "motorbike" else 4)
    assert all(abs(z) < MM for _, z in wheels)
    xs = sorted({round(x, 6) for x, _ in wheels}, reverse=True)
    assert xs[0] - xs[1] == pytest.approx(model.wheelbase, abs=MM)


def test_the_gvt_wheels_are_at_its_published_wheelbase() -> None:
    xs = sorted({round(x, 6) for x, _ in _wheels(BODIES["ncap_gvt"])})
    assert xs[1] - xs[0] == pytest.approx(targets.GVT_WHEELBASE, abs=MM)


def test_a_saloon_is_not_a_box() -> None:
    sedan = BODIES["sedan"]
    assert 0.55 < filled_fraction(sedan.parts) < 0.85
    roof = next(p for p in sedan.parts if p.name == "roof")
    assert np.ptp(points(roof)[:, 1]) < 0.9 * sedan.width


def test_a_camera_sees_glass_ahead_and_aside_and_paint_above() -> None:
    sedan = BODIES["sedan"]
    glass = next(p for p in sedan.parts if p.name == "glass")
    z = float(np.mean(points(glass)[:, 2]))  # mid-window height
    x = float(np.mean(points(glass)[:, 0]))
    ahead = first_hit(sedan.parts, (10.0, 0.0, z), (-1.0, 0.0, 0.0))
    aside = first_hit(sedan.parts, (x + 0.3, 10.0, z), (0.0, -1.0, 0.0))
    above = first_hit(sedan.parts, (x, 0.0, 10.0), (0.0, 0.0, -1.0))
    assert ahead is not None and ahead.material == "glass"
    assert aside is not None and aside.material == "glass"
    assert above is not None and above.material == "paint"


@pytest.mark.parametrize("name", ["ncap_ebta", "ncap_emt", "motorbike"])
def test_two_wheelers_are_mostly_empty(name: str) -> None:
    assert filled_fraction(BODIES[name].parts) < 0.35


@pytest.mark.parametrize("target", [targets.EPTA, targets.EPTC], ids=lambda t: t.name)
def test_a_walker_stays_inside_its_envelope_at_every_phase(target: targets.Target) -> None:
    for k in range(32):
        lo, hi = bounds(pedestrian_parts(target.height, k / 32, target.width))
        assert np.all(lo >= [-target.length / 2 - 1e-9, -target.width / 2 - 1e-9, -1e-9])
        assert np.all(hi <= [target.length / 2 + 1e-9, target.width / 2 + 1e-9,
                             target.height + 1e-9])
        assert lo[2] == pytest.approx(0.0, abs=1e-9)  # a foot on the ground


def _feet_bottoms(body: Body) -> list[float]:
    return [float(points(p)[:, 2].min()) for p in body.parts if p.name.endswith("_foot")]


def test_the_legs_move_with_the_phase_and_both_feet_land_in_double_support() -> None:
    a, b = pedestrian(targets.EPTA, 0.0), pedestrian(targets.EPTA, 0.25)
    for name in ("left_foot", "right_shank", "left_arm"):
        pa = next(p for p in a.parts if p.name == name)
        pb = next(p for p in b.parts if p.name == name)
        assert np.abs(points(pa) - points(pb)).max() > 0.02, name
    assert _feet_bottoms(a) == pytest.approx([0.0, 0.0], abs=1e-9)
    assert max(_feet_bottoms(b)) > 0.01  # mid stance: the swinging foot is off the ground
    assert bounds(b.parts)[1][2] == pytest.approx(targets.EPTA.height, abs=0.01)


def test_the_material_table_is_complete() -> None:
    used = {p.material for b in BODIES.values() for p in b.parts}
    assert used <= set(MATERIALS)
    assert {"paint", "glass", "tyre", "lamp", "skin", "cloth"} <= used


def test_the_committed_assets_are_what_the_code_makes(tmp_path: Path) -> None:
    written = export(tmp_path)
    assert sorted(p.name for p in ASSETS.glob("*.obj")) == sorted(
        p.name for p in written if p.suffix == ".obj")
    for path in written:
        assert (ASSETS / path.name).read_bytes() == path.read_bytes(), path.name


def _parse_obj(text: str) -> tuple[np.ndarray, dict[str, list[tuple[int, int, int]]],
                                   dict[str, str]]:
    """Vertices, faces (1-based) by group, and each group's material."""
    vertices: list[list[float]] = []
    faces: dict[str, list[tuple[int, int, int]]] = {}
    materials: dict[str, str] = {}
    group = ""
    for line in text.splitlines():
        word, *rest = line.split() or [""]
        if word == "v":
            vertices.append([float(v) for v in rest])
        elif word == "g":
            group = rest[0]
            faces[group] = []
        elif word == "usemtl":
            materials[group] = rest[0]
        elif word == "f":
            faces[group].append((int(rest[0]), int(rest[1]), int(rest[2])))
    return np.array(vertices), faces, materials


@pytest.mark.parametrize("obj", sorted(ASSETS.glob("*.obj")), ids=lambda p: p.stem)
def test_each_asset_loads_back_as_closed_outward_meshes(obj: Path) -> None:
    vertices, faces, materials = _parse_obj(obj.read_text(encoding="utf-8"))
    mtl = obj.with_suffix(".mtl").read_text(encoding="utf-8")
    assert faces and set(faces) == set(materials)
    for group, tri in faces.items():
        assert f"newmtl {materials[group]}" in mtl
        edges: dict[tuple[int, int], int] = {}
        for a, b, c in tri:
            for e in ((a, b), (b, c), (c, a)):
                edges[e] = edges.get(e, 0) + 1
        # closed and consistently wound: every edge once each way
        assert all(n == 1 and edges.get((b, a)) == 1 for (a, b), n in edges.items()), group
        t = np.array(tri) - 1
        p0, p1, p2 = vertices[t[:, 0]], vertices[t[:, 1]], vertices[t[:, 2]]
        signed = np.einsum("ij,ij->i", p0, np.cross(p1, p2)).sum() / 6.0
        assert signed > 0.0, group  # outward normals enclose a positive volume
