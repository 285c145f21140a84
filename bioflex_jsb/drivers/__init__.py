"""Run drivers: thin loops over the one coupled step (``bioflex_jsb.runtime.coupled_step``).

``gust``: a nonlinear gust run; ``native``: a run of the native XML wing; ``sitl``: the step
paced to the wall clock behind a MAVLink link.
"""
