"""``bioflex-jsb bench``: the figures it prints (shape, not timing: machines are noisy)."""

from __future__ import annotations

import json
import math

import pytest

from bioflex_jsb.cli import main

pytestmark = pytest.mark.slow  # real ground stations / subprocess runs: not in the fast subset


def test_bench_json_has_every_figure(capsys):
    assert main(["bench", "--steps", "50", "--repeat", "1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("bare_us_per_step", "cosim_us_per_step", "ratio", "logged_us_per_step",
                "log_ratio", "native_us_per_step", "native_ratio", "sitl_p50_ms",
                "sitl_p99_ms"):
        assert math.isfinite(data[key]) and data[key] > 0.0, key
    assert data["steps"] == 50 and data["repeat"] == 1


def test_bench_bad_input_is_one_line_and_exit_2(capsys):
    assert main(["bench", "--steps", "5"]) == 2
    err = capsys.readouterr().err
    assert "--steps" in err and err.count("\n") == 1
