"""Wing variants by name, and the elastic-wing model built from physical data.

A variant is a physical wing: chordwise inertial and elastic axis positions (Eq. 11-12),
ribs or not (Table 2), optionally a modal file from the user's own FE model, and optionally
coefficient overrides. The chain is

    structure (bioflex_jsb.structures)  → modes φ_i, θ_i, ω_i, m_i
    lifting line (bioflex_jsb.aerodynamics) → C_lα c(y), x_ac(y)
    Table B1 quadrature (modal_coefficients) → C-coefficients (+ overrides, reported)
    → :class:`~bioflex_jsb.flight_dynamics.lti.ElasticWingModel`.

Generalised-mass basis (docs/decisions.md, "Generalised mass basis"): the beam model, like
Table 2, gives the generalised masses of a clamped *half* wing, while Table B1 integrates the
aerodynamic work over the *whole* span. ``"consistent"`` (default) divides the whole-span
forces by the whole-wing generalised mass 2 m_i; ``"paper"`` divides them by the half-wing
m_i as Table B2 reads literally, which doubles every H term. Every output names the basis.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path

import numpy as np

from bioflex_jsb.aerodynamics.vortex_lattice import SpanwiseAerodynamics
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.modal_coefficients import (
    modal_coefficients,
    offset_shift_for_c_eta11,
    parse_override_key,
    shifted,
    spanwise_geometry,
)
from bioflex_jsb.inputs import CHORD_FRACTION, Flag, Invalid, Kind, Real, Text, problem
from bioflex_jsb.parameters.airframe import PROTOTYPE_AIRFRAME, AirframeData
from bioflex_jsb.parameters.sensors import NO_SENSORS, Sensors
from bioflex_jsb.parameters.wing import (
    DEFAULT_PLANFORM,
    MODAL_DAMPING_RATIO,
    PUBLISHED_C_ETA1_Q1,
    Planform,
)
from bioflex_jsb.structures.beam_wing import BeamWing
from bioflex_jsb.structures.modal_data import ModalData
from bioflex_jsb.tomlfile import read_toml
from bioflex_jsb.values import is_finite_real

MASS_BASES = ("paper", "consistent")
DEFAULT_MASS_BASIS = "consistent"
DEFAULT_N_MODES = 3
# ESTIMATE: section moment coefficient about the aerodynamic centre of a thin cambered plate
# with ≈ 2 % camber (thin-aerofoil theory, −π/2·(2 h/c)·… ≈ −0.05). Enters only C_0^Q (H_iu).
CM_AC_SECTION = -0.05


class VariantError(InputError):
    """A wing variant that cannot be built; the message names the field."""


@dataclass(frozen=True)
class WingVariant:
    """A physical wing.

    x_inertial_frac, x_elastic_frac: axis positions as fractions of the chord aft of the
    leading edge [-]; ribs: the ribbed structure of Fig. 2(b) (Table 2 "with ribs") or the
    homogeneous membrane (unused with a modes file or a beam: None in :meth:`as_dict`);
    modes_file: a modal-data file (docs/structures.md) that replaces the beam model; beam: a
    definition's beam wing (:class:`~bioflex_jsb.structures.beam_wing.BeamWing`: its
    sections, point masses, struts), whose modes replace the beam model as a modes file's
    do (not both); overrides: pinned
    Table B1 coefficients (reported by every output); pinned_c_eta1_q1: pin C_η1^Q1 by
    shifting the aerodynamic offset e(y) of every mode uniformly (the paper's "adjusted
    to"; reported by every output); published_c_eta1_q1: the paper's value for comparison
    (None for user variants).
    """

    name: str
    x_inertial_frac: float
    x_elastic_frac: float
    ribs: bool = True
    structural_damping: float = MODAL_DAMPING_RATIO
    modes_file: str | None = None
    overrides: dict[str, float] = field(default_factory=dict)
    pinned_c_eta1_q1: float | None = None
    published_c_eta1_q1: float | None = None
    description: str = ""
    beam: BeamWing | None = None

    def __post_init__(self) -> None:
        if self.beam is not None and self.modes_file:
            raise VariantError(f"wing {self.name!r}: a beam and a modes file both give the "
                               "modes; give one")

    def as_dict(self) -> dict[str, object]:
        out = {
            "name": self.name,
            "x_inertial_frac": self.x_inertial_frac,
            "x_elastic_frac": self.x_elastic_frac,
            # a modes file's (or a beam's) wing has no membrane beam whose ribs the flag
            # would choose: null, not a "true" a reader of the log's metadata would take for
            # a property of the wing
            "ribs": None if (self.modes_file or self.beam is not None) else self.ribs,
            "structural_damping": self.structural_damping,
            "modes_file": self.modes_file,
            "overrides": dict(self.overrides),
            "pinned_c_eta1_q1": self.pinned_c_eta1_q1,
            "published_c_eta1_q1": self.published_c_eta1_q1,
            "description": self.description,
        }
        if self.beam is not None:  # the beam's content (sections, masses, mesh) by digest
            out["beam"] = f"sha256:{self.beam.digest}"
        return out


def _pub(name: str) -> float:
    return PUBLISHED_C_ETA1_Q1[name]


# The named variants. Axis positions of ``original`` and ``optimised`` are Table 8's; the
# paper gives none for the four sensitivity variants of Section 4, only that the inertial
# axis moved backward by "about 0.3~0.35 of the chord" (we use 0.32 c, and the mirror image
# forward) and that C_η1^Q1 was "adjusted to" ±0.1. The strip model cannot reproduce the
# published C_η1^Q1 of any of the six from these axes (docs/decisions.md, "Wing variants":
# with the elastic axis at mid chord, aft of the quarter-chord aerodynamic centre, strip
# theory gives C_η1^Q1 ≈ +0.3, a wing that diverges at 12 m/s), so each named variant pins
# C_η1^Q1 to its published value, as the paper itself did; every output reports the pin and
# the physical value beside it.
def _named(name: str, x_i: float, x_e: float, description: str) -> WingVariant:
    pub = _pub(name)
    return WingVariant(name, x_i, x_e, pinned_c_eta1_q1=pub, published_c_eta1_q1=pub,
                       description=description)


VARIANTS: dict[str, WingVariant] = {
    "original": _named("original", 0.5, 0.5, "homogeneous axes at mid chord (Table 8)"),
    "optimised": _named("optimised", 0.25, 0.22, "bird-like forward axes (Table 8, Fig. 2(b))"),
    "inertial-forward": _named(
        "inertial-forward", 0.18, 0.5, "inertial axis 0.32 c forward (Section 4.2, Table 6)"
    ),
    "elastic-forward": _named(
        "elastic-forward", 0.5, 0.25, "elastic axis 0.25 c forward (Section 4.2)"
    ),
    "inertial-backward": _named(
        "inertial-backward", 0.82, 0.5, "inertial axis 0.32 c backward (Section 4.1)"
    ),
    "elastic-backward": _named(
        "elastic-backward", 0.5, 0.75, "elastic axis 0.25 c backward (Section 4.1)"
    ),
}


def variant_names() -> tuple[str, ...]:
    return tuple(VARIANTS)


def get_variant(name: str) -> WingVariant:
    try:
        return VARIANTS[name]
    except KeyError:
        raise VariantError(
            f"unknown wing {name!r}; valid names: {', '.join(VARIANTS)} "
            "(or a variant file ending in .toml)"
        ) from None


# ---------------------------------------------------------------------------------------
# Variant files
# ---------------------------------------------------------------------------------------
PHYSICAL_PIN = "physical"  # pin_c_eta1_q1 = "physical": no pin, the strip model's value
_VARIANT_KEYS = {
    "name", "base", "x_inertial_frac", "x_elastic_frac", "ribs", "structural_damping",
    "modes_file", "overrides", "pin_c_eta1_q1", "description",
}


# Largest |value| of a pinned coefficient (overrides, pin_c_eta1_q1) [-]. The named wings'
# Table B1 coefficients are all below 1.2 in magnitude, and strip theory bounds a modal lift
# derivative by the 2-D lift slope 2π per rad of unit twist (the modes are normalised to
# max |twist| = 1): 100 leaves 16 times that for what-if studies. Beyond it the coefficient
# describes no wing (1e308 overflows the state matrix to infinity).
MAX_PINNED_COEFFICIENT = 100.0


# The fields of a variant file, each a kind of bioflex_jsb.inputs (its range and message).
COEFFICIENT = Real("", -MAX_PINNED_COEFFICIENT, MAX_PINNED_COEFFICIENT,
                   hint=" (a Table B1 coefficient of any wing is a few units at most)")
# structural damping ratio ζ [-]: 1 is critical damping, no longer an oscillating mode
STRUCTURAL_DAMPING = Real("(damping ratio)", 0.0, 1.0, below=True)
NAME = Text()  # printed and logged: printable text (no newline, no bidirectional override)
DESCRIPTION = Text(empty=True)
PATH_TEXT = Text()  # a modes file's path


def _field(kind: Kind, value, key: str, source: str):
    """``value`` checked by ``kind``; the problem is one line naming the file and ``key``."""
    try:
        return kind.check(value)
    except Invalid as exc:
        raise problem(VariantError, source, key, exc.text) from None


def variant_from_mapping(data: dict, source: str, base_dir: Path | None = None) -> WingVariant:
    """Build a variant from a parsed variant file (see docs/wing_variants.md)."""
    _check_variant_keys(data, source)
    base = _variant_base(data, source)
    values: dict[str, object] = {"name": _field(NAME, data.get("name", Path(source).stem),
                                                "name", source)}
    values.update(_structure_values(data, source, base_dir))
    if "overrides" in data:
        values["overrides"] = _overrides(data["overrides"], source)
    modes = _variant_modes(data, values, source)
    values["pinned_c_eta1_q1"] = _variant_pin(data, base, values, source, modes)
    if "description" in data:
        values["description"] = _field(DESCRIPTION, data["description"], "description", source)
    return replace(base, published_c_eta1_q1=None, **values)


def _check_variant_keys(data: dict, source: str) -> None:
    """A variant file's keys: some, all known; an aircraft or clamped-wing definition named
    as what it is."""
    if not data:
        raise VariantError(f"{source}: the variant file sets nothing (empty, or comments "
                           f"only); give at least one of {', '.join(sorted(_VARIANT_KEYS))} "
                           "(docs/wing_variants.md), or --wing NAME for a named wing")
    unknown = sorted(set(data) - _VARIANT_KEYS)
    if "airframe" in unknown:
        raise VariantError(f"{source} is an aircraft definition (it has [airframe]), not a "
                           "wing variant: give it as --aircraft FILE (docs/aircraft.md)")
    if isinstance(data.get("wing"), dict) and "stations" in data["wing"]:
        raise VariantError(f"{source} is a clamped-wing definition (it has [wing] stations), "
                           "not a wing variant: analyse it with flutter --clamped FILE "
                           "(docs/aircraft.md)")
    if unknown:
        raise VariantError(
            f"{source}: unknown key {unknown[0]!r}; accepted: {', '.join(sorted(_VARIANT_KEYS))}"
        )


def _variant_base(data: dict, source: str) -> WingVariant:
    """The named wing a variant starts from (``base``; a file's base is not a file)."""
    base_name = data.get("base", "original")
    if not isinstance(base_name, str) or base_name not in VARIANTS:
        raise VariantError(f"{source}: base {base_name!r} is not a named wing; accepted: "
                           f"{', '.join(VARIANTS)}")
    return get_variant(base_name)


def _structure_values(data: dict, source: str, base_dir: Path | None) -> dict[str, object]:
    """The axes [chord fraction], ribs, structural damping [ratio] and modes file (relative
    to ``base_dir``) a variant file gives."""
    values: dict[str, object] = {}
    for key in ("x_inertial_frac", "x_elastic_frac"):
        if key in data:
            values[key] = _field(CHORD_FRACTION, data[key], key, source)
    if "ribs" in data:
        values["ribs"] = _field(Flag(), data["ribs"], "ribs", source)
    if "structural_damping" in data:
        values["structural_damping"] = _field(STRUCTURAL_DAMPING, data["structural_damping"],
                                              "structural_damping", source)
    if "modes_file" in data:
        path = Path(_field(PATH_TEXT, data["modes_file"], "modes_file", source))
        if base_dir is not None and not path.is_absolute():
            path = base_dir / path
        values["modes_file"] = str(path)
    return values


def _overrides(ov, source: str) -> dict[str, float]:
    """``overrides``: a table of coefficient name (docs/wing_variants.md) = value."""
    if not isinstance(ov, dict):
        raise problem(VariantError, source, "overrides", "must be a table (coefficient = value)")
    checked = {}
    for k, v in ov.items():
        try:
            parse_override_key(k, DEFAULT_N_MODES)
        except ValueError as exc:
            raise problem(VariantError, source, "overrides", str(exc)) from None
        checked[k] = _field(COEFFICIENT, v, f"overrides.{k}", source)
    return checked


def _variant_modes(data: dict, values: dict, source: str):
    """The modes file's modes (None without one); its axes become the variant's, and the
    keys a modes file decides are refused beside it."""
    if "modes_file" not in data:
        return None
    moved = [k for k in ("x_inertial_frac", "x_elastic_frac", "ribs") if k in data]
    if moved:
        raise VariantError(
            f"{source}: {moved[0]!r} has no effect with 'modes_file': the modes file "
            "gives the structure, its [axes] table the axis positions; move it there "
            "or remove it")
    from bioflex_jsb.structures.modal_file import read_modal_file

    modes = read_modal_file(values["modes_file"])
    # the axes the wing has: the modes file's (their mean where it gives one per station)
    values["x_inertial_frac"] = float(np.mean(modes.x_inertial_frac))
    values["x_elastic_frac"] = float(np.mean(modes.x_elastic_frac))
    return modes


def _variant_pin(data: dict, base: WingVariant, values: dict, source: str, modes
                 ) -> float | None:
    """C_η1^Q1 pinned by the file (``pin_c_eta1_q1``: a number, or PHYSICAL_PIN for the
    strip model's own value) or inherited from the base (:func:`_inherited_pin`)."""
    if "pin_c_eta1_q1" not in data:
        return _inherited_pin(base, values, source, modes)
    pin = data["pin_c_eta1_q1"]
    if pin == PHYSICAL_PIN:
        return None
    if not is_finite_real(pin):
        raise VariantError(f"{source}: pin_c_eta1_q1: must be a finite number or "
                           f"{PHYSICAL_PIN!r} (the strip model's own value), got {pin!r}")
    return _field(COEFFICIENT, pin, "pin_c_eta1_q1", source)


def _differs(a, b) -> bool:
    return bool(np.any(np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float)) > 1e-9))


