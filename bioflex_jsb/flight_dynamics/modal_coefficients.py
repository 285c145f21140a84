"""Aerodynamic coefficients of the structural modes: Table B1 by spanwise quadrature.

Geometry along the span (wing frame: x aft of the root leading edge, docs/conventions.md):

* x_ac(y): local aerodynamic centre (from :mod:`bioflex_jsb.aerodynamics`);
* x_E(y) = x_le(y) + x_E,frac·c(y): elastic axis;
* e(y) = x_E(y) − x_ac(y) [m]: distance of the aerodynamic centre **ahead** of the elastic
  axis (Fig. 14; positive when the elastic axis lies aft of the aerodynamic centre);
* d(y) = x_cg − x_ac(y) [m]: distance of the aerodynamic centre ahead of the centre of
  gravity; this is the "(x_E + e)" of Eq. (3) and Table B1.

Mode shapes (Section 3.1 signs): bending φ_i(y) positive **down** [m/rad], twist θ_i(y) =
dφ_i/dx positive **leading edge up** [rad/rad]. The upward displacement of the aerodynamic
centre per unit η_i is w_i(y) = e θ_i − φ_i, the virtual-work term of Table B1.

All integrals are over the whole span, −b/2..b/2 (Table B1), i.e. twice the starboard
integral for the symmetric modes used here.

The coefficients here do not depend on the flight condition; the trim-dependent ones
(C_Dη, C_0^Q) and the dimensional Table B2 derivatives are formed in
:mod:`bioflex_jsb.flight_dynamics.lti`. Table B1 itself needed no correction
(docs/decisions.md, "Paper typos", item 6).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from bioflex_jsb.inputs import unknown_key_text


@dataclass(frozen=True)
class ModalCoefficients:
    """Non-dimensional aerodynamic derivatives of n structural modes (Table B1).

    Arrays are indexed by mode: ``c_l_eta[i]`` is C_Lη_i; matrices ``c_eta_q[i, j]`` is
    C_ηj^Qi (generalised force on mode i due to η_j). Rate derivatives use c̄/(2u_0).
    ``overrides`` names every coefficient that was pinned instead of computed.
    """

    c_l_eta: np.ndarray
    c_l_etadot: np.ndarray
    c_m_eta: np.ndarray
    c_m_etadot: np.ndarray
    c_mac_q: np.ndarray
    c_alpha_q: np.ndarray
    c_q_q: np.ndarray
    c_eta_q: np.ndarray
    c_etadot_q: np.ndarray
    overrides: dict[str, float] = field(default_factory=dict)

    @property
    def n_modes(self) -> int:
        return int(self.c_l_eta.shape[0])

    def as_dict(self) -> dict[str, object]:
        """Named coefficients as plain lists (for JSON output)."""
        out: dict[str, object] = {}
        for name in (
            "c_l_eta", "c_l_etadot", "c_m_eta", "c_m_etadot", "c_mac_q",
            "c_alpha_q", "c_q_q", "c_eta_q", "c_etadot_q",
        ):
            out[name] = np.asarray(getattr(self, name)).tolist()
        out["overrides"] = dict(self.overrides)
        return out

    def with_overrides(self, overrides: Mapping[str, float]) -> ModalCoefficients:
        """Return a copy with coefficients pinned, e.g. ``{"C_eta1^Q1": -0.14}``."""
        arrays = {
            name: np.array(getattr(self, name), dtype=float, copy=True)
            for name in _OVERRIDE_TARGETS.values()
        }
        for key, value in overrides.items():
            attr, index = parse_override_key(key, self.n_modes)
            arrays[attr][index] = float(value)
        pinned = dict(self.overrides)
        pinned.update({k: float(v) for k, v in overrides.items()})
        return replace(self, overrides=pinned, **arrays)


# Override keys: the paper's symbols in ASCII. Mode numbers are 1-based as in the paper.
_OVERRIDE_TARGETS = {
    "C_L_eta": "c_l_eta",
    "C_L_etadot": "c_l_etadot",
    "C_m_eta": "c_m_eta",
    "C_m_etadot": "c_m_etadot",
    "C_alpha^Q": "c_alpha_q",
    "C_q^Q": "c_q_q",
    "C_eta^Q": "c_eta_q",
    "C_etadot^Q": "c_etadot_q",
}
_KEY_FORMS = (
    (re.compile(r"^C_L_eta(\d+)$"), "c_l_eta"),
    (re.compile(r"^C_L_etadot(\d+)$"), "c_l_etadot"),
    (re.compile(r"^C_m_eta(\d+)$"), "c_m_eta"),
    (re.compile(r"^C_m_etadot(\d+)$"), "c_m_etadot"),
    (re.compile(r"^C_alpha\^Q(\d+)$"), "c_alpha_q"),
    (re.compile(r"^C_q\^Q(\d+)$"), "c_q_q"),
    (re.compile(r"^C_eta(\d+)\^Q(\d+)$"), "c_eta_q"),
    (re.compile(r"^C_etadot(\d+)\^Q(\d+)$"), "c_etadot_q"),
)
# The override keys a file or a call may give, <i> and <j> mode numbers from 1.
OVERRIDE_KEYS = ("C_L_eta<i>", "C_L_etadot<i>", "C_m_eta<i>", "C_m_etadot<i>", "C_alpha^Q<i>",
                 "C_q^Q<i>", "C_eta<j>^Q<i>", "C_etadot<j>^Q<i>")


def parse_override_key(key: str, n_modes: int) -> tuple[str, tuple[int, ...]]:
    """Map an override key such as ``C_eta1^Q1`` to (attribute, index); ValueError if bad."""
    for pattern, attr in _KEY_FORMS:
        match = pattern.match(key.strip())
        if match:
            numbers = [int(g) for g in match.groups()]
            if any(n < 1 or n > n_modes for n in numbers):
                raise ValueError(
                    f"override {key!r} names mode {max(numbers)}, but the wing has {n_modes} modes"
                )
            if attr in ("c_eta_q", "c_etadot_q"):
                j, i = numbers
                return attr, (i - 1, j - 1)
            return attr, (numbers[0] - 1,)
    raise ValueError(unknown_key_text(key, OVERRIDE_KEYS))


@dataclass(frozen=True)
class SpanwiseGeometry:
    """Strip quantities at the aerodynamic quadrature stations of the starboard half.

    stations_m, weights_m [m]: ∫_0^{b/2} f dy ≈ Σ weights·f.
    cl_alpha_c_m: C_lα(y)·c(y) [m/rad]; chord_m [m]; e_m and d_m as in the module docstring.
    """

    stations_m: np.ndarray
    weights_m: np.ndarray
    chord_m: np.ndarray
    cl_alpha_c_m: np.ndarray
    e_m: np.ndarray
    d_m: np.ndarray


def spanwise_geometry(aero, planform, x_elastic_frac: np.ndarray, modal_stations_m: np.ndarray):
    """Combine the lifting-line strips with the elastic-axis line of the structure.

    ``aero`` is a :class:`bioflex_jsb.aerodynamics.vortex_lattice.SpanwiseAerodynamics`,
    ``planform`` a :class:`bioflex_jsb.parameters.wing.Planform`, ``x_elastic_frac`` the
    elastic-axis chord fraction at ``modal_stations_m``.
    """
    y = np.asarray(aero.stations_m, dtype=float)
    chord = np.asarray(aero.chord_m, dtype=float)
    xe_frac = np.interp(y, modal_stations_m, np.asarray(x_elastic_frac, dtype=float))
    x_e = planform.leading_edge_x_at(y) + xe_frac * chord
    x_ac = np.asarray(aero.x_ac_m, dtype=float)
    return SpanwiseGeometry(
        stations_m=y,
        weights_m=np.asarray(aero.weights_m, dtype=float),
        chord_m=chord,
        cl_alpha_c_m=np.asarray(aero.cl_alpha_c_m_per_rad, dtype=float),
        e_m=x_e - x_ac,
        d_m=planform.x_cg_m - x_ac,
    )


def modal_coefficients(
    modes,
    strips: SpanwiseGeometry,
    *,
    reference_area_m2: float,
    cbar_m: float,
) -> ModalCoefficients:
    """Table B1 coefficients of ``modes`` (a :class:`~bioflex_jsb.structures.modal_data.ModalData`).

    These do not depend on the flight condition. The trim-dependent ones are formed by the
    LTI builder: C_0^Q_i = α_w C_α^Q_i + C_mac·``c_mac_q``_i, where the trim lift
    distribution is taken proportional to C_lα c(y) at the wing's effective angle
    α_w = C_L0/C_Lα,w, and ``c_mac_q``_i = (1/(S c̄)) ∫ θ_i c² dy is the work of a unit
    section moment coefficient about the aerodynamic centre (Table B1, C_0^Q, second term).
    ``reference_area_m2`` S [m²] and ``cbar_m`` c̄ [m]: the aircraft's reference geometry
    (its :class:`~bioflex_jsb.parameters.airframe.AirframeData`), which the coefficients are
    normalised by.
    """
    y = strips.stations_m
    w = strips.weights_m * 2.0  # whole span: symmetric modes on a symmetric wing
    clac = strips.cl_alpha_c_m
    phi = np.array([np.interp(y, modes.stations_m, b) for b in modes.bending_m])  # (n, k)
    theta = np.array([np.interp(y, modes.stations_m, t) for t in modes.twist_rad])  # (n, k)
    e, d, c = strips.e_m, strips.d_m, strips.chord_m
    work = e * theta - phi  # upward AC displacement per unit η_i [m]
    s, cb = reference_area_m2, cbar_m

    def integral(f: np.ndarray) -> np.ndarray:
        return f @ w

    c_l_eta = integral(theta * clac) / s
    c_l_etadot = 2.0 * integral(phi * clac) / (s * cb)
    c_m_eta = integral(d * theta * clac) / (s * cb)
    c_m_etadot = 2.0 * integral(d * phi * clac) / (s * cb**2)
    c_mac_q = integral(theta * c**2) / (s * cb)
    c_alpha_q = integral(work * clac) / (s * cb)
    c_q_q = -2.0 * integral(d * work * clac) / (s * cb**2)
    # [i, j]: force on mode i due to η_j
    c_eta_q = np.einsum("ik,jk,k->ij", work, theta * clac, w) / (s * cb)
    c_etadot_q = 2.0 * np.einsum("ik,jk,k->ij", work, phi * clac, w) / (s * cb**2)
    return ModalCoefficients(
        c_l_eta=c_l_eta,
        c_l_etadot=c_l_etadot,
        c_m_eta=c_m_eta,
        c_m_etadot=c_m_etadot,
        c_mac_q=c_mac_q,
        c_alpha_q=c_alpha_q,
        c_q_q=c_q_q,
        c_eta_q=c_eta_q,
        c_etadot_q=c_etadot_q,
    )


def offset_shift_for_c_eta11(modes, strips: SpanwiseGeometry, target: float, *,
                             reference_area_m2: float, cbar_m: float) -> float:
    """Uniform shift Δe [m] of the aerodynamic-centre offset e(y) that makes C_η1^Q1 = target.

    C_η1^Q1 = (1/(S c̄)) ∫ θ_1 (e θ_1 − φ_1) C_lα c dy is linear in e, so
    Δe = (target − C_η1^Q1) S c̄ / ∫ θ_1² C_lα c dy. This is how a published C_η1^Q1 is
    pinned without breaking the other coefficients: every work term e θ_i − φ_i moves with
    the same e, as the paper's "adjusted to" (Sections 4.1, 4.2) does by moving the axes.
    """
    y = strips.stations_m
    theta1 = np.interp(y, modes.stations_m, modes.twist_rad[0])
    weight = float((theta1**2 * strips.cl_alpha_c_m) @ (2.0 * strips.weights_m))
    if weight <= 0.0:
        raise ValueError("mode 1 has no twist: C_eta1^Q1 cannot be pinned through e")
    current = modal_coefficients(modes, strips, reference_area_m2=reference_area_m2,
                                 cbar_m=cbar_m).c_eta_q[0, 0]
    return (target - current) * reference_area_m2 * cbar_m / weight


def shifted(strips: SpanwiseGeometry, delta_e_m: float) -> SpanwiseGeometry:
    """``strips`` with the aerodynamic-centre offset e(y) moved by ``delta_e_m`` [m]."""
    return replace(strips, e_m=strips.e_m + delta_e_m)
