"""Golden check cases (``tests/golden_cases.py``): the Fig. 21 run of every model, channel by
channel, against the stored reference histories."""

from __future__ import annotations

import pytest

from tests.golden_cases import CASES, GOLDEN_DIR, RTOL_OF_RANGE, compare, fly_case, read_csv


@pytest.mark.parametrize("case", CASES)
def test_golden_case_matches_the_stored_history(case):
    errors = compare(read_csv(GOLDEN_DIR / f"{case}.csv"), fly_case(case))
    bad = {k: v for k, v in errors.items() if v > RTOL_OF_RANGE}
    assert not bad, f"{case}: channels off by more than {RTOL_OF_RANGE} of their range: {bad}"


def test_the_comparison_sees_a_small_common_shift():
    """A change that moves everything together by 1e-6 of the range must fail the case."""
    stored = read_csv(GOLDEN_DIR / "fig21_coupled.csv")
    run = fly_case("fig21_coupled")
    for name in ("q", "eta1"):
        ref = stored[1][name]
        run.channels[name] = run.channels[name] + 1e-6 * float(ref.max() - ref.min())
    errors = compare(stored, run)
    assert errors["q"] > RTOL_OF_RANGE and errors["eta1"] > RTOL_OF_RANGE
