"""flight_dynamics."""
