"""The ``[sensors]`` table of an aircraft definition (definition/sensors.py): read, checked
in one line, and placed in body axes from the CG."""

from __future__ import annotations

import pytest

from bioflex_jsb.definition.aircraft import load_aircraft
from bioflex_jsb.definition.loader import shipped_path
from bioflex_jsb.definition.reader import DefinitionError
from bioflex_jsb.parameters.sensors import CG_IMU

SENSORS = """
[[sensors.imu]]
name = "autopilot"
position_m = [0.05, 0.0, 0.02]
orientation_deg = [0.0, 0.0, 90.0]
autopilot = true
accel_noise_m_s2 = 0.3
seed = 4

[[sensors.imu]]
name = "tip"
wing_y_m = 0.85
chord_position = 0.6

[[sensors.imu]]
name = "port"
wing_y_m = -0.3
chord_position = 0.22

[[sensors.imu]]
name = "tail"
position_m = [0.85, 0.0, 0.05]
frame = "structural"

[[sensors.airspeed]]
name = "pitot"
position_m = [0.0, 0.0, 0.0]
frame = "structural"
"""


def _write(tmp_path, extra: str, name: str = "with_sensors"):
    text = shipped_path("bioflex_optimised").read_text(encoding="utf-8")
    path = tmp_path / f"{name}.toml"
    path.write_text(text.replace('name = "bioflex_optimised"', f'name = "{name}"') + extra,
                    encoding="utf-8")
    return path


def test_sensors_are_placed_in_body_axes_from_the_cg(tmp_path):
    """The prototype's CG is 0.3549 m aft of the nose, its wing root leading edge 0.3 m
    (bioflex_optimised.toml): a point of the structural frame (x aft, z up) is (x_cg − x,
    y, −z) in body axes; the wing tip's leading edge is 0.17016 m aft of the root's (the
    swept outer panel), its chord 0.183 m."""
    aircraft = load_aircraft(_write(tmp_path, SENSORS))
    s = aircraft.sensors()
    names = [i.name for i in s.imus]
    assert names == ["autopilot", "tip", "port", "tail"]
    assert s.autopilot_imu.name == "autopilot"
    ap, tip, port, tail = s.imus
    assert ap.position_m == (0.05, 0.0, 0.02) and ap.wing is None
    assert ap.orientation_rad[2] == pytest.approx(1.5707963267948966)
    assert ap.noise.accel_noise_m_s2 == 0.3 and ap.noise.seed == 4
    x_tip = 0.3 + 0.17015608451944958 + 0.6 * 0.183
    assert tip.position_m == pytest.approx((0.3549 - x_tip, 0.85, 0.0), abs=1e-12)
    assert tip.wing.elastic_axis_offset_m == pytest.approx((0.6 - 0.22) * 0.183, abs=1e-15)
    assert port.position_m == pytest.approx((0.3549 - 0.3 - 0.22 * 0.183, -0.3, 0.0))
    assert port.wing.elastic_axis_offset_m == pytest.approx(0.0, abs=1e-15)
    assert tail.position_m == pytest.approx((0.3549 - 0.85, 0.0, -0.05))
    assert s.airspeeds[0].position_m == pytest.approx((0.3549, 0.0, 0.0))
    # the wing carries them into every run
    assert aircraft.wing().sensors == s


def test_without_sensors_the_autopilot_imu_is_at_the_cg():
    aircraft = load_aircraft("bioflex_optimised")
    assert not aircraft.sensors()
    assert aircraft.sensors().autopilot_imu is CG_IMU
    assert not aircraft.wing().sensors


@pytest.mark.parametrize("extra, field", [
    ("[[sensors.imu]]\nname = \"a\"\n", "either position_m"),
    ("[[sensors.imu]]\nname = \"a\"\nposition_m = [0, 0, 0]\nwing_y_m = 0.2\n",
     "either position_m"),
    ("[[sensors.imu]]\nname = \"Tip\"\nposition_m = [0, 0, 0]\n", "sensors.imu[0].name"),
    ("[[sensors.imu]]\nname = \"a\"\nwing_y_m = 0.9\n", "sensors.imu[0].wing_y_m"),
    ("[[sensors.imu]]\nname = \"a\"\nwing_y_m = 0.5\nchord_position = 25\n",
     "chord_position"),
    ("[[sensors.imu]]\nname = \"a\"\nposition_m = [0, 0, 0]\ngyro_noise_rad_s = 57.3\n",
     "gyro_noise_rad_s"),
    ("[[sensors.imu]]\nname = \"a\"\nposition_m = [0, 0, 0]\nframe = \"wing\"\n", "frame"),
    ("[[sensors.imu]]\nname = \"a\"\nposition_m = [0, 0, 0]\nbias = 1\n",
     "sensors.imu[0]: unknown key 'bias'; accepted: "),
    ("[[sensors.imu]]\nname = \"a\"\nposition_m = [0, 0, 0]\nautopilot = true\n"
     "[[sensors.imu]]\nname = \"b\"\nposition_m = [0, 0, 0]\nautopilot = true\n",
     "the autopilot reads one IMU"),
    ("[[sensors.imu]]\nname = \"a\"\nposition_m = [0, 0, 0]\n"
     "[[sensors.imu]]\nname = \"a\"\nposition_m = [1, 0, 0]\n", "used twice"),
    ("[[sensors.imu]]\nname = \"a\"\nposition_m = [0, 0, 0]\nchord_position = 0.3\n",
     "only for a wing sensor"),
])
def test_bad_sensor_fields_are_one_line(tmp_path, extra, field):
    with pytest.raises(DefinitionError, match=field.replace("[", r"\[").replace("]", r"\]")
                       .replace(".", r"\.")) as info:
        load_aircraft(_write(tmp_path, "\n" + extra))
    assert "\n" not in str(info.value)


def test_a_clamped_wing_has_no_sensors(tmp_path):
    text = shipped_path("goland").read_text(encoding="utf-8")
    path = tmp_path / "g.toml"
    path.write_text(text + "\n[[sensors.imu]]\nname = \"a\"\nposition_m = [0, 0, 0]\n",
                    encoding="utf-8")
    from bioflex_jsb.definition.loader import load_definition

    with pytest.raises(DefinitionError, match="clamped wing"):
        load_definition(path)