def _inherited_pin(base: WingVariant, values: dict, source: str, modes) -> float | None:
    """The base's C_η1^Q1 pin for a variant file that does not say ``pin_c_eta1_q1``.

    Inherited when the variant keeps the base's axes and structure (e.g. the base's wing with
    the user's own FE modes at the same axes, other damping, overrides): the pin is part of
    the named wing. Refused, with what to add, when the variant moves an axis or the ribs, or
    brings a modes file with other [axes]: the base's pin was set for the base's axes, and
    whether it still holds is the user's decision.
    """
    if base.pinned_c_eta1_q1 is None:
        return None
    changes = []
    if modes is not None:
        for key, mine in (("x_inertial_frac", modes.x_inertial_frac),
                          ("x_elastic_frac", modes.x_elastic_frac)):
            if _differs(mine, getattr(base, key)):
                changes.append(f"the modes file's [axes] {key} is not {getattr(base, key):g}")
    else:
        for key in ("x_inertial_frac", "x_elastic_frac", "ribs"):
            if key in values and values[key] != getattr(base, key):
                changes.append(f"{key} = {values[key]} (base: {getattr(base, key)})")
    if changes:
        raise VariantError(
            f"{source}: {changes[0]}, so base {base.name!r}'s C_eta1^Q1 pin "
            f"({base.pinned_c_eta1_q1:g}) may not apply; add pin_c_eta1_q1 = "
            f"{base.pinned_c_eta1_q1:g} to keep it, another number, or pin_c_eta1_q1 = "
            f"\"{PHYSICAL_PIN}\" for the strip model's own value (docs/wing_variants.md)")
    return base.pinned_c_eta1_q1


