"""Export of state-space models: .npz, .mat (scipy.io), python-control ``StateSpace``.

A file holds A, B, C, D; the names and units of states, inputs and outputs; ``model``,
``speed_m_s``; and ``metadata``, a JSON text of what the model was built from (wing, speed,
mass basis, aerodynamic model, overrides, …). :func:`read_state_space` reads it back and
:func:`to_python_control` accepts a :class:`StateSpace`, such a file's path, or what
``numpy.load`` / ``scipy.io.loadmat`` returned for it.
"""

from __future__ import annotations

import io
import json
import zipfile
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.files import read_input_bytes
from bioflex_jsb.flight_dynamics.lti import StateSpace

FORMATS = (".npz", ".mat")
# Largest model file read [bytes], and what its arrays may declare: a model of n states holds
# about (n + inputs + outputs)^2 numbers; the project's have fewer than 40 states (< 20 kB).
MAX_MODEL_FILE_BYTES = 64 * 1024 * 1024
_NAME_KEYS = ("states", "state_units", "inputs", "input_units", "outputs", "output_units")


def _json_safe(value):
    if isinstance(value, dict):
        return {str(k): _json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_json_safe(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value


def _arrays(ss: StateSpace, metadata: Mapping[str, object] | None) -> dict[str, object]:
    meta = dict(ss.notes)
    meta.update(metadata or {})
    meta.setdefault("model", ss.model)
    meta.setdefault("speed_m_s", ss.speed_m_s)
    return {
        "A": ss.a, "B": ss.b, "C": ss.c, "D": ss.d,
        "states": np.array(ss.states), "state_units": np.array(ss.state_units),
        "inputs": np.array(ss.inputs), "input_units": np.array(ss.input_units),
        "outputs": np.array(ss.outputs), "output_units": np.array(ss.output_units),
        "model": np.array(ss.model), "speed_m_s": np.array(ss.speed_m_s),
        "metadata": np.array(json.dumps(_json_safe(meta), sort_keys=True)),
    }


def write_state_space(ss: StateSpace, path: str | Path,
                      metadata: Mapping[str, object] | None = None) -> Path:
    """Write ``ss`` with its signal names and units and ``metadata`` (merged over
    ``ss.notes``, stored as JSON text); the suffix picks the format."""
    p = Path(path)
    if p.suffix not in FORMATS:
        raise InputError(f"unknown model file type {p.suffix!r}; accepted: {', '.join(FORMATS)}")
    if p.suffix == ".npz":
        with open(p, "wb") as fh:  # np.savez on a name would append .npz to other suffixes
            np.savez(fh, **_arrays(ss, metadata))
    else:
        from scipy.io import savemat

        savemat(p, _arrays(ss, metadata))
    return p


def _names(value) -> tuple[str, ...]:
    # .mat stores a string array as rows padded with blanks: strip them
    return tuple(str(x).strip() for x in np.asarray(value).reshape(-1))


def _scalar_text(value) -> str:
    arr = np.asarray(value)
    return str(arr.reshape(-1)[0]).strip() if arr.size else ""


def state_space_from_arrays(data: Mapping[str, object], source: str = "model file") -> StateSpace:
    """A :class:`StateSpace` from the arrays of a model file (``numpy.load`` of a .npz, or
    ``scipy.io.loadmat`` of a .mat)."""
    try:
        a, b, c, d = (np.atleast_2d(np.asarray(data[k], dtype=float)) for k in "ABCD")
        names = {k: _names(data[k]) for k in _NAME_KEYS}
        model = _scalar_text(data["model"])
        speed = float(np.asarray(data["speed_m_s"], dtype=float).reshape(-1)[0])
    except KeyError as exc:
        raise InputError(f"{source}: not a bioflex-jsb model file (no {exc.args[0]!r})") from None
    except (IndexError, TypeError, ValueError) as exc:  # an empty speed, text for a matrix
        raise InputError(f"{source}: not a bioflex-jsb model file ({exc})") from None
    notes: dict[str, object] = {}
    if "metadata" in data:
        try:
            notes = json.loads(_scalar_text(data["metadata"]))
        except ValueError:
            raise InputError(f"{source}: its metadata is not valid JSON") from None
        if not isinstance(notes, dict):
            raise InputError(f"{source}: its metadata is not a JSON object")
    n, m, p = a.shape[0], b.shape[1], c.shape[0]
    if (b.shape[0], c.shape[1], d.shape) != (n, n, (p, m)) or len(names["states"]) != n \
            or len(names["inputs"]) != m or len(names["outputs"]) != p:
        raise InputError(f"{source}: the matrices and the signal names do not agree in size")
    return StateSpace(model=model, speed_m_s=speed, a=a, b=b, c=c, d=d, notes=notes, **names)


def _check_npz_sizes(raw: bytes, source: str) -> None:
    """InputError unless the arrays of the .npz ``raw`` declare at most
    :data:`MAX_MODEL_FILE_BYTES` in all (what ``numpy.load`` will decompress: the zip reader
    stops at a member's declared size)."""
    with zipfile.ZipFile(io.BytesIO(raw)) as z:
        declared = sum(info.file_size for info in z.infolist())
    if declared > MAX_MODEL_FILE_BYTES:
        raise InputError(f"{source}: its arrays declare {declared} bytes, more than the "
                         f"{MAX_MODEL_FILE_BYTES} a model file may hold")


def read_state_space(path: str | Path) -> StateSpace:
    """Read a model file written by :func:`write_state_space` (``bioflex-jsb export``)."""
    p = Path(path)
    if p.suffix not in FORMATS:
        raise InputError(f"unknown model file type {p.suffix!r}; accepted: {', '.join(FORMATS)}")
    raw = read_input_bytes(p, "model file", MAX_MODEL_FILE_BYTES)
    try:
        if p.suffix == ".npz":
            _check_npz_sizes(raw, str(p))
            with np.load(io.BytesIO(raw), allow_pickle=False) as data:
                return state_space_from_arrays(dict(data), str(p))
        from scipy.io import loadmat
        from scipy.io.matlab import MatReadError

        try:
            arrays = loadmat(io.BytesIO(raw))
        except MatReadError as exc:  # truncated, or not a .mat file at all
            raise InputError(f"{str(p)!r} is not a model file: {exc}") from None
        return state_space_from_arrays(arrays, str(p))
    except InputError:
        raise
    except OSError as exc:
        raise InputError(f"cannot read {str(p)!r}: {exc.strerror or exc}") from None
    # not a zip/mat file: an empty .npz is an EOFError, a damaged zip a BadZipFile
    except (ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise InputError(f"{str(p)!r} is not a model file: "
                         f"{exc or type(exc).__name__}") from None


def to_python_control(model):
    """A python-control ``StateSpace`` with named states, inputs and outputs.

    ``model``: a :class:`StateSpace`, the path of a file ``bioflex-jsb export`` wrote (.npz
    or .mat), or the mapping ``numpy.load``/``scipy.io.loadmat`` returned for one: its
    :meth:`~bioflex_jsb.state_space.StateSpace.to_control`. Needs the optional dependency
    (``pip install "bioflex-jsb[control]"``; without it one line, exit 2 in the CLI).
    """
    if isinstance(model, str | Path):
        ss = read_state_space(model)
    elif isinstance(model, StateSpace):
        ss = model
    elif isinstance(model, Mapping) or hasattr(model, "files"):  # dict, NpzFile
        ss = state_space_from_arrays({k: model[k] for k in model.keys()})
    else:
        raise InputError(f"to_python_control needs a StateSpace, a model file or its arrays, "
                         f"got {type(model).__name__}")
    return ss.to_control()  # the one conversion (bioflex_jsb.state_space)
