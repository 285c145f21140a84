"""Modal-data files: bring your own finite-element modes (TOML, read with :mod:`tomllib`).

This is the only module of :mod:`bioflex_jsb.structures` that touches files. The format is
documented in ``docs/structures.md`` ("Modal-data files"); an example is shipped as
``bioflex_jsb/data/modes/example_ribbed.toml``. In short::

    format = "bioflex-jsb-modes"        # required, identifies the file
    format_version = 1                  # required
    source = "my FE model, run 12"      # optional text
    notes = "..."                       # optional text

    [units]                             # required, every key required
    length = "mm"                       # "m" | "mm": stations and bending
    angle = "deg"                       # "rad" | "deg": twist
    frequency = "Hz"                    # "Hz" | "rad/s"
    generalised_mass = "kg*m^2"         # "kg*m^2" only

    [stations]
    y = [0.0, 85.0, ..., 850.0]         # starboard half, root (0) to tip, increasing

    [axes]                              # optional; scalar or one value per station
    x_elastic_frac = 0.5                # chord fraction aft of the leading edge (Eq. 12)
    x_inertial_frac = 0.5               # (Eq. 11); both default to 0.5 (Table 8, original)

    [[mode]]                            # one table per mode, lowest frequency first
    frequency = 30.9
    damping_ratio = 0.0                 # optional, default 0 (Section 3.1)
    generalised_mass = 4.87e-5          # half wing, for the shapes as given [kg·m²]
    bending = [...]                     # elastic-axis displacement per unit η, + DOWN
    twist = [...]                       # section twist per unit η, + LEADING EDGE UP

Shapes may be in any scaling: the reader rescales every mode to the project normalisation
(max |twist| = 1 rad/rad, tip twist positive; see :mod:`.modal_data`) and scales the
generalised mass with it (``normalise=False`` keeps the file's scaling).

Every problem raises :class:`ModalFileError` with a one-line message that names the file, the
key (e.g. ``mode[2].twist``) and, where it can be found, the line number.
"""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.inputs import (
    CHORD_FRACTION,
    Choice,
    Invalid,
    Kind,
    Real,
    keys_text,
    problem,
)
from bioflex_jsb.structures.modal_data import ModalData, ModalDataError

FORMAT_NAME = "bioflex-jsb-modes"
FORMAT_VERSION = 1

# Unit name -> factor to SI (m, rad, rad/s, kg·m²).
LENGTH_UNITS = {"m": 1.0, "mm": 1e-3}
ANGLE_UNITS = {"rad": 1.0, "deg": math.pi / 180.0}
FREQUENCY_UNITS = {"Hz": 2.0 * math.pi, "rad/s": 1.0}
GENERALISED_MASS_UNITS = {"kg*m^2": 1.0}
_UNIT_TABLES = {
    "length": LENGTH_UNITS,
    "angle": ANGLE_UNITS,
    "frequency": FREQUENCY_UNITS,
    "generalised_mass": GENERALISED_MASS_UNITS,
}

# Default axis position when [axes] is absent: Table 8, original wing (x_I = x_E = 0.5).
DEFAULT_AXIS_FRAC = 0.5

_TOP_KEYS = {"format", "format_version", "source", "notes", "units", "stations", "axes", "mode"}
_MODE_KEYS = {"frequency", "damping_ratio", "generalised_mass", "bending", "twist"}


# Largest modal-data file read [bytes]: a finite-element export of a few hundred stations
# and modes is a few MB; a bigger file is refused rather than read into memory.
MAX_MODAL_BYTES = 64 * 1024 * 1024