def load_variant_file(path: str | Path) -> WingVariant:
    """Read a TOML variant file; :class:`VariantError` with a one-line reason if bad."""
    p = Path(path)
    data = read_toml(p, "variant file", VariantError)
    return variant_from_mapping(data, str(p), p.parent)


def resolve_variant(name_or_path: str) -> WingVariant:
    """A named variant, or a variant file if the argument ends in ``.toml``."""
    if name_or_path.endswith(".toml"):
        return load_variant_file(name_or_path)
    return get_variant(name_or_path)


# ---------------------------------------------------------------------------------------
# Building the model
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class WingBuild:
    """Everything built for one variant: the modes, the strips, and the LTI wing model."""

    variant: WingVariant
    modes: ModalData
    aero: SpanwiseAerodynamics
    model: ElasticWingModel
    mass_basis: str
    physical_c_eta1_q1: float
    e_shift_frac: float = 0.0  # pin of C_η1^Q1: shift of e(y) [fraction of chord]
    planform: Planform = DEFAULT_PLANFORM  # the strips' planform (and the CG's x_cg_m)
    # the section loads' monitoring stations [fractions of the semispan, root 0]: an aircraft
    # definition's [loads] stations (Aircraft.wing), None: the loads' default stations
    monitoring_stations: tuple[float, ...] | None = None
    # the aircraft's sensor stations in body axes from the CG (an aircraft definition's
    # [sensors], Aircraft.wing; none: the autopilot's IMU at the CG)
    sensors: Sensors = NO_SENSORS
    # the antisymmetric loading of the lateral elastic models (aerodynamics/
    # antisymmetric_loading.py: LATERAL_AERO): "strips" (default) or "lattice"
    lateral_aero: str = "strips"

    @property
    def airframe(self) -> AirframeData:
        """The aircraft the wing was built for (its S, c̄, mass, I_yy, derivatives)."""
        return self.model.airframe

    def summary(self) -> dict[str, object]:
        c = self.model.coefficients
        return {
            "variant": self.variant.as_dict(),
            "mass_basis": self.mass_basis,
            "frequencies_hz": (np.asarray(self.model.frequencies_rad_s) / (2 * math.pi)).tolist(),
            "generalised_masses_kg_m2": np.asarray(self.model.generalised_masses_kg_m2).tolist(),
            "c_eta1_q1": float(c.c_eta_q[0, 0]),
            "c_eta1_q1_physical": self.physical_c_eta1_q1,
            "c_eta1_q1_published": self.variant.published_c_eta1_q1,
            "e_shift_frac": self.e_shift_frac,
            "overrides": dict(c.overrides),
            "coefficients": c.as_dict(),
        }


