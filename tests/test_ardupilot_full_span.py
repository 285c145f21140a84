"""The ArduPilot JSON backend with both wing halves (``ardupilot --span full``): the ailerons
ArduPlane commands load the antisymmetric modes through JSBSim's flight controls, as in
``sitl --span full`` (docs/lateral.md, "Both halves in the co-simulation"). Driven here by
servo frames without ArduPlane: the prototype's estimated outboard aileron is reversed at
15 m/s (`bioflex-jsb aileron --aircraft bioflex_optimised`: 12.8 m/s), so a right-aileron
servo step rolls the elastic aircraft left, the rigid one right."""

from __future__ import annotations

import pytest

from bioflex_jsb import api
from bioflex_jsb.drivers import ardupilot as ad
from bioflex_jsb.runtime.fdm import Airframe
from tests.cli_helpers import assert_one_line_error, run_cli

ARMED_IDLE = (1500, 1500, 1050, 1500)  # TKOFF_THR_IDLE 5 %: fires the launcher
RIGHT = (1510, 1500, 1050, 1500)  # servo 1 +10 µs: aileron command +0.02 (rolls right)
FLY_S = 0.3  # the step's duration [s]: within the roll's linear range


@pytest.fixture(scope="module")
def prototype():
    return api.load_aircraft("bioflex_optimised")


def _roll_after_step(prototype, model: str, span: str):
    """(roll rate [rad/s] FLY_S after the aileron step, the physics) of a launch, 0.25 s at
    trim and the step."""
    ph = ad.ArduPilotPhysics(Airframe(), prototype.wing(), model, span=span,
                             aileron=prototype.definition.aileron)
    for _ in range(ph.launch_hold_steps + ph.stroke_steps + int(round(0.25 / ph.dt_s))):
        ph.step(ARMED_IDLE + (0,) * 12, 1200)
    assert ph.phase == ad.FLIGHT
    p0 = ph.core.get["p"]()
    for _ in range(int(round(FLY_S / ph.dt_s))):
        ph.step(RIGHT + (0,) * 12, 1200)
    assert ph.summary()["stop_count"] == 0
    return ph.core.get["p"]() - p0, ph


def test_arduplanes_aileron_loads_the_antisymmetric_modes(prototype):
    """Measured: the roll rate 0.3 s after the step +0.0486 rad/s rigid, −0.1405 elastic
    (ratio −2.89; the same step flown by `gust` −2.978, the linear lateral model −2.980:
    docs/lateral.md "Validation"); asym_eta1 0.0119 rad, the tips twisted −0.0076 (port)
    and +0.0153 rad (starboard) with the symmetric part; the half wing's rows have no
    antisymmetric channels."""
    p_rigid, _ = _roll_after_step(prototype, "rigid", "full")
    p_elastic, ph = _roll_after_step(prototype, "coupled", "full")
    assert p_rigid > 0.0 and p_elastic < 0.0
    assert -3.3 < p_elastic / p_rigid < -2.5
    row = dict(zip(ph.core.names, ph._last_row, strict=True))
    assert abs(row["asym_eta1"]) > 1e-4 and row["aileron_rad"] > 1e-3  # JSBSim's δa, + right
    assert row["tip_twist_port_rad"] * row["tip_twist_starboard_rad"] < 0.0
    _, half = _roll_after_step(prototype, "coupled", "half")
    assert not any(n.startswith("asym_eta") for n in half.core.names)


def test_native_wing_with_both_halves_is_refused(capsys):
    code, _, err = run_cli(capsys, "ardupilot", "--model", "native", "--span", "full",
                           "--duration", "1", "--no-log")
    assert_one_line_error(code, err, "--span full")
