"""Topics, frames and JSON schemas of the MCAP logs (``docs/logging.md`` has the table).

``<model>`` is ``rigid``, ``coupled`` or ``qsd`` (``native`` in ArduPilot sessions); units are
in every field name and in the schema descriptions. Every field of a run topic is a double;
the ``autopilot`` topic (ArduPilot sessions) also has integers (protobuf ``fixed32``: a fixed
width, so its records are built a chunk at a time like the others) and enums.
"""

from __future__ import annotations

RUN_METADATA = "bioflex.run"
FRAME_METADATA = "bioflex.world_frame"
WORLD_FRAME = "world"
GROUPS = ("rigid_body", "modal", "modal_loads", "gust", "controls", "pose", "location",
          "lti_prediction", "autopilot", "loads", "imu", "airspeed_probe",
          "controller", "lateral")
# The sensor stations' topics (docs/aircraft.md, "Sensors"): one per IMU, one per airspeed
# probe, named by the sensor (topic(model, sensor_group(kind, name)))
# The autopilot topic's enums: (JSON schema / protobuf enum name, value names from 0); the
# values are the drivers' codes (bioflex_jsb.drivers.ardupilot ACTIONS and PHASES)
AUTOPILOT_ACTIONS = ("ACTION_STEP", "ACTION_RESEND", "ACTION_RESET")
AUTOPILOT_PHASES = ("PHASE_REST", "PHASE_LAUNCH", "PHASE_FLIGHT")
AUTOPILOT_ENUMS = (("Action", AUTOPILOT_ACTIONS), ("Phase", AUTOPILOT_PHASES))
# The events of a run (one topic for the file, not per model): foxglove.Log messages, whose
# level is foxglove.Log.Level (these names, numbered from 0)
EVENTS_TOPIC = "/bioflex/events"
EVENT_SCHEMA = "foxglove.Log"
EVENT_LEVELS = ("UNKNOWN", "DEBUG", "INFO", "WARNING", "ERROR", "FATAL")
# The aircraft in 3-D (bioflex_jsb.sinks.mcap.scene): foxglove.SceneUpdate messages on
# topic(model, SCENE_GROUP) (the wing, at the scene's rate) and topic(model, AIRFRAME_GROUP)
# (the rigid parts), in the body frame; its settings
# (the deformation's exaggeration, the rate, the geometry's sources) in SCENE_METADATA
SCENE_GROUP = "scene"
AIRFRAME_GROUP = "airframe"  # the rigid parts of the scene, once per chunk
SCENE_SCHEMA = "foxglove.SceneUpdate"
SCENE_METADATA = "bioflex.scene"


def topic(model: str, group: str) -> str:
    """The topic of ``group`` (one of :data:`GROUPS`) for the wing ``model``."""
    return f"/bioflex/{model}/{group}"


def sensor_group(kind: str, name: str) -> str:
    """The topic group of the sensor ``name`` of ``kind`` (``imu``, ``airspeed``):
    ``/bioflex/<model>/imu_<name>``, ``/bioflex/<model>/airspeed_<name>``."""
    return f"{kind}_{name}"


def body_frame(model: str) -> str:
    return f"{model}_body"


def _num(description: str) -> dict:
    return {"type": "number", "description": description}


_TIME = {
    "type": "object",
    "title": "time",
    "description": "simulation time since the start of the run",
    "properties": {"sec": {"type": "integer", "minimum": 0, "description": "whole seconds [s]"},
                   "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999,
                            "description": "nanoseconds [ns]"}},
}

