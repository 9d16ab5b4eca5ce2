"""Reading Entities: ScenarioObjects with their Vehicle/Pedestrian/MiscObject (inline or from
a catalog) and their ObjectController."""

from __future__ import annotations

from collections.abc import Callable

from avsim.scenario.errors import fmt
from avsim.scenario.openscenario.attributes import unsupported
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.entities import (
    Axle,
    BoundingBox,
    Controller,
    Entity,
    EntityObject,
    MiscObject,
    Pedestrian,
    Vehicle,
)
from avsim.scenario.openscenario.limits import MAX_BOX_HEIGHT, MAX_BOX_LENGTH, MAX_BOX_WIDTH
from avsim.scenario.openscenario.xmlread import Node

OBJECT_KINDS = ("Vehicle", "Pedestrian", "MiscObject")


def _size(node: Node, ctx: Context, name: str, most: float) -> float:
    """[m] a bounding box dimension: > 0 and at most `most`."""
    value = ctx.attrs.number(node, name)
    if not 0.0 < value <= most:
        raise node.error(f"{name}: must be > 0 and <= {fmt(most)} m, got {fmt(value)}")
    return value


def parse_bbox(node: Node, ctx: Context) -> BoundingBox:
    """A BoundingBox: its centre (finite) and its dimensions (`limits`)."""
    center = node.need("Center")
    dims = node.need("Dimensions")
    a = ctx.attrs
    return BoundingBox(
        center_x=a.number(center, "x"),
        center_y=a.number(center, "y"),
        center_z=a.number(center, "z"),
        length=_size(dims, ctx, "length", MAX_BOX_LENGTH),
        width=_size(dims, ctx, "width", MAX_BOX_WIDTH),
        height=_size(dims, ctx, "height", MAX_BOX_HEIGHT),
    )


def parse_axle(node: Node, ctx: Context) -> Axle:
    a = ctx.attrs
    return Axle(
        max_steering=a.number(node, "maxSteering"),
        wheel_diameter=a.number(node, "wheelDiameter"),
        track_width=a.number(node, "trackWidth"),
        position_x=a.number(node, "positionX"),
        position_z=a.number(node, "positionZ"),
    )


def _front_axle(axles: Node, ctx: Context) -> Axle | None:
    """The FrontAxle, None if none (optional in 1.3's schema: a trailer has none)."""
    node = axles.child("FrontAxle")
    return None if node is None else parse_axle(node, ctx)


def _no_trailer(trailer: Node, ctx: Context) -> bool:
    """Whether a Trailer element connects nothing: a TrailerRef whose entityRef is empty."""
    ref = trailer.child("TrailerRef")
    return ref is not None and len(trailer.children) == 1 \
        and ctx.attrs.opt_text(ref, "entityRef") == ""


def parse_vehicle(node: Node, ctx: Context) -> Vehicle:
    """A Vehicle; its 1.3 TrailerHitch / TrailerCoupler are read past (they matter only to
    a trailer connection), a Trailer (one connected from the start) is refused unless it
    names none (a `TrailerRef` to the empty name, as esmini's own catalog writes "no
    trailer")."""
    ctx = ctx.with_declarations(node)
    trailer = node.child("Trailer")
    if trailer is not None and not _no_trailer(trailer, ctx):
        raise unsupported(trailer)
    a = ctx.attrs
    perf = node.need("Performance")
    axles = node.need("Axles")
    return Vehicle(
        name=a.text(node, "name"),
        category=a.text(node, "vehicleCategory"),
        bbox=parse_bbox(node.need("BoundingBox"), ctx),
        max_speed=a.number(perf, "maxSpeed"),
        max_accel=a.number(perf, "maxAcceleration"),
        max_decel=a.number(perf, "maxDeceleration"),
        max_accel_rate=a.opt_number(perf, "maxAccelerationRate"),
        max_decel_rate=a.opt_number(perf, "maxDecelerationRate"),
        front_axle=_front_axle(axles, ctx),
        rear_axle=parse_axle(axles.need("RearAxle"), ctx),
        additional_axles=tuple(parse_axle(x, ctx) for x in axles.all("AdditionalAxle")),
        mass=a.opt_number(node, "mass"),
        role=a.opt_text(node, "vehicleRole"),
        model=a.opt_text(node, "model3d") or "",
        properties=a.properties(node.child("Properties")),
    )