# Ranges of the numeric fields (SI, after the [units] conversion). These keep the model the
# file builds inside floating-point range and conditioning; they are far wider than any wing
# of this aircraft (Table 2: 31..107 Hz, generalised masses ~1e-5 kg·m² when normalised).
# ω: the state matrix holds ω_i² and 2ζ_iω_i beside rigid-body terms of 0.1..10 rad/s;
# past 1e5 rad/s (16 kHz) ω² = 1e10 and the eigenvalues lose 10 of their 16 digits; below
# 1e-2 rad/s (a ten-minute period) it is no structural mode of a clamped wing.
MIN_FREQUENCY_RAD_S = 1e-2
MAX_FREQUENCY_RAD_S = 1e5
# ζ: a structural mode is under-damped (0 <= ζ < 1), as the variant's structural_damping.
MAX_DAMPING_RATIO = 1.0  # excluded
# m_i of the normalised mode (max |twist| = 1 rad/rad, or bending-scaled): at least 7
# decades below Table 2's (the modal forces Q/m_i overflow to infinity near 5e-324); above,
# room for aircraft far larger than the prototype: a twist-normalised bending mode of a
# slender wing has little twist per metre of heave, so its m_i is large (the SGS-size beam
# of 7 kg/m with the centre of mass 0.05 c behind the elastic axis: 1.1e5; a 20 % longer
# one: 1.05e3 on its axes); 1e12 is 7 decades above that and still far inside doubles.
# a modal file's numbers: finite, in the file's own [units] (ranges are checked in SI after)
FINITE = Real("")
MIN_GENERALISED_MASS_KG_M2 = 1e-12
MAX_GENERALISED_MASS_KG_M2 = 1e12


class ModalFileError(InputError):
    """A modal-data file that cannot be used; one-line message naming key and line."""


class _Locator:
    """Finds the line of a key in the TOML text (for messages about parsed values)."""

    _HEADER = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_.\-]+)\s*\]\]?")

    def __init__(self, text: str) -> None:
        self.lines = text.splitlines()

    def line_of(self, table: str | None, key: str | None = None, index: int = 0) -> int | None:
        """1-based line of ``key`` in ``table`` (``index``-th ``[[table]]``); None if absent."""
        current: str | None = None
        count = -1
        key_re = re.compile(rf"^\s*{re.escape(key)}\s*=") if key else None
        for number, line in enumerate(self.lines, start=1):
            match = self._HEADER.match(line)
            if match:
                current = match.group(2)
                if current == table:
                    count += 1
                    if key is None and (match.group(1) == "[" or count == index):
                        return number
                continue
            in_table = (table is None and current is None) or (
                current == table and (count == index)
            )
            if key_re is not None and in_table and key_re.match(line):
                return number
        return None