# Fields of rigid_body, in message order: (field, row key, description).
RIGID_FIELDS = (
    ("du_m_s", "u", "airspeed perturbation from trim [m/s]"),
    ("dalpha_rad", "alpha", "angle-of-attack perturbation from trim, against the air [rad]"),
    ("dtheta_rad", "theta", "pitch-angle perturbation from trim [rad]"),
    ("airspeed_m_s", "airspeed_m_s", "true airspeed [m/s]"),
    ("n_z", "n_z", "load factor, up, 1 in level flight [-]"),
    ("roll_rad", "phi_rad", "roll angle φ, right wing down positive (NED Euler) [rad]"),
    ("pitch_rad", "theta_rad", "pitch angle θ, nose up positive (NED Euler) [rad]"),
    ("yaw_rad", "psi_rad", "heading ψ, clockwise from north (NED Euler) [rad]"),
    ("p_rad_s", "p_rad_s", "roll rate about body x (forward) [rad/s]"),
    ("q_rad_s", "q", "pitch rate about body y (starboard), nose up [rad/s]"),
    ("r_rad_s", "r_rad_s", "yaw rate about body z (down) [rad/s]"),
    ("altitude_m", "altitude_m", "altitude above sea level [m]"),
)
# Fields logged only when the run provides them (row key = field name).
RIGID_OPTIONAL = (
    ("alpha_rad", "angle of attack against the air [rad]"),
    ("beta_rad", "sideslip angle, wind from starboard positive [rad]"),
    ("v_north_m_s", "inertial velocity, north [m/s]"),
    ("v_east_m_s", "inertial velocity, east [m/s]"),
    ("v_down_m_s", "inertial velocity, down [m/s]"),
)

# rigid_body's field → the run's channel it holds (what a reader rebuilds the run with)
RIGID_BODY_CHANNELS: dict[str, str] = {
    **{f: k for f, k, _ in RIGID_FIELDS}, **{f: f for f, _ in RIGID_OPTIONAL}}

