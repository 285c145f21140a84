"""``bioflex-jsb bench``: the figures it prints (shape, not timing: machines are noisy)."""

from __future__ import annotations

import json
import math

import pytest

from bioflex_jsb.cli import main

pytestmark = pytest.mark.slow  # real ground stations / subprocess runs: not in the fast subset


def test_bench_json_has_every_figure(capsys):
    assert main(["bench", "--steps", "100", "--repeat", "1", "--sitl-seconds", "0.5",
                 "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("ratio", "logged_ratio", "log_ratio", "native_ratio", "python_ratio"):
        d = data[key]
        assert d["min"] <= d["median"] <= d["max"], key
        # shape, not values: 100-step timings on a shared machine are noise
        assert math.isfinite(d["median"]), key
    for key in ("bare", "cosim", "logged", "native", "python"):
        assert math.isfinite(data["us_per_step"][key]["median"]), key
    assert set(data["cosim_us_per_step_by_gust"]) == {"sharp:0.3", "sharp:3",
                                                      "dryden:1.5:100:7"}
    assert set(data["fixed_ms_per_run"]) == {"cosim", "logged"}
    assert data["kernel_compile_s"]["cold"] > 0.0 and data["kernel_compile_s"]["cached"] > 0.0
    assert data["refresh_ms"]["median"] > 0.0
    assert 0.0 <= data["sitl"]["p50_ms"] <= data["sitl"]["p99_ms"]
    assert data["steps"] == 100 and data["repeat"] == 1


def test_bench_bad_input_is_one_line_and_exit_2(capsys):
    for argv, word in ((["bench", "--steps", "5"], "--steps"),
                       (["bench", "--speed", "1000"], "--speed"),
                       (["bench", "--steps", "1e8"], "--steps"),
                       (["bench", "--sitl-seconds", "-1"], "--sitl-seconds")):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert word in err and err.count("\n") == 1, (argv, err)