class _Reader:
    def __init__(self, text: str, name: str) -> None:
        self.name = name
        self.loc = _Locator(text)

    def fail(self, what: str, message: str, table=None, key=None, index: int = 0):
        line = self.loc.line_of(table, key, index) if (table or key) else None
        if line is None and table is None and key:  # an unknown top-level [table]
            line = self.loc.line_of(key)
        where = f" (line {line})" if line is not None else ""
        raise problem(ModalFileError, self.name, what, message + where)

    def keys(self, t: dict, accepted, what: str, table=None, index: int = 0) -> None:
        """Unknown keys of table ``what`` in the one wording (:func:`bioflex_jsb.inputs.
        keys_text`): ``<file>: <table>: unknown key 'X'; accepted: … (and N more
        problems)``, at the first unknown key's line."""
        text = keys_text(t, sorted(accepted))
        if text is not None:
            first = sorted(str(k) for k in set(t) - set(accepted))[0]
            self.fail(what, text, table, first, index)

    # --------------------------------------------------------------------------------------
    def check(self, kind: Kind, value, what, table, key, index=0, element=None):
        """``value`` checked by a kind of :mod:`bioflex_jsb.inputs`; the problem names
        ``what`` (and the array ``element``) and the line."""
        try:
            return kind.check(value)
        except Invalid as exc:
            at = f"element {element}: " if element is not None else ""
            self.fail(what, at + exc.text, table, key, index)

    def number(self, value, what, table, key, index=0) -> float:
        return self.check(FINITE, value, what, table, key, index)

    def array(self, value, what, table, key, index=0, length=None) -> np.ndarray:
        if not isinstance(value, list):
            self.fail(what, f"expected an array of numbers, got {type(value).__name__}",
                      table, key, index)
        out = np.empty(len(value))
        for j, item in enumerate(value):
            out[j] = self.check(FINITE, item, what, table, key, index, element=j)
        if length is not None and out.size != length:
            self.fail(what, f"expected {length} values (one per station), got {out.size}",
                      table, key, index)
        return out

    def axis(self, value, what, key, k) -> np.ndarray:
        if isinstance(value, list):
            arr = self.array(value, what, "axes", key, length=k)
            for j, x in enumerate(arr):
                self.check(CHORD_FRACTION, x, what, "axes", key, element=j)
            return arr
        return np.full(k, self.check(CHORD_FRACTION, value, what, "axes", key))

    # --------------------------------------------------------------------------------------
    def parse(self, data: dict, normalise: bool) -> ModalData:
        """The file's tables read in order (header, units, stations, axes, modes), each
        problem one line naming the key; the modal data in SI, normalised if asked."""
        self._header(data)
        units, factor = self._units(data)
        y = self._stations(data, factor)
        k = y.size
        x_e, x_i = self._axes(data, k)
        modes = data.get("mode")
        if not isinstance(modes, list) or not modes:
            self.fail("mode", "no [[mode]] table: at least one mode is needed")
        read = [self._mode(mode, i, k, units, factor) for i, mode in enumerate(modes)]
        freq, damp, mass, bend, twist = (list(c) for c in zip(*read, strict=True))
        if np.any(np.diff(freq) < 0.0):
            j = int(np.argmax(np.diff(freq) < 0.0)) + 1
            self.fail(f"mode[{j + 1}].frequency",
                      "modes must be listed by increasing frequency", "mode", "frequency", j)
        try:
            modal = ModalData(
                frequencies_rad_s=np.array(freq),
                damping_ratios=np.array(damp),
                generalised_masses_kg_m2=np.array(mass),
                stations_m=y,
                bending_m=np.array(bend),
                twist_rad=np.array(twist),
                x_elastic_frac=x_e,
                x_inertial_frac=x_i,
                source=str(data.get("source", self.name)),
                notes=str(data.get("notes", "")),
            )
            scaled = modal.normalised()
        except ModalDataError as exc:  # should be caught above; keep the one-line promise
            self.fail("data", str(exc))
        for i, m in enumerate(scaled.generalised_masses_kg_m2):
            if not MIN_GENERALISED_MASS_KG_M2 <= m <= MAX_GENERALISED_MASS_KG_M2:
                self.fail(f"mode[{i + 1}].generalised_mass",
                          f"{m:g} kg*m^2 in the project normalisation (docs/structures.md) is "
                          f"outside {MIN_GENERALISED_MASS_KG_M2:g}.."
                          f"{MAX_GENERALISED_MASS_KG_M2:g}",
                          "mode", "generalised_mass", i)
        return scaled if normalise else modal


    def _header(self, data: dict) -> None:
        """Known top-level keys, the format's name and version, text source and notes."""
        self.keys(data, _TOP_KEYS, "")
        if data.get("format") != FORMAT_NAME:
            self.fail("format", f"missing or not {FORMAT_NAME!r}", None, "format")
        if data.get("format_version") != FORMAT_VERSION:
            self.fail("format_version", f"missing or not {FORMAT_VERSION}", None,
                      "format_version")
        for key in ("source", "notes"):
            if key in data and not isinstance(data[key], str):
                self.fail(key, "expected a string", None, key)

    def _units(self, data: dict) -> tuple[dict, dict[str, float]]:
        """The [units] table and each quantity's factor to SI."""
        units = data.get("units")
        if not isinstance(units, dict):
            self.fail("units", "missing [units] table (length, angle, frequency, "
                      "generalised_mass)")
        self.keys(units, _UNIT_TABLES, "units", "units")
        factor = {}
        for key, table in _UNIT_TABLES.items():
            if key not in units:
                self.fail(f"units.{key}", Choice(tuple(table)).missing_text(), "units")
            self.check(Choice(tuple(table), "unit"), units[key], f"units.{key}", "units", key)
            factor[key] = table[units[key]]
        return units, factor

    def _stations(self, data: dict, factor: dict[str, float]) -> np.ndarray:
        """The spanwise stations y [m]: at least two, strictly increasing, on the
        starboard half."""
        stations = data.get("stations")
        if not isinstance(stations, dict) or "y" not in stations:
            self.fail("stations.y", "missing [stations] table with y = [...]")
        self.keys(stations, ("y",), "stations", "stations")
        y = self.array(stations["y"], "stations.y", "stations", "y") * factor["length"]
        if y.size < 2:
            self.fail("stations.y", "need at least two stations", "stations", "y")
        if np.any(np.diff(y) <= 0.0):
            j = int(np.argmax(np.diff(y) <= 0.0)) + 1
            self.fail("stations.y", f"not strictly increasing at element {j}", "stations", "y")
        if y[0] < 0.0:
            self.fail("stations.y", "stations are on the starboard half (y ≥ 0)",
                      "stations", "y")
        return y

    def _axes(self, data: dict, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The elastic and inertial axes [chord fractions] at the ``k`` stations."""
        axes = data.get("axes", {})
        if not isinstance(axes, dict):
            self.fail("axes", "expected a table")
        self.keys(axes, ("x_elastic_frac", "x_inertial_frac"), "axes", "axes")
        x_e = self.axis(axes.get("x_elastic_frac", DEFAULT_AXIS_FRAC), "axes.x_elastic_frac",
                        "x_elastic_frac", k)
        x_i = self.axis(axes.get("x_inertial_frac", DEFAULT_AXIS_FRAC),
                        "axes.x_inertial_frac", "x_inertial_frac", k)
        return x_e, x_i

    def _mode(self, mode, i: int, k: int, units: dict, factor: dict[str, float]) -> tuple:
        """One [[mode]] in SI: (frequency [rad/s], damping ratio, generalised mass, bending
        [m] and twist [rad] at the ``k`` stations)."""
        tag = f"mode[{i + 1}]"
        if not isinstance(mode, dict):
            self.fail(tag, "expected a [[mode]] table")
        self.keys(mode, _MODE_KEYS, tag, "mode", i)
        for key in ("frequency", "generalised_mass", "bending", "twist"):
            if key not in mode:
                self.fail(f"{tag}.{key}", "missing", "mode", None, i)
        f = self.number(mode["frequency"], f"{tag}.frequency", "mode", "frequency", i)
        if f <= 0.0:
            self.fail(f"{tag}.frequency", "must be positive", "mode", "frequency", i)
        if not MIN_FREQUENCY_RAD_S <= f * factor["frequency"] <= MAX_FREQUENCY_RAD_S:
            self.fail(f"{tag}.frequency", f"{f:g} {units['frequency']} is outside "
                      f"{MIN_FREQUENCY_RAD_S:g}..{MAX_FREQUENCY_RAD_S:g} rad/s (the range "
                      "a structural mode of the model may have)", "mode", "frequency", i)
        z = self.number(mode.get("damping_ratio", 0.0), f"{tag}.damping_ratio", "mode",
                        "damping_ratio", i)
        if not 0.0 <= z < MAX_DAMPING_RATIO:
            self.fail(f"{tag}.damping_ratio", f"must satisfy 0 <= damping_ratio < "
                      f"{MAX_DAMPING_RATIO:g} (an under-damped mode), got {z:g}", "mode",
                      "damping_ratio", i)
        m = self.number(mode["generalised_mass"], f"{tag}.generalised_mass", "mode",
                        "generalised_mass", i)
        if m <= 0.0:
            self.fail(f"{tag}.generalised_mass", "must be positive", "mode",
                      "generalised_mass", i)
        b = self.array(mode["bending"], f"{tag}.bending", "mode", "bending", i, k)
        t = self.array(mode["twist"], f"{tag}.twist", "mode", "twist", i, k)
        if not np.any(b) and not np.any(t):
            self.fail(f"{tag}.twist", "bending and twist are both all zero", "mode",
                      "twist", i)
        return (f * factor["frequency"], z, m * factor["generalised_mass"],
                b * factor["length"], t * factor["angle"])

def parse_modal_text(text: str, *, name: str = "<modal text>", normalise: bool = True) -> ModalData:
    """Parse modal-file ``text``; ``name`` is used in error messages."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ModalFileError(f"{name}: TOML syntax error: {exc}".replace("\n", " ")) from None
    except RecursionError:  # nesting deeper than the interpreter's recursion limit
        raise ModalFileError(f"{name}: nests arrays or tables too deep to parse") from None
    return _Reader(text, name).parse(data, normalise)


def read_modal_file(path: str | Path, *, normalise: bool = True) -> ModalData:
    """Read a modal-data file into SI :class:`ModalData` (normalised unless told not to)."""
    from bioflex_jsb.files import read_input_text

    p = Path(path)
    # a regular file of at most MAX_MODAL_BYTES, UTF-8 (a FIFO or a device: refused at once)
    text = read_input_text(p, "modal-data file", MAX_MODAL_BYTES, ModalFileError)
    return parse_modal_text(text, name=str(p), normalise=normalise)


# ------------------------------------------------------------------------------------------
# Writer
# ------------------------------------------------------------------------------------------
def _fmt(x: float) -> str:
    # repr gives the shortest string that round-trips exactly; TOML accepts it as a float.
    s = repr(float(x))
    return s if any(c in s for c in ".en") else s + ".0"


def _fmt_array(values, per_line: int = 6) -> str:
    items = [_fmt(v) for v in values]
    if len(items) <= per_line:
        return "[" + ", ".join(items) + "]"
    rows = [", ".join(items[i:i + per_line]) for i in range(0, len(items), per_line)]
    return "[\n    " + ",\n    ".join(rows) + ",\n]"


def _fmt_axis(values) -> str:
    """A scalar when the axis position is the same at every station, else an array."""
    values = np.asarray(values, dtype=float)
    return _fmt(values[0]) if np.all(values == values[0]) else _fmt_array(values)


def _toml_string(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def format_modal_text(
    modes: ModalData,
    *,
    length: str = "m",
    angle: str = "rad",
    frequency: str = "Hz",
    header: str = "",
) -> str:
    """The TOML text of ``modes`` in the given units (see the module docstring)."""
    for key, unit in (("length", length), ("angle", angle), ("frequency", frequency)):
        if unit not in _UNIT_TABLES[key]:
            raise ModalFileError(f"writer: units.{key}: unknown unit {unit!r}")
    lf, af, ff = LENGTH_UNITS[length], ANGLE_UNITS[angle], FREQUENCY_UNITS[frequency]
    out = []
    if header:
        out += ["# " + line for line in header.splitlines()]
    out += [
        f"format = {_toml_string(FORMAT_NAME)}",
        f"format_version = {FORMAT_VERSION}",
        f"source = {_toml_string(modes.source)}",
        f"notes = {_toml_string(modes.notes)}",
        "",
        "[units]",
        f"length = {_toml_string(length)}",
        f"angle = {_toml_string(angle)}",
        f"frequency = {_toml_string(frequency)}",
        'generalised_mass = "kg*m^2"',
        "",
        "[stations]",
        f"y = {_fmt_array(modes.stations_m / lf)}",
        "",
        "[axes]",
        f"x_elastic_frac = {_fmt_axis(modes.x_elastic_frac)}",
        f"x_inertial_frac = {_fmt_axis(modes.x_inertial_frac)}",
    ]
    for i in range(modes.n_modes):
        out += [
            "",
            "[[mode]]",
            f"frequency = {_fmt(modes.frequencies_rad_s[i] / ff)}",
            f"damping_ratio = {_fmt(modes.damping_ratios[i])}",
            f"generalised_mass = {_fmt(modes.generalised_masses_kg_m2[i])}",
            f"bending = {_fmt_array(modes.bending_m[i] / lf)}",
            f"twist = {_fmt_array(modes.twist_rad[i] / af)}",
        ]
    return "\n".join(out) + "\n"


def write_modal_file(path: str | Path, modes: ModalData, **units_and_header) -> None:
    """Write ``modes`` to ``path`` (keywords as :func:`format_modal_text`)."""
    Path(path).write_text(format_modal_text(modes, **units_and_header), encoding="utf-8")