SCHEMAS: dict[str, dict] = {
    "rigid_body": {
        "title": "bioflex.RigidBody",
        "description": "Airframe state after each step; perturbations (d…) are from the trim "
        "at the run start. The position is on the pose topic (world frame, local ENU) and "
        "the location topic (WGS-84); the time is the message's log time.",
        "type": "object",
        "properties": {
            **{f: _num(d) for f, _, d in RIGID_FIELDS},
            **{f: _num(d) for f, d in RIGID_OPTIONAL},
        },
    },
    "modal": {
        "title": "bioflex.Modal",
        "description": "Modal coordinates of the elastic wing (perturbations from trim); "
        "modes normalised on twist, positive leading edge up (docs/conventions.md).",
        "type": "object",
        "properties": {
            "eta_rad": {"type": "array", "items": {"type": "number"},
                        "description": "η_i, element i is mode i+1 [rad]"},
            "eta_dot_rad_s": {"type": "array", "items": {"type": "number"},
                              "description": "η̇_i, element i is mode i+1 [rad/s]"},
        },
    },
    "modal_loads": {
        "title": "bioflex.ModalLoads",
        "description": "Incremental loads of the elastic wing applied to the airframe.",
        "type": "object",
        "properties": {
            "lift_n": _num("lift, up, normal to the air velocity [N]"),
            "drag_n": _num("drag, aft, along the air velocity [N]"),
            "pitch_moment_n_m": _num("pitching moment about the CG, nose up [N*m]"),
        },
    },
    "gust": {
        "title": "bioflex.Gust",
        "description": "Wind field applied to the airframe (vertical gust only).",
        "type": "object",
        "properties": {
            "w_g_m_s": _num("vertical gust velocity, up [m/s] (JSBSim wind-down = -w_g)"),
        },
    },
    "controls": {
        "title": "bioflex.Controls",
        "description": "Control inputs (held at trim in gust runs).",
        "type": "object",
        "properties": {
            "elevator_rad": _num("elevator deflection, trailing edge down positive [rad]"),
            "throttle": _num("throttle, 0 to 1 [-]"),
        },
    },
    "pose": {
        "title": "foxglove.FrameTransform",
        "description": "Aircraft pose: transform from the parent frame `world` (local ENU, "
        "origin at the first sample of the file) to the child frame `<model>_body` (x "
        "forward, y left, z up).",
        "type": "object",
        "properties": {
            "timestamp": _TIME,
            "parent_frame_id": {"type": "string", "description": "parent frame (world)"},
            "child_frame_id": {"type": "string", "description": "child frame (<model>_body)"},
            "translation": {
                "type": "object", "title": "foxglove.Vector3",
                "description": "body origin (CG) in the world frame [m]",
                "properties": {"x": _num("east [m]"), "y": _num("north [m]"),
                               "z": _num("up [m]")},
            },
            "rotation": {
                "type": "object", "title": "foxglove.Quaternion",
                "description": "rotation of the body frame in the world frame [-]",
                "properties": {"x": _num("x [-]"), "y": _num("y [-]"), "z": _num("z [-]"),
                               "w": _num("w [-]")},
            },
        },
    },
    "location": {
        "title": "foxglove.LocationFix",
        "description": "Aircraft position on the WGS-84 ellipsoid (exact, from the simulation).",
        "type": "object",
        "properties": {
            "timestamp": _TIME,
            "frame_id": {"type": "string", "description": "frame at the position (body)"},
            "latitude": _num("geodetic latitude [deg]"),
            "longitude": _num("longitude [deg]"),
            "altitude": _num("altitude above sea level [m]"),
            "position_covariance": {
                "type": "array", "items": {"type": "number"}, "minItems": 9, "maxItems": 9,
                "description": "ENU position covariance, row-major [m^2] (zero: exact)"},
            "position_covariance_type": {
                "type": "integer", "enum": [0, 1, 2, 3],
                "description": "0 unknown, 1 approximated, 2 diagonal known, 3 known"},
        },
    },
    "lti_prediction": {
        "title": "bioflex.LtiPrediction",
        "description": "Response of the linear model (Eq. 4) to the same gust samples, as "
        "perturbations from trim.",
        "type": "object",
        "properties": {
            "du_m_s": _num("airspeed perturbation [m/s]"),
            "dalpha_rad": _num("angle-of-attack perturbation, against the air [rad]"),
            "q_rad_s": _num("pitch rate [rad/s]"),
            "dtheta_rad": _num("pitch-angle perturbation [rad]"),
            "n_z": _num("load factor [-]"),
            "eta_rad": {"type": "array", "items": {"type": "number"},
                        "description": "modal coordinates, element i is mode i+1 [rad]"},
        },
    },
    "autopilot": {
        "title": "bioflex.Autopilot",
        "description": "ArduPilot's side of an ArduPlane SITL session (bioflex-jsb ardupilot): "
        "one message per servo frame answered, resends and resets included, in the order "
        "they arrived. Log time: the session's physics time when the frame arrived (the start "
        "of the step it drives; it goes on across ArduPilot restarts); timestamp_s: the "
        "physics time of the reply (what ArduPilot's clock follows).",
        "type": "object",
        "properties": {
            "frame_count": {"type": "integer", "minimum": 0, "maximum": 4294967295,
                            "description": "ArduPilot's frame counter (uint32) [count]"},
            "frame_rate_hz": {"type": "integer", "minimum": 0, "maximum": 65535,
                              "description": "ArduPilot's frame rate request, SIM_RATE_HZ "
                              "[Hz]"},
            "pwm_us": {"type": "array", "items": {"type": "integer"},
                       "description": "servo outputs, element i is servo i+1, 16 or 32 of "
                       "them (SERVO_32_ENABLE); 0: a channel ArduPilot does not drive [µs]"},
            "aileron_cmd_norm": _num("fcs/aileron-cmd-norm mapped from servo 1, + rolls "
                                     "right, -1 to 1 [-]"),
            "elevator_cmd_norm": _num("fcs/elevator-cmd-norm mapped from servo 2, + trailing "
                                      "edge down (nose down), -1 to 1 [-]"),
            "throttle_cmd_norm": _num("fcs/throttle-cmd-norm of every engine mapped from "
                                      "servo 3, 0 to 1 [-]"),
            "rudder_cmd_norm": _num("fcs/rudder-cmd-norm mapped from servo 4, + trailing "
                                    "edge left (nose left), -1 to 1 [-]; the four commands "
                                    "are applied to JSBSim in flight only"),
            "action": {"type": "string", "title": "Action", "enum": list(AUTOPILOT_ACTIONS),
                       "description": "what the lock-step server did: a physics step, the "
                       "same reply again without a step (a repeated frame_count), or a "
                       "physics reset then a step (frame_count went back: ArduPilot "
                       "restarted)"},
            "phase": {"type": "string", "title": "Phase", "enum": list(AUTOPILOT_PHASES),
                      "description": "the aircraft after the frame: at rest on the launcher, "
                      "on the launcher's stroke, or flying (the coupled step)"},
            "timestamp_s": _num("physics time of the state in the reply [s] (0 at ArduPilot's "
                                "start and restarts)"),
        },
    },
}


