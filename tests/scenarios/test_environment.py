"""Closed loop: the stack meets the OpenSCENARIO environment as the sensors render it.

docs/examples/minimal.xosc (a car 40 m ahead, both at 50 km/h) is run for 6 s at the `fast`
profile as it is, in 30 m fog, and at night (NCAP's "Night": a moon of 0.1 lx high up, no
headlights): in fog and at night the front camera loses the lane (the planner's lane source
leaves the camera) and the lane is estimated on fewer frames; in fog the LiDAR sees the car
ahead only once it is close (two-way extinction), at night as far as by day (an active
sensor). Perception is not tuned for any of it.
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest

from avsim.run.runner import Runner, RunResult
from avsim.scenario.load import load_scenario
from world.sensors.setup import Profile

pytestmark = pytest.mark.slow

EXAMPLES = Path(__file__).parents[2] / "docs" / "examples"
DURATION = 6.0  # [s]
WEATHER = {
    "clear": None,
    "fog": '<Weather cloudState="free"><Fog visualRange="30"/></Weather>',
    "night": '<Weather fractionalCloudCover="zeroOktas">'
             '<Sun azimuth="3.1" elevation="1.15" illuminance="0.1"/></Weather>',
}


def scenario_file(folder: Path, name: str) -> Path:
    """minimal.xosc (with its road) in `folder`, its Init setting the environment `name`."""
    shutil.copy(EXAMPLES / "straight.xodr", folder / "straight.xodr")
    text = (EXAMPLES / "minimal.xosc").read_text()
    weather = WEATHER[name]
    if weather is not None:
        action = (f'<GlobalAction><EnvironmentAction><Environment name="{name}">{weather}'
                  '</Environment></EnvironmentAction></GlobalAction>')
        at = text.index('<Private entityRef="Ego">', text.index("<Init>"))
        text = text[:at] + action + text[at:]
    path = folder / f"{name}.xosc"
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Callable[..., RunResult]:
    cache: dict[tuple[str, str, float], RunResult] = {}

    def play(name: str, sensing: str = "inline", duration: float = DURATION) -> RunResult:
        if (name, sensing, duration) not in cache:
            folder = tmp_path_factory.mktemp(name)
            scenario = load_scenario(str(scenario_file(folder, name)),
                                     {"duration": duration})
            cache[name, sensing, duration] = Runner(scenario, None, profile=Profile.FAST,
                                          sensing=sensing).run()
        return cache[name, sensing, duration]

    return play


def lane_sources(result: RunResult) -> list[str]:
    return [c.target for c in result.state_changes if c.machine == "lane_source"]


def test_clear_weather_keeps_the_camera_lane(run: Callable[..., RunResult]) -> None:
    clear = run("clear")
    assert set(lane_sources(clear)) <= {"camera"}
    assert clear.metrics["first_tracked_distance_lead"] > 35.0


@pytest.mark.parametrize("weather", ["fog", "night"])
def test_fog_and_night_take_the_lane_from_the_camera(run: Callable[..., RunResult],
                                                     weather: str) -> None:
    clear, other = run("clear"), run(weather)
    assert [c.kind for c in other.storyboard_state] == ["environment"]
    assert any(source != "camera" for source in lane_sources(other)), lane_sources(other)
    assert other.metrics["lane_frames"] < clear.metrics["lane_frames"]


def test_fog_shortens_the_lidars_reach_and_night_does_not(
        run: Callable[..., RunResult]) -> None:
    clear = run("clear").metrics["first_tracked_distance_lead"]
    fog = run("fog").metrics["first_tracked_distance_lead"]
    night = run("night").metrics["first_tracked_distance_lead"]
    assert night == pytest.approx(clear, abs=1.0)
    assert math.isnan(fog) or fog < 30.0  # never tracked, or only within the fog's range


def test_the_render_worker_draws_the_same_night(run: Callable[..., RunResult]) -> None:
    """The cameras render in a worker posed by snapshots: the environment travels with
    them, and the sensor's noise is seeded alike: the same run, bit for bit."""
    inline = run("night", duration=2.0)
    worker = run("night", sensing="process", duration=2.0)
    assert inline.log.array("steering").tobytes() == worker.log.array("steering").tobytes()
    assert inline.metrics == worker.metrics
