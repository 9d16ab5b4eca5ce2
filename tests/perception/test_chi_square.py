"""The lane filter's chi-square gate (`perception.lanes.chi_square_quantile`) is bit for bit
scipy.stats' quantile, over the gate probabilities and degrees of freedom it is used with."""

from __future__ import annotations

import pytest
from scipy.stats import chi2

from perception.lanes import LaneFilter, LaneFilterParams, chi_square_quantile


@pytest.mark.parametrize("probability", [0.9, 0.95, 0.99, LaneFilterParams().gate_probability,
                                         0.9999])
@pytest.mark.parametrize("dof", [1, 2, 3, 4])
def test_the_quantile_is_scipy_stats_bit_for_bit(probability: float, dof: int) -> None:
    assert chi_square_quantile(probability, dof).hex() == \
        float(chi2.ppf(probability, dof)).hex()


def test_the_filter_gates_at_the_quantile_of_its_probability() -> None:
    params = LaneFilterParams()
    gate = LaneFilter(params)._gate
    assert gate == {n: float(chi2.ppf(params.gate_probability, n)) for n in (3, 4)}
    assert 16.2 < gate[3] < 16.3 and 18.4 < gate[4] < 18.5  # the 99.9 % points' tables