def with_lateral_aero(build: WingBuild, lateral_aero: str) -> WingBuild:
    """``build`` with its lateral elastic models' antisymmetric loading ``lateral_aero``
    (``strips`` or ``lattice``; aerodynamics/antisymmetric_loading.py); anything else is
    refused in one line."""
    from bioflex_jsb.aerodynamics.antisymmetric_loading import LATERAL_AERO

    if lateral_aero not in LATERAL_AERO:
        raise InputError(f"lateral_aero: unknown lateral aerodynamics {lateral_aero!r}; "
                         f"accepted: {', '.join(LATERAL_AERO)}")
    return build if build.lateral_aero == lateral_aero else replace(
        build, lateral_aero=lateral_aero)


@lru_cache(maxsize=4)
def _aero(planform: Planform):
    from bioflex_jsb.aerodynamics.vortex_lattice import solve_spanwise_aerodynamics

    return solve_spanwise_aerodynamics(planform)


def structural_modes(variant: WingVariant, n_modes: int = DEFAULT_N_MODES):
    """The variant's modes: its modal file, or the calibrated half-wing beam; the lowest
    ``n_modes`` of them (:func:`modes_used_note` says so when a file holds more)."""
    modes = _all_modes(variant, n_modes)
    if modes.n_modes < n_modes:
        raise VariantError(
            f"wing {variant.name!r} has {modes.n_modes} modes, {n_modes} were asked for"
        )
    return modes.truncated(n_modes)


