"""The regulation formulas the judge applies, written from the regulations' text and owned
here (the stack has its own for its decisions; `tests/avsim/criteria/test_regulations.py`
compares them).

UN R157 (ALKS) 5.2.3.3, the minimum following distance: while the ego moves, the bumper gap
to the vehicle in front in its lane is at least ``d_min = v * t_front``, v the ego's present
speed [m/s] and t_front the minimum time gap [s] of the regulation's table
(`R157_TIME_GAPS`: 1.0 s at 7.2 km/h, then 1.1 s at 10 km/h rising 0.1 s every 10 km/h to
2.3 s at 130 km/h, the 01 series' top speed), linearly interpolated between its rows. At
present speeds below 2 m/s (7.2 km/h, the table's first row) d_min is never less than
`R157_LEAST_GAP` (2 m), whatever the formula gives.

From 10 km/h up the rows lie on one line, ``t_front = 1 s + v_kph / (100 km/h per s)``,
so the interpolation between them is that line (`r157_time_gap` computes it so: one
rounding fewer than interpolating row by row); beyond 130 km/h, outside the regulation's
scope, the judge keeps to the same line. Between 7.2 and 10 km/h the interpolation runs
from 1.0 s to 1.1 s; below 7.2 km/h, where the table has no row, t_front holds at 1.0 s and
the 2 m floor decides (v * 1.0 s < 2 m there).
"""

from __future__ import annotations

from world.frames import to_kph

# UN R157 5.2.3.3's table: (present speed [km/h], minimum time gap t_front [s])
R157_TIME_GAPS: tuple[tuple[float, float], ...] = (
    (7.2, 1.0), (10.0, 1.1), (20.0, 1.2), (30.0, 1.3), (40.0, 1.4), (50.0, 1.5),
    (60.0, 1.6), (70.0, 1.7), (80.0, 1.8), (90.0, 1.9), (100.0, 2.0), (110.0, 2.1),
    (120.0, 2.2), (130.0, 2.3))
R157_LEAST_GAP = 2.0  # [m] d_min's floor (at present speeds below 2 m/s)
R157_GAP_AT_ZERO = 1.0  # [s] where the rows from 10 km/h meet 0 km/h on their line
R157_KPH_PER_SECOND = 100.0  # [km/h per s] of that line: 0.1 s more every 10 km/h


def r157_time_gap(v: float) -> float:
    """[s] UN R157's minimum time gap t_front at the ego's present speed v [m/s] (module
    doc: the table's rows linearly interpolated, 1.0 s below its first row)."""
    v_kph = to_kph(v)
    (k0, t0), (k1, t1) = R157_TIME_GAPS[0], R157_TIME_GAPS[1]
    if v_kph >= k1:
        return R157_GAP_AT_ZERO + v_kph / R157_KPH_PER_SECOND
    if v_kph <= k0:
        return t0
    return t0 + (v_kph - k0) * (t1 - t0) / (k1 - k0)


def r157_min_gap(v: float) -> float:
    """[m] UN R157's minimum following distance d_min at the ego's present speed v [m/s]:
    v * t_front, never less than 2 m."""
    return max(v * r157_time_gap(v), R157_LEAST_GAP)
