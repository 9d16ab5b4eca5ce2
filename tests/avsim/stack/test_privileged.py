"""Privileged truth mode: the `truth` sensor only when asked for, labelled in every result,
and the bundled truth perception stage."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from avsim.batch.jobs import RunJob, RunOutcome, Status
from avsim.cli import main
from avsim.report.suite import _properties, summary_markdown
from avsim.run.result import result_json
from avsim.run.runner import Runner
from avsim.run.verdict import RunVerdict
from avsim.scenario.errors import ScenarioError
from avsim.scenario.load import load_scenario
from avsim.stack.choice import TRUTH_PERCEPTION
from perception.truth import TruthPerception
from tests.avsim.stack import user_stacks
from world.frames import GroundTruth, SensorKind

USER = "tests.avsim.stack.user_stacks"
LEAD = """\
format: avsim/1
name: lead
duration: 1
road:
  speed_limit_kph: 50
  segments:
    - straight: 300
ego: {s: 10, speed_kph: 30, set_speed_kph: 30}
actors:
  - {id: lead, type: car, lane: 0, s: 40, speed_kph: 20}
"""


@pytest.fixture
def lead(tmp_path: Path) -> Path:
    path = tmp_path / "lead.yaml"
    path.write_text(LEAD, encoding="utf-8")
    return path


def _logged(path: Path, privileged: bool) -> tuple[Runner, user_stacks.FrameLog]:
    user_stacks.FRAME_LOGS.clear()
    overrides: dict[str, object] = {"stack.stack": f"{USER}:frame_log"}
    if privileged:
        overrides["stack.privileged"] = True
    runner = Runner(load_scenario(path, overrides), None, profile=None)
    runner.run()
    (log,) = user_stacks.FRAME_LOGS
    return runner, log


def test_a_run_without_privileged_mode_never_gets_a_truth_frame(lead: Path) -> None:
    _, log = _logged(lead, privileged=False)
    assert len(log.deliveries) >= 40  # odometry at 40 Hz for 1 s
    assert all("truth" not in names for _, names in log.deliveries)
    assert not any(isinstance(f, GroundTruth) for f in log.frames)
    assert all(s.kind is not SensorKind.TRUTH for s in log.ctx.sensors)


def test_privileged_mode_hands_the_stack_the_truth_at_the_control_rate(lead: Path) -> None:
    runner, log = _logged(lead, privileged=True)
    (spec,) = [s for s in log.ctx.sensors if s.kind is SensorKind.TRUTH]
    assert (spec.name, spec.rate, spec.latency) == ("truth", 40, 0.0)
    truths = [f for f in log.frames if isinstance(f, GroundTruth)]
    assert len(truths) == len(runner.log.t) >= 40  # one per control tick
    for truth, (t, names) in zip(truths, [d for d in log.deliveries if "truth" in d[1]],
                                 strict=True):
        assert truth.t == t and names[-1] == "truth"
    last = truths[-1]
    (lead_car,) = last.objects
    assert lead_car.id == "lead" and lead_car.kind == "car"
    poses = runner.world.actors.poses
    speed = 20 / 3.6  # [m/s] the lead's, steady; the last truth is one tick old
    assert lead_car.x == pytest.approx(poses.centres[0, 0] - speed * 0.025, abs=1e-9)
    assert lead_car.y == poses.centres[0, 1]
    assert math.hypot(lead_car.vx, lead_car.vy) == pytest.approx(speed, abs=1e-9)
    assert lead_car.length == pytest.approx(2 * poses.half_sizes[0, 0])
    ego = runner.world.ego_truth
    assert last.t == pytest.approx(runner.world.t - 0.025)  # the last tick's capture
    assert abs(last.x - ego.position[0]) < 0.3 and last.speed > 7.0


def test_the_truth_perception_needs_privileged_mode_at_load(lead: Path) -> None:
    with pytest.raises(ScenarioError) as err:
        load_scenario(lead, {"stack.perception": TRUTH_PERCEPTION})
    assert err.value.key == "stack.perception" and "privileged" in err.value.problem
    loaded = load_scenario(lead, {"stack.perception": TRUTH_PERCEPTION,
                                  "stack.privileged": True})
    assert loaded.stack.privileged


def test_the_cli_refuses_the_truth_perception_without_privileged_in_one_line(
        lead: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(main, ["run", str(lead), "--profile", "none",
                                       "--perception", TRUTH_PERCEPTION])
    assert result.exit_code == 2, result.output
    assert result.stderr.count("\n") == 1 and "stack.perception" in result.stderr
    assert "Traceback" not in result.stderr and not (tmp_path / "runs").exists()


def test_a_privileged_run_is_labelled_in_its_result_header_junit_and_summary(
        lead: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "lead.json"
    result = CliRunner().invoke(main, ["run", str(lead), "--profile", "none", "--privileged",
                                       "--perception", TRUTH_PERCEPTION, "--json", str(out),
                                       "--out", str(tmp_path / "lead.rrd"), "--no-progress"])
    assert result.exit_code == 1, result.output  # judged: 1 s does not complete the route
    assert "lead: privileged: ground truth" in result.output
    import json

    payload = json.loads(out.read_text())
    assert payload["stack"]["privileged"] is True
    assert payload["localisation"]["privileged"] is True
    job = RunJob("lead", str(lead), tmp_path / "lead")
    outcome = RunOutcome(job, Status.PASSED, payload, None, 1.0)
    assert _properties(outcome)["stack"].endswith("(privileged: ground truth)")
    summary = summary_markdown([outcome], title="t", out_dir=tmp_path, snapshots={})
    assert "(privileged: ground truth)" in summary


def test_an_unprivileged_result_says_so(lead: Path) -> None:
    runner = Runner(load_scenario(lead), None, profile=None)
    payload = result_json(runner.run(), lead, Path("x.rrd"), "none")
    assert payload["stack"]["privileged"] is False  # type: ignore[index]
    assert payload["localisation"]["privileged"] is False  # type: ignore[index]


def test_the_bundled_stack_on_truth_perception_stops_behind_the_sudden_stop() -> None:
    """sudden_stop, profile none, privileged: the lead brakes at 6 m/s^2 from 50 km/h 12 m
    ahead; the bundled planner and controller on the truth stop the car behind it, without
    contact, and pass."""
    scenario = load_scenario("sudden_stop", {"stack.perception": TRUTH_PERCEPTION,
                                             "stack.privileged": True})
    runner = Runner(scenario, None, profile=None)
    lead_speeds: list[float] = []
    result = runner.run(
        lambda t, d: lead_speeds.append(float(runner.world.actors.poses.speeds[0])))
    assert result.verdict is RunVerdict.PASS, [c for c in result.criteria if c.failed]
    assert isinstance(runner.stack.perception, TruthPerception)  # type: ignore[attr-defined]
    assert min(lead_speeds) < 0.1  # the lead braked to a stop
    standstill = next(c for c in result.criteria if c.name == "standstill_gap")
    assert standstill.passed and standstill.value is not None  # the car stood behind it
    log = runner.log
    assert np.nanmin(np.array(log.speed)) < 0.1
