"""The two stack modes of a scenario test module's runs (`run_scenario(..., stack=mode)`):
`truth`, the bundled planner and control on the privileged ground truth in `make test`, and
`sensors`, the whole stack on the cameras and LiDAR in `make acceptance`; and the two sensor
profiles of a module that judges what the stack does with what its sensors read (a stop sign
or a light read from the camera) but not perception's own figures: `fast` in `make test`,
`default` in `make acceptance` (`PROFILES`, the `sensor_profile` fixture)."""

from __future__ import annotations

import pytest

from world.sensors.setup import Profile

TRUTH = "truth"  # the privileged truth stack on profile `none`
SENSORS = "sensors"  # the scenario's own stack and sensors, as asked (`profile`)
TRUTH_STACK: dict[str, object] = {
    "stack.perception": "avsim.stack.bundled:truth_perception",
    "stack.privileged": True,
}  # the overrides that hand the bundled planner the ground truth
MODES = [pytest.param(TRUTH, id=TRUTH),
         pytest.param(SENSORS, id=SENSORS, marks=pytest.mark.acceptance)]
PROFILES = [pytest.param(Profile.FAST, id=Profile.FAST.value),
            pytest.param(Profile.DEFAULT, id=Profile.DEFAULT.value,
                         marks=pytest.mark.acceptance)]  # `sensor_profile`'s (module doc)