def modes_used_note(variant: WingVariant, n_modes: int = DEFAULT_N_MODES) -> str | None:
    """One line when the variant's modes file holds more than the ``n_modes`` the model
    flies (which ones are used, and why); None otherwise."""
    if not variant.modes_file:
        return None
    modes = _all_modes(variant, n_modes)
    if modes.n_modes <= n_modes:
        return None
    f = modes.frequencies_hz
    return (f"wing {variant.name!r}: the modes file holds {modes.n_modes} modes; the model "
            f"uses the lowest {n_modes} ({f[0]:.4g}..{f[n_modes - 1]:.4g} Hz) and leaves out "
            f"the other {modes.n_modes - n_modes} (from {f[n_modes]:.4g} Hz): the paper's wing "
            f"model has {n_modes} modes (Table 2), and the coefficient names, logs and "
            "exports are made for them")


def membrane_structure(variant: WingVariant):
    """The calibrated membrane wing structure of a named variant (the prototype's ribbed or
    unribbed wing, :mod:`bioflex_jsb.parameters.wing_structure`): the beam its modes and
    sections are computed from when the variant has neither a beam nor a modes file."""
    from bioflex_jsb.parameters.wing_structure import RIBBED_WING, UNRIBBED_WING

    return RIBBED_WING if variant.ribs else UNRIBBED_WING


