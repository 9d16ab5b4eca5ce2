"""Scenery roads as textured meshes: roads drawn in the world but not on the HD map the stack
reads (`world.spec.WorldSpec.scenery_roads`: an OpenDRIVE dual carriageway's far side).

Each is laid out as a map of its own (`world.map.road.build_road_map`) and drawn as the
route is: its surface with the lines painted in the texture (`world.scene.road_mesh`) and
its stop lines and crosswalks (`world.scene.road_marks`), at the same heights (a scenery
road lies beside the route, not on it: a median between). Mesh names are prefixed
`scenery<k>_` (k: the road's index) to keep them unique in the world.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from world.map.road import build_road_map
from world.scene.road_marks import build_road_marks
from world.scene.road_mesh import TexturedMesh, build_road_surface
from world.spec import RoadSpec


def build_scenery_roads(roads: Sequence[RoadSpec]) -> list[TexturedMesh]:
    """The surface and marks of each scenery road, in order (module doc); `MapError` for a
    road that cannot be laid out."""
    meshes: list[TexturedMesh] = []
    for k, spec in enumerate(roads):
        road_map = build_road_map(spec)
        meshes += [replace(mesh, name=f"scenery{k}_{mesh.name}")
                   for mesh in (*build_road_surface(road_map), *build_road_marks(road_map))]
    return meshes
