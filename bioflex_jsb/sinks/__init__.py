"""Sinks: where a run's results go (MCAP logs, plots, exported models).

A sink takes a run description (:class:`bioflex_jsb.simulation.run.RunDescription`) and the
run's data, never command-line arguments.
"""
