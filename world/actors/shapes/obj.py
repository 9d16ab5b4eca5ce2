"""A body as Wavefront OBJ text with its MTL material library.

One `g` group per part (its name) with `usemtl` of its material; vertices in metres in the
body frame, 6 decimals (1 um), faces counter-clockwise seen from outside. The MTL gives each
material used its flat colour (`Kd`) and, as a comment, its LiDAR reflectivity.
"""

from __future__ import annotations

from world.actors.shapes.body import Body
from world.actors.shapes.materials import MATERIALS
from world.actors.shapes.mesh import part_mesh


def _num(v: float) -> str:
    return f"{round(v, 6) + 0.0:.6f}"


def obj_text(body: Body) -> str:
    """The body's OBJ file."""
    lines = [f"# {body.name}: {body.length} x {body.width} x {body.height} m; "
             "x forward, y left, z up, origin on the ground at the footprint's centre",
             f"mtllib {body.name}.mtl", f"o {body.name}"]
    base = 1
    for part in body.parts:
        vertices, triangles = part_mesh(part)
        lines += [f"g {part.name}", f"usemtl {part.material}"]
        lines += [f"v {_num(x)} {_num(y)} {_num(z)}" for x, y, z in vertices]
        lines += [f"f {a + base} {b + base} {c + base}" for a, b, c in triangles]
        base += len(vertices)
    return "\n".join(lines) + "\n"


def mtl_text(body: Body) -> str:
    """The body's MTL file: the materials its parts use, in the table's order."""
    used = {p.material for p in body.parts}
    lines = [f"# materials of {body.name}"]
    for m in MATERIALS.values():
        if m.name in used:
            r, g, b = m.rgb
            lines += ["", f"newmtl {m.name}", f"# {m.what}; LiDAR reflectivity {m.reflectivity}",
                      f"Kd {r:.3f} {g:.3f} {b:.3f}", "Ka 0.000 0.000 0.000",
                      "Ks 0.000 0.000 0.000", "d 1.0", "illum 1"]
    return "\n".join(lines) + "\n"
