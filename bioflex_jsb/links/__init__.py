"""Links to peers over the network: the MAVLink vehicle that ground stations talk to
(``mavlink``, set up by ``mavlink_setup``) and ArduPilot's JSON SITL physics link
(``ardupilot_json``)."""