def parse_pedestrian(node: Node, ctx: Context) -> Pedestrian:
    ctx = ctx.with_declarations(node)
    a = ctx.attrs
    model = a.opt_text(node, "model3d")
    if model is None:
        model = a.opt_text(node, "model") or ""
    return Pedestrian(
        name=a.text(node, "name"),
        category=a.text(node, "pedestrianCategory"),
        mass=a.number(node, "mass"),
        bbox=parse_bbox(node.need("BoundingBox"), ctx),
        model=model,
        properties=a.properties(node.child("Properties")),
    )


def parse_misc_object(node: Node, ctx: Context) -> MiscObject:
    ctx = ctx.with_declarations(node)
    a = ctx.attrs
    return MiscObject(
        name=a.text(node, "name"),
        category=a.text(node, "miscObjectCategory"),
        mass=a.number(node, "mass"),
        bbox=parse_bbox(node.need("BoundingBox"), ctx),
        model=a.opt_text(node, "model3d") or "",
        properties=a.properties(node.child("Properties")),
    )


def parse_controller(node: Node, ctx: Context) -> Controller:
    """A Controller element, or a CatalogReference to one."""
    if node.tag == "CatalogReference":
        entry = ctx.catalogs.resolve(node, ctx.attrs, ("Controller",))
        return parse_controller(entry.node, ctx.in_scope(entry.scope, entry.node))
    if node.tag != "Controller":
        raise unsupported(node)
    ctx = ctx.with_declarations(node)
    return Controller(
        name=ctx.attrs.text(node, "name"),
        properties=ctx.attrs.properties(node.child("Properties")),
    )


def _catalog_object(node: Node, ctx: Context) -> EntityObject:
    entry = ctx.catalogs.resolve(node, ctx.attrs, OBJECT_KINDS)
    return parse_object(entry.node, ctx.in_scope(entry.scope, entry.node))


OBJECT_READERS: dict[str, Callable[[Node, Context], EntityObject]] = {
    "CatalogReference": _catalog_object,
    "Vehicle": parse_vehicle,
    "Pedestrian": parse_pedestrian,
    "MiscObject": parse_misc_object,
}


def parse_object(node: Node, ctx: Context) -> EntityObject:
    """A Vehicle, Pedestrian or MiscObject element, or a CatalogReference to one
    (`OBJECT_READERS`)."""
    reader = OBJECT_READERS.get(node.tag)
    if reader is None:
        raise unsupported(node)
    return reader(node, ctx)


def parse_entities(node: Node, ctx: Context) -> tuple[Entity, ...]:
    """The ScenarioObjects of an Entities element (EntitySelection is not supported yet)."""
    entities: list[Entity] = []
    for obj in node.children:
        if obj.tag != "ScenarioObject":
            raise unsupported(obj)
        name = ctx.attrs.text(obj, "name")
        if any(e.name == name for e in entities):
            raise obj.error(f"entity {name} declared twice")
        kinds = [c for c in obj.children if c.tag != "ObjectController"]
        if len(kinds) != 1:
            raise obj.error(
                "needs exactly one of CatalogReference, Vehicle, Pedestrian, MiscObject"
            )
        controller_node = obj.child("ObjectController")
        controller = (  # an empty ObjectController: no controller (esmini reads it so)
            parse_controller(controller_node.only_child(), ctx)
            if controller_node is not None and controller_node.children
            else None
        )
        entities.append(Entity(name, parse_object(kinds[0], ctx), controller))
    return tuple(entities)
