"""The default blueprint, read back from a recording: every view the layout promises is
there, rooted at the entity paths the recorder logs to."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from rerun.chunk import RrdReader

from avsim.record import blueprint as bp
from avsim.record.recorder import Recorder


def blueprint_rows(path: Path) -> dict[str, dict[str, Any]]:
    """Blueprint entity path -> {component: first value} of the recording's default blueprint."""
    reader = RrdReader(path)
    (blueprint,) = reader.blueprints()
    rows: dict[str, dict[str, Any]] = {}
    for chunk in reader.stream(store=blueprint).to_chunks():
        batch = chunk.to_record_batch()
        fields = rows.setdefault(chunk.entity_path, {})
        for name in batch.schema.names:
            if ":" in name:
                fields[name] = batch.column(name).to_pylist()[0]
    return rows


@pytest.fixture(scope="module")
def rows(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Any]]:
    path = tmp_path_factory.mktemp("blueprint") / "empty.rrd"
    Recorder(path, recording_id="blueprint").close()
    return blueprint_rows(path)


@pytest.fixture(scope="module")
def views(rows: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """View name -> {"class", "origin", "contents", "path"} of the default blueprint."""
    found = {}
    for entity, fields in rows.items():
        if "ViewBlueprint:class_identifier" in fields:
            (name,) = fields["ViewBlueprint:display_name"]
            found[name] = {
                "class": fields["ViewBlueprint:class_identifier"][0],
                "origin": fields["ViewBlueprint:space_origin"][0],
                "contents": rows[f"{entity}/ViewContents"]["ViewContents:query"],
                "path": entity.lstrip("/"),
            }
    return found


def test_every_view_is_rooted_where_the_recorder_logs(views: dict[str, dict[str, Any]]) -> None:
    expected = {
        "Chase": ("3D", bp.WORLD),
        "Overview": ("3D", bp.WORLD),
        "Front camera": ("2D", bp.FRONT_CAMERA),
        "Left camera": ("2D", "/world/ego/camera_left"),
        "Right camera": ("2D", "/world/ego/camera_right"),
        "FSM": ("StateTimeline", bp.FSM_ROOT),
        "Speed [m/s]": ("TimeSeries", bp.METRICS),
        "Steering [rad], cross-track error [m]": ("TimeSeries", bp.METRICS),
        "Other metrics": ("TimeSeries", bp.METRICS),
        "Events": ("TextLog", bp.EVENTS),
    }
    assert {name: (v["class"], v["origin"]) for name, v in views.items()} == expected


def test_world_views_show_sensors_and_perception(views: dict[str, dict[str, Any]]) -> None:
    # The overview shows all of /world: LiDAR, tracks, lane lines and the cameras in 3D.
    assert views["Overview"]["contents"] == ["$origin/**"]
    for path in (bp.LIDAR, bp.TRACK_BOXES, bp.TRACK_VELOCITY, bp.LANE_LINES, bp.DETECTIONS):
        assert path.startswith(f"{bp.WORLD}/")
    # The chase view leaves out only the cameras' image planes.
    cameras = [f"- {bp.camera_entity(name)}" for name in bp.CAMERAS]
    assert views["Chase"]["contents"] == [f"+ {bp.WORLD}/**", *cameras]


def test_camera_tabs_sit_beside_the_fsm_lanes(
    rows: dict[str, dict[str, Any]], views: dict[str, dict[str, Any]]
) -> None:
    containers = {
        entity.lstrip("/"): fields
        for entity, fields in rows.items()
        if "ContainerBlueprint:contents" in fields
    }
    cameras = [views[f"{name.capitalize()} camera"]["path"] for name in bp.CAMERAS]
    (tabs,) = [c for c, f in containers.items() if f["ContainerBlueprint:contents"] == cameras]
    assert containers[tabs]["ContainerBlueprint:active_tab"] == [cameras[0]]  # front
    (parent,) = [f for f in containers.values() if tabs in f["ContainerBlueprint:contents"]]
    assert parent["ContainerBlueprint:contents"] == [tabs, views["FSM"]["path"]]


def test_camera_entities() -> None:
    assert bp.camera_entity("front") == bp.FRONT_CAMERA == "/world/ego/camera_front"
    assert bp.CAMERAS[0] == "front"
