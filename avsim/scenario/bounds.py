"""The upper bound of every size a scenario file can ask for: counts, lengths,
times, speeds and noise. A file over a bound is refused at load with the one-line error
(`<file>: <key>: must be <= B, got V`), before anything is built, so that no file can make a
run hang or exhaust memory while it starts. The bounds are far above what a driving scenario
needs (a soak is 1 h on a town loop; the longest bundled route is 3 km) and are listed in
`docs/scenario-format.md` ("Bounds").

The constrained types below are the models' (`avsim.scenario.model`); units are the file's.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

MAX_FILE_BYTES = 512 * 1024  # a scenario file's size (the bundled ones are about 2 kB)
MAX_VALUES = 100_000  # the values (scalars, lists, mappings, keys) a file holds, anchors expanded
MAX_DEPTH = 64  # collections nested in a file or a `--set` value, anchors expanded (the
# bundled files nest 6 deep; YAML's composer and everything after it recurse per level)
MAX_INT_DIGITS = 20  # digits of an integer in a file or a `--set` value (2**64 has 20)
MAX_NAME_LENGTH = 100  # characters of `name` (it names the run's files: runs/<name>.rrd)
MAX_DURATION = 7200.0  # [s] `duration`, and every time in the file (triggers, delays, lights)
MAX_SEED = 2**32 - 1  # `seed` (numpy's seed range)
MAX_DISTRIBUTION_RUNS = 1000  # the runs an OpenSCENARIO ParameterValueDistribution file
#   describes (its permutations, or its stochastic numberOfTestRuns)
MAX_LANES = 6  # driving lanes per direction on a road, oncoming lanes
MAX_TOWN_LANES = 3  # lanes per direction on a town's streets
MAX_LANE_WIDTH = 6.0  # [m] a lane's width
MAX_SHOULDER = 10.0  # [m] the paved shoulder
MAX_SEGMENTS = 500  # `road.segments`
MAX_ROUTE_LENGTH = 20_000.0  # [m] a road's route (its segments' lengths added up), stations
MAX_RADIUS = 100_000.0  # [m] an arc's radius
MAX_FEATURES = 1000  # `road.features`
MAX_FEATURE_SIZE = 50.0  # [m] a crosswalk's width, a speed bump's length
MAX_BUMP_HEIGHT = 0.5  # [m] a speed bump's height
MAX_SETBACK = 100.0  # [m] `road.buildings.setback`
MAX_TOWN_BLOCKS = 10  # `town.blocks_x`, `town.blocks_y`
MAX_BLOCK = 500.0  # [m] `town.block`
MAX_ROUTE_TURNS = 200  # a town route's turns
MAX_ACTORS = 100  # `actors`
MAX_ACTIONS = 50  # an actor's `actions`
MAX_EVENTS = 50  # `events`
MAX_SPEED_KPH = 300.0  # [km/h] every speed in the file
MAX_ACCEL = 15.0  # [m/s^2] an action's acceleration or deceleration, either sign
MAX_LATERAL_SPEED = 10.0  # [m/s] a lane change's
MAX_OFFSET = 50.0  # [m] an actor's lateral offset, a walk's target offset
MAX_HEADING_SIGMA = 180.0  # [deg] GNSS heading noise
MAX_VELOCITY_SIGMA = 50.0  # [m/s] GNSS velocity noise
MAX_DROPOUT_RATE = 10.0  # [1/s] GNSS outages started per second
MAX_RANGE_SIGMA = 1.0  # [m] LiDAR range noise
MAX_FAULT_DURATION = MAX_DURATION  # [s] a sensor fault's duration
MAX_GNSS_JUMP = 1000.0  # [m] a GNSS jump's offset, per axis
MAX_SENSOR_DELAY = 1.0  # [s] a sensor delay's added latency (the stack keeps 2 s of poses)

Duration = Annotated[float, Field(gt=0, le=MAX_DURATION)]
Time = Annotated[float, Field(ge=0, le=MAX_DURATION)]
Seed = Annotated[int, Field(ge=0, le=MAX_SEED)]
Lanes = Annotated[int, Field(ge=1, le=MAX_LANES)]
OncomingLanes = Annotated[int, Field(ge=0, le=MAX_LANES)]
TownLanes = Annotated[int, Field(ge=1, le=MAX_TOWN_LANES)]
LaneWidth = Annotated[float, Field(gt=0, le=MAX_LANE_WIDTH)]
Shoulder = Annotated[float, Field(ge=0, le=MAX_SHOULDER)]
Length = Annotated[float, Field(gt=0, le=MAX_ROUTE_LENGTH)]
Station = Annotated[float, Field(ge=0, le=MAX_ROUTE_LENGTH)]
Radius = Annotated[float, Field(gt=0, le=MAX_RADIUS)]
FeatureSize = Annotated[float, Field(gt=0, le=MAX_FEATURE_SIZE)]
BumpHeight = Annotated[float, Field(gt=0, le=MAX_BUMP_HEIGHT)]
Setback = Annotated[float, Field(ge=0, le=MAX_SETBACK)]
Blocks = Annotated[int, Field(ge=1, le=MAX_TOWN_BLOCKS)]
Block = Annotated[float, Field(gt=0, le=MAX_BLOCK)]
Speed = Annotated[float, Field(ge=0, le=MAX_SPEED_KPH)]
PosSpeed = Annotated[float, Field(gt=0, le=MAX_SPEED_KPH)]
Accel = Annotated[float, Field(ge=-MAX_ACCEL, le=MAX_ACCEL)]
Decel = Annotated[float, Field(gt=0, le=MAX_ACCEL)]
LateralSpeed = Annotated[float, Field(gt=0, le=MAX_LATERAL_SPEED)]
Offset = Annotated[float, Field(ge=-MAX_OFFSET, le=MAX_OFFSET)]
ActionIndex = Annotated[int, Field(ge=0, le=max(MAX_ACTIONS, MAX_EVENTS))]
HeadingSigma = Annotated[float, Field(ge=0, le=MAX_HEADING_SIGMA)]
VelocitySigma = Annotated[float, Field(ge=0, le=MAX_VELOCITY_SIGMA)]
DropoutRate = Annotated[float, Field(ge=0, le=MAX_DROPOUT_RATE)]
RangeSigma = Annotated[float, Field(ge=0, le=MAX_RANGE_SIGMA)]
FaultDuration = Annotated[float, Field(gt=0, le=MAX_FAULT_DURATION)]
SensorDelay = Annotated[float, Field(gt=0, le=MAX_SENSOR_DELAY)]
