"""Settings of a JSBSim run shared by the runtime and the file generators (pure data).

The runtime applies them to every run (:func:`bioflex_jsb.runtime.coupled_step.configure_airframe`);
the native export writes them into its script, so the plain JSBSim program flies with the same.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

# JSBSim integrators for every run (FGPropagate; 3 = Adams-Bashforth 2 for the rates and the
# positions): JSBSim's default rectangular Euler for the rotational rate is first order and
# alone moves the pitch-rate peak of a sharp-edged gust by 1.3 % when the step is halved.
INTEGRATORS: Mapping[str, int] = MappingProxyType({
    "simulation/integrator/rate/rotational": 3,
    "simulation/integrator/rate/translational": 3,
    "simulation/integrator/position/rotational": 3,
    "simulation/integrator/position/translational": 3,
})
