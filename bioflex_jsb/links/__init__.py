"""Links to peers over the network: the MAVLink vehicle that ground stations talk to."""
