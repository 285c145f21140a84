"""One definition of a number for every input reader (bioflex_jsb.values)."""

import math

import numpy as np
import pytest

from bioflex_jsb.values import is_finite_real, is_real, is_whole


@pytest.mark.parametrize("value", [0, -3, 2.5, np.float64(1.5), np.int32(7), math.inf, math.nan])
def test_numbers_of_every_kind_are_real(value):
    assert is_real(value)


@pytest.mark.parametrize("value", [True, False, np.bool_(True), "15", None, [1.0], 1j, b"1"])
def test_bools_strings_and_containers_are_not_numbers(value):
    assert not is_real(value) and not is_finite_real(value) and not is_whole(value)


def test_finite_excludes_nan_and_infinities_only():
    assert is_finite_real(1e308) and is_finite_real(np.float32(-2.0))
    assert not any(is_finite_real(v) for v in (math.nan, math.inf, -math.inf, np.nan))


def test_whole_numbers_are_integers_not_integral_floats():
    assert is_whole(3) and is_whole(np.int64(3))
    assert not is_whole(3.0) and not is_whole(np.float64(3.0))


def test_every_reader_refuses_a_bool_where_a_number_goes(tmp_path):
    """The readers that used to write the guard themselves now share it: a bool is refused
    by the definition reader, the variant reader and the API alike."""
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.flight_dynamics.wing_model import VariantError, variant_from_mapping
    from bioflex_jsb.simulation.run_checks import finite_number

    with pytest.raises(VariantError, match="x_elastic_frac"):
        variant_from_mapping({"x_elastic_frac": True}, "v.toml")
    with pytest.raises(InputError, match="must be a number"):
        finite_number(True, "speed [m/s]")
    assert finite_number(np.float64(15.0), "speed [m/s]") == 15.0