def _all_modes(variant: WingVariant, n_modes: int):
    """Every mode of the variant's modal file, or ``n_modes`` of its beam wing (a
    definition's) or of the calibrated membrane beam."""
    if variant.beam is not None:
        modes = variant.beam.modes(n_modes)
    elif variant.modes_file:
        from bioflex_jsb.structures.modal_file import read_modal_file

        modes = read_modal_file(variant.modes_file)
    else:
        from bioflex_jsb.structures.wing_model import wing_modes

        modes = wing_modes(
            membrane_structure(variant),
            n_modes,
            x_inertial_frac=variant.x_inertial_frac,
            x_elastic_frac=variant.x_elastic_frac,
        )
    return modes


# Wings built in this process, most recently used last; bounded so that a long sweep over
# many variants does not keep every build (each holds its modes and strips: ~100 kB).
_BUILD_CACHE: OrderedDict[tuple, WingBuild] = OrderedDict()
BUILD_CACHE_SIZE = 64


def build_wing(
    variant: WingVariant,
    n_modes: int = DEFAULT_N_MODES,
    mass_basis: str = DEFAULT_MASS_BASIS,
    planform: Planform = DEFAULT_PLANFORM,
    airframe: AirframeData = PROTOTYPE_AIRFRAME,
) -> WingBuild:
    """Structure → lifting line → Table B1 → :class:`ElasticWingModel` for ``variant`` on
    ``airframe`` (its S and c̄ non-dimensionalise Table B1; the model carries it, so every
    analysis of the wing takes the airframe's mass, inertia and derivatives).

    Results are cached per (variant, n_modes, mass basis, planform, airframe): building is
    pure.
    """
    if mass_basis not in MASS_BASES:
        raise VariantError(f"unknown mass basis {mass_basis!r}; accepted: {', '.join(MASS_BASES)}")
    key = (repr(sorted(variant.as_dict().items())), _file_version(variant.modes_file),
           n_modes, mass_basis, planform, airframe)
    if key in _BUILD_CACHE:
        _BUILD_CACHE.move_to_end(key)
        return _BUILD_CACHE[key]
    build = _BUILD_CACHE[key] = _build(variant, n_modes, mass_basis, planform, airframe)
    while len(_BUILD_CACHE) > BUILD_CACHE_SIZE:
        _BUILD_CACHE.popitem(last=False)
    return build


def _file_version(path: str | None) -> tuple | None:
    """What identifies the contents of a modes file for the build cache (a file edited
    between two builds in one process is read again): its size, change time and inode."""
    if not path:
        return None
    try:
        st = Path(path).stat()
    except OSError:  # unreadable: the build reads it and reports why, in one line
        return None
    return (st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino)


# How far the stations of a modes file may be from the root (first) and the tip (last) of the
# half wing, as a fraction of b/2: the strips interpolate the shapes at their own stations and
# hold the end value beyond the last one, so a file that stops short of the tip, or runs past
# it, would give a wing with shapes it does not have. 1 %: rounding of an FE mesh's nodes.
STATION_SPAN_TOLERANCE = 0.01