# The sensor stations (bioflex_jsb.simulation.sensors; docs/aircraft.md "Sensors"): one
# message per step on each sensor's topic, the run's channels imu_<name>_<field>
SCHEMAS["imu"] = {
    "title": "bioflex.Imu",
    "description": "An IMU at its station (the channel's metadata: sensor, and the run's "
    "meta['sensors'] its position and axes): the specific force and the rates in its own "
    "axes, the rigid body's at its point plus the elastic wing's modes for a wing station, "
    "with its bias and noise (ArduPilot's SIM_ACC*/SIM_GYR* meanings). Log time: the step's.",
    "type": "object",
    "properties": {
        "ax_m_s2": _num("specific force along the sensor's x axis (body x forward when "
                        "mounted straight) [m/s^2]; at rest level, z reads -g"),
        "ay_m_s2": _num("specific force along the sensor's y axis (starboard) [m/s^2]"),
        "az_m_s2": _num("specific force along the sensor's z axis (down) [m/s^2]"),
        "gx_rad_s": _num("rate about the sensor's x axis [rad/s]"),
        "gy_rad_s": _num("rate about the sensor's y axis [rad/s]"),
        "gz_rad_s": _num("rate about the sensor's z axis [rad/s]"),
    },
}
SCHEMAS["airspeed_probe"] = {
    "title": "bioflex.AirspeedProbe",
    "description": "An airspeed probe at its station: the true airspeed of the air at its "
    "point (the CG's, the rotation's and the wing's modal velocity), with its noise.",
    "type": "object",
    "properties": {"airspeed_m_s": _num("true airspeed at the probe [m/s]")},
}


def _station_loads(method: str, what: str, unit: str, sign: str) -> dict:
    return {"type": "array", "items": {"type": "number"},
            "description": f"{what} by {method} at each monitoring station, {sign}; element j "
            f"is station j (the channel's metadata: stations_m [m from the root], "
            f"station_fractions of the semispan); empty when the run has no {method} [{unit}]"}


