"""Reading a Position element (World, RelativeWorld, RelativeObject, Road, RelativeRoad,
Lane, RelativeLane, Trajectory; Route and Geo positions are not supported yet)."""

from __future__ import annotations

from collections.abc import Callable

from avsim.scenario.openscenario.attributes import unsupported
from avsim.scenario.openscenario.context import Context
from avsim.scenario.openscenario.positions import (
    LanePosition,
    Orientation,
    Position,
    RelativeLanePosition,
    RelativeObjectPosition,
    RelativeRoadPosition,
    RelativeWorldPosition,
    RoadPosition,
    TrajectoryPosition,
    WorldPosition,
)
from avsim.scenario.openscenario.xmlread import Node


def parse_orientation(node: Node | None, ctx: Context) -> Orientation | None:
    if node is None:
        return None
    a = ctx.attrs
    kind = a.choice(node, "type", ("relative", "absolute")) if "type" in node.attrs else None
    return Orientation(
        h=a.number_or(node, "h", 0.0),
        p=a.number_or(node, "p", 0.0),
        r=a.number_or(node, "r", 0.0),
        type=kind,  # type: ignore[arg-type]
    )


def _world(node: Node, ctx: Context) -> Position:
    a = ctx.attrs
    return WorldPosition(
        x=a.number(node, "x"),
        y=a.number(node, "y"),
        z=a.opt_number(node, "z"),
        h=a.opt_number(node, "h"),
        p=a.opt_number(node, "p"),
        r=a.opt_number(node, "r"),
    )


def _relative_world(node: Node, ctx: Context) -> Position:
    a = ctx.attrs
    return RelativeWorldPosition(
        entity=ctx.entity_ref(node),
        dx=a.number(node, "dx"),
        dy=a.number(node, "dy"),
        dz=a.opt_number(node, "dz"),
        orientation=parse_orientation(node.child("Orientation"), ctx),
    )


def _relative_object(node: Node, ctx: Context) -> Position:
    a = ctx.attrs
    return RelativeObjectPosition(
        entity=ctx.entity_ref(node),
        dx=a.number(node, "dx"),
        dy=a.number(node, "dy"),
        dz=a.opt_number(node, "dz"),
        orientation=parse_orientation(node.child("Orientation"), ctx),
    )


def _road(node: Node, ctx: Context) -> Position:
    a = ctx.attrs
    return RoadPosition(
        road_id=a.text(node, "roadId"),
        s=a.number(node, "s"),
        t=a.number(node, "t"),
        orientation=parse_orientation(node.child("Orientation"), ctx),
    )


def _relative_road(node: Node, ctx: Context) -> Position:
    a = ctx.attrs
    return RelativeRoadPosition(
        entity=ctx.entity_ref(node),
        ds=a.number(node, "ds"),
        dt=a.number(node, "dt"),
        orientation=parse_orientation(node.child("Orientation"), ctx),
    )


def _lane(node: Node, ctx: Context) -> Position:
    a = ctx.attrs
    return LanePosition(
        road_id=a.text(node, "roadId"),
        lane_id=a.text(node, "laneId"),
        s=a.number(node, "s"),
        offset=a.number_or(node, "offset", 0.0),
        orientation=parse_orientation(node.child("Orientation"), ctx),
    )


def _relative_lane(node: Node, ctx: Context) -> Position:
    a = ctx.attrs
    ds = a.opt_number(node, "ds")
    ds_lane = a.opt_number(node, "dsLane")
    if (ds is None) == (ds_lane is None):
        raise node.error("needs exactly one of ds and dsLane")
    return RelativeLanePosition(
        entity=ctx.entity_ref(node),
        d_lane=a.integer(node, "dLane"),
        ds=ds,
        ds_lane=ds_lane,
        offset=a.number_or(node, "offset", 0.0),
        orientation=parse_orientation(node.child("Orientation"), ctx),
    )


def _trajectory(node: Node, ctx: Context) -> Position:
    # a trajectory's vertices are positions: its reader imports this module
    from avsim.scenario.openscenario.parse_trajectories import parse_trajectory_ref

    a = ctx.attrs
    return TrajectoryPosition(
        trajectory=parse_trajectory_ref(node, ctx),
        s=a.number(node, "s"),
        t=a.number_or(node, "t", 0.0),
        orientation=parse_orientation(node.child("Orientation"), ctx),
    )


_READERS: dict[str, Callable[[Node, Context], Position]] = {
    "WorldPosition": _world,
    "RelativeWorldPosition": _relative_world,
    "RelativeObjectPosition": _relative_object,
    "RoadPosition": _road,
    "RelativeRoadPosition": _relative_road,
    "LanePosition": _lane,
    "RelativeLanePosition": _relative_lane,
    "TrajectoryPosition": _trajectory,
}


def parse_position(node: Node, ctx: Context) -> Position:
    """The position a Position element holds."""
    inner = node.only_child()
    reader = _READERS.get(inner.tag)
    if reader is None:
        raise unsupported(inner)
    return reader(inner, ctx)


POSITION_READERS = _READERS  # the Position elements read (`coverage`)
