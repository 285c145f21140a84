"""Export of state-space models: .npz, .mat (scipy.io), python-control ``StateSpace``."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import StateSpace

FORMATS = (".npz", ".mat")


def _arrays(ss: StateSpace) -> dict[str, object]:
    return {
        "A": ss.a, "B": ss.b, "C": ss.c, "D": ss.d,
        "states": np.array(ss.states), "state_units": np.array(ss.state_units),
        "inputs": np.array(ss.inputs), "input_units": np.array(ss.input_units),
        "outputs": np.array(ss.outputs), "output_units": np.array(ss.output_units),
        "model": np.array(ss.model), "speed_m_s": np.array(ss.speed_m_s),
    }


def write_state_space(ss: StateSpace, path: str | Path) -> Path:
    """Write ``ss`` with its signal names and units; the suffix picks the format."""
    p = Path(path)
    if p.suffix not in FORMATS:
        raise InputError(f"unknown model file type {p.suffix!r}; accepted: {', '.join(FORMATS)}")
    if p.suffix == ".npz":
        np.savez(p, **_arrays(ss))
    else:
        from scipy.io import savemat

        savemat(p, _arrays(ss))
    return p


def to_python_control(ss: StateSpace):
    """A python-control ``StateSpace`` with named states, inputs and outputs.

    Needs the optional dependency (``pip install "bioflex-jsb[control]"``).
    """
    try:
        import control
    except ImportError:
        raise ImportError(
            "python-control is not installed; pip install 'bioflex-jsb[control]'"
        ) from None
    return control.ss(ss.a, ss.b, ss.c, ss.d, states=list(ss.states), inputs=list(ss.inputs),
                      outputs=list(ss.outputs), name=f"bioflex_{ss.model}")