# The wing's section loads of a gust run (bioflex_jsb.sinks.mcap.loads_topic; docs/loads.md
# has the methods, frames and signs): totals, the 1 g part included
SCHEMAS["loads"] = {
    "title": "bioflex.SectionLoads",
    "description": "Section loads of the starboard half wing at its monitoring stations, "
    "the 1 g static part included (its values in the channel's metadata static_1g), by force "
    "summation (fs: the strips' aerodynamic loads, the gust's included, minus the wing's "
    "inertia) and by mode displacement (md: EI phi'' eta, GJ theta' eta); wing frame x aft, "
    "y starboard, z up. One message per step at the step's log time, in chunks of their "
    "own written after the steps' (a step's pitch acceleration is the central difference "
    "of q: its loads wait for the next step).",
    "type": "object",
    "properties": {
        f"{tag}_{quantity}": _station_loads(method, what, unit, sign)
        for tag, method in (("fs", "force summation"), ("md", "mode displacement"))
        for quantity, what, unit, sign in (
            ("shear_n", "vertical shear of the wing outboard", "N", "up positive"),
            ("bending_n_m", "bending moment about the station's x axis", "N*m",
             "tip up positive (upper surface in compression)"),
            ("torque_n_m", "torque about the elastic axis", "N*m",
             "leading edge up positive"))
    },
}
# A controller in the loop of a gust run (bioflex_jsb.sinks.mcap.controller_topic;
# bioflex_jsb.simulation.controller): what it read and what it commanded, every step
SCHEMAS["controller"] = {
    "title": "bioflex.Controller",
    "description": "The controller in the loop (bioflex_jsb.simulation.controller), one "
    "message per step at the step's log time, in chunks of their own after the steps': the "
    "commands it wrote from the step's row (JSBSim's flight controls move the surface in "
    "that step, so the controls topic shows it at the next step) and the signals it read. "
    "The channel's metadata: its name, kind, signals, commands, states, sample time.",
    "type": "object",
    "properties": {
        "elevator_cmd_rad": _num("elevator commanded over the trim, trailing edge down "
                                 "positive; NaN when it does not command the elevator [rad]"),
        "throttle_cmd": _num("throttle commanded over the trim; NaN when it does not "
                             "command the throttle [-]"),
        "signals": {"type": "array", "items": {"type": "number"},
                    "description": "the signals it read at the step, element i the channel "
                    "metadata's signals[i], as the run's channels (SI; a linear controller "
                    "reads their perturbations from the trim values in the metadata)"},
        # after signals: the older fields keep their protobuf numbers
        "flaperon_cmd_rad": _num("flaperon (both ailerons together) commanded over the "
                                 "trim, trailing edges down positive; NaN when it does not "
                                 "command the flaperon [rad]"),
        "aileron_cmd_rad": _num("aileron (left - right)/2 commanded over the trim on both "
                                "wing halves, + rolls right; NaN when it does not command "
                                "the aileron [rad]"),
    },
}
# The antisymmetric wing of a full-span run (bioflex_jsb.sinks.mcap.lateral_topic;
# bioflex_jsb.simulation.full_span), every step
SCHEMAS["lateral"] = {
    "title": "bioflex.Lateral",
    "description": "Both wing halves (a full-span run, bioflex_jsb.simulation.full_span), "
    "one message per step at the step's log time, in chunks of their own after the steps': "
    "the aileron JSBSim flew, the elastic rolling moment applied over the step, the tip "
    "twist of each half, the antisymmetric modal state, and the side force and yawing "
    "moment applied over the step.",
    "type": "object",
    "properties": {
        "aileron_rad": _num("JSBSim's aileron, (left - right)/2 of the surfaces' angles, "
                            "positive rolling right [rad]"),
        "modal_roll_n_m": _num("the antisymmetric deformation's rolling moment applied to "
                               "the airframe (JSBSim's modal-roll), right wing down "
                               "positive [N*m]"),
        "tip_twist_starboard_rad": _num("starboard tip twist, symmetric plus antisymmetric "
                                        "modes, leading edge up positive [rad]"),
        "tip_twist_port_rad": _num("port tip twist, symmetric minus antisymmetric modes, "
                                   "leading edge up positive [rad]"),
        "asym_eta_rad": {"type": "array", "items": {"type": "number"},
                         "description": "antisymmetric modal coordinates eta_a (starboard "
                         "tip twist positive) [rad]"},
        "asym_eta_dot_rad_s": {"type": "array", "items": {"type": "number"},
                               "description": "their rates [rad/s]"},
        "modal_side_n": _num("the antisymmetric deformation's side force applied to the "
                             "airframe (JSBSim's modal-side), along body +y (to starboard) "
                             "[N]"),
        "modal_yaw_n_m": _num("the deformation's yawing moment applied to the airframe "
                              "(JSBSim's modal-yaw), about body +z, nose right positive "
                              "[N*m]"),
    },
}
# The LTI model's section loads on its prediction topic, under the loads topic's field names
# (Foxglove plots /bioflex/<model>/lti_prediction.fs_bending_n_m[0] beside
# /bioflex/<model>/loads.fs_bending_n_m[0]): totals, the run's 1 g part added to the LTI's
# perturbation (drivers/compare.py; the channel's metadata as the loads channel's)
SCHEMAS["lti_prediction"]["properties"].update({
    name: dict(prop, description="the linear model's (the run's 1 g part plus the LTI load "
               "output C x + D w_g) " + prop["description"])
    for name, prop in SCHEMAS["loads"]["properties"].items()})