def _check_modes_fit(variant: WingVariant, modes: ModalData, planform: Planform) -> None:
    """A modes file's stations span this half wing; a C_η1^Q1 pin needs twist in mode 1."""
    half = planform.semispan_m
    y = modes.stations_m
    off = max(y[0], abs(y[-1] - half))  # from the root, and from the tip [m]
    if (variant.modes_file or variant.beam is not None) and off > STATION_SPAN_TOLERANCE * half:
        raise VariantError(
            f"wing {variant.name!r}: the modes file's stations run {y[0]:g}..{y[-1]:g} m; "
            f"accepted: from the root (0 m) to the tip (b/2 = {half:g} m) within "
            f"{100 * STATION_SPAN_TOLERANCE:g} % (stations.y, in its [units] length)")
    if variant.pinned_c_eta1_q1 is not None and modes.twist_free()[0]:
        raise VariantError(
            f"wing {variant.name!r}: mode 1 is pure bending (no twist), so its C_eta1^Q1 (the "
            "aerodynamic stiffness of its twist) is zero for any aerodynamic offset and cannot "
            f"be pinned to {variant.pinned_c_eta1_q1:g}; set pin_c_eta1_q1 = "
            f"\"{PHYSICAL_PIN}\" (the mode then flies with its plunge terms C_L_etadot, "
            "C_etadot^Q) or give mode 1 its twist")


def _build(variant: WingVariant, n_modes: int, mass_basis: str, planform: Planform,
           airframe: AirframeData) -> WingBuild:
    modes = structural_modes(variant, n_modes)
    _check_modes_fit(variant, modes, planform)
    aero = _aero(planform)
    strips = spanwise_geometry(aero, planform, modes.x_elastic_frac, modes.stations_m)
    ref = dict(reference_area_m2=airframe.reference.area_m2,
               cbar_m=airframe.reference.mean_chord_m)
    physical = modal_coefficients(modes, strips, **ref)
    coeffs = physical
    e_shift_m = 0.0
    if variant.pinned_c_eta1_q1 is not None:
        e_shift_m = offset_shift_for_c_eta11(modes, strips, variant.pinned_c_eta1_q1, **ref)
        coeffs = modal_coefficients(modes, shifted(strips, e_shift_m), **ref)
        coeffs = coeffs.with_overrides({"C_eta1^Q1": variant.pinned_c_eta1_q1})
    if variant.overrides:
        coeffs = coeffs.with_overrides(variant.overrides)
    masses = np.asarray(modes.generalised_masses_kg_m2, dtype=float)
    if mass_basis == "consistent":
        masses = 2.0 * masses
    # Damping rule (docs/wing_variants.md): each mode gets the larger of its own ζ_i (the
    # modes file's damping_ratio, 0 for the beam) and the variant's structural_damping.
    damping = np.asarray(modes.damping_ratios, dtype=float)
    if variant.structural_damping > 0.0:
        damping = np.maximum(damping, variant.structural_damping)
    model = ElasticWingModel(
        name=variant.name,
        frequencies_rad_s=np.asarray(modes.frequencies_rad_s, dtype=float),
        damping_ratios=damping,
        generalised_masses_kg_m2=masses,
        coefficients=coeffs,
        # on the airframe's reference area S, as C_L and Table B1 are: the lattice's slope
        # is on the planform's own area (the SGS: 14.072 m² of a 1 m chord against SGS.xml's
        # S = 13.073 m²; α_w = C_L / C_Lα,w then left the wing carrying 1.076 × W at 1 g);
        # the prototype's two areas are equal (0.3111 m², to 1 ulp)
        wing_lift_slope_per_rad=float(aero.wing_lift_slope_per_rad * aero.reference_area_m2
                                      / airframe.reference.area_m2),
        cm_ac=CM_AC_SECTION,
        tip_twist_per_eta=np.asarray(modes.twist_rad, dtype=float)[:, -1].copy(),
        airframe=airframe,
    )
    return WingBuild(variant, modes, aero, model, mass_basis, float(physical.c_eta_q[0, 0]),
                     e_shift_m / planform.chord_m, planform)