for _s in SCHEMAS.values():
    _s["$schema"] = "https://json-schema.org/draft/2020-12/schema"


# -- the protobuf schemas the logs are written with (docs/logging.md, Encoding) -------------
def _proto_fields(group: str) -> tuple[tuple[str, int, bool], ...]:
    """(field, number, repeated) of a bioflex message: the JSON schema's fields in order,
    numbered from 1 (every field a double)."""
    props = SCHEMAS[group]["properties"]
    return tuple((name, i + 1, props[name].get("type") == "array")
                 for i, name in enumerate(props))


def _typed_fields(group: str) -> tuple[tuple[str, int, bool, int, str | None], ...]:
    """(field, number, repeated, protobuf type, enum) of a message with integer or enum
    fields: a JSON ``integer`` (or an array of them) is ``fixed32``, a ``string`` with an
    ``enum`` the protobuf enum named by its ``title``, anything else a double."""
    from bioflex_jsb.sinks.mcap_io.protobuf import TYPE_DOUBLE, TYPE_ENUM, TYPE_FIXED32

    props = SCHEMAS[group]["properties"]
    out = []
    for name, number, repeated in _proto_fields(group):
        p = props[name]
        kind = p["items"]["type"] if repeated else p.get("type")
        if kind == "integer":
            out.append((name, number, repeated, TYPE_FIXED32, None))
        elif kind == "string" and "enum" in p:
            out.append((name, number, repeated, TYPE_ENUM, p["title"]))
        else:
            out.append((name, number, repeated, TYPE_DOUBLE, None))
    return tuple(out)


def _proto_schemas() -> dict[str, tuple[str, bytes]]:
    from bioflex_jsb.sinks.mcap_io import foxglove_descriptors as fox
    from bioflex_jsb.sinks.mcap_io.protobuf import (
        file_descriptor,
        file_descriptor_set,
        typed_file_descriptor,
    )

    out = {}
    for group, schema in SCHEMAS.items():
        name = schema["title"]
        if group == "pose":
            files = [fox.FILES[f] for f in fox.FRAME_TRANSFORM_FILES]
        elif group == "location":
            files = [fox.FILES[f] for f in fox.LOCATION_FIX_FILES]
        elif group == "autopilot":
            package, message = name.split(".")
            files = [typed_file_descriptor(package, message, _typed_fields(group),
                                           AUTOPILOT_ENUMS)]
        else:
            package, message = name.split(".")
            files = [file_descriptor(package, message, _proto_fields(group))]
        out[group] = (name, file_descriptor_set(files))
    return out


PROTO_FIELDS = {g: _proto_fields(g) for g in SCHEMAS if g not in ("pose", "location")}
# group → (schema name, serialised FileDescriptorSet): schema encoding "protobuf"
PROTO_SCHEMAS: dict[str, tuple[str, bytes]] = _proto_schemas()


def _event_schema() -> tuple[str, bytes]:
    from bioflex_jsb.sinks.mcap_io import foxglove_descriptors as fox
    from bioflex_jsb.sinks.mcap_io.protobuf import file_descriptor_set

    return EVENT_SCHEMA, file_descriptor_set(fox.files(fox.LOG_FILES))


# the events topic's schema: (name, serialised FileDescriptorSet), schema encoding "protobuf"
EVENTS_PROTO_SCHEMA: tuple[str, bytes] = _event_schema()


def _scene_schema() -> tuple[str, bytes]:
    from bioflex_jsb.sinks.mcap_io import foxglove_descriptors as fox
    from bioflex_jsb.sinks.mcap_io.protobuf import file_descriptor_set

    return SCENE_SCHEMA, file_descriptor_set(fox.files(fox.SCENE_UPDATE_FILES))


# the scene topics' schema: (name, serialised FileDescriptorSet), schema encoding "protobuf"
SCENE_PROTO_SCHEMA: tuple[str, bytes] = _scene_schema()
