"""Paper-versus-model comparisons as data (used by scripts/ and the tests).

Each row pairs a published number with the model's, with the relative differences. Nothing
here prints; ``scripts/paper_tables.py`` formats the rows.
"""

from __future__ import annotations

from dataclasses import dataclass

from bioflex_jsb.flight_dynamics import eigen
from bioflex_jsb.flight_dynamics.wing_model import DEFAULT_MASS_BASIS, VARIANTS, build_wing
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import PROTOTYPE_AIRFRAME

# Where the paper prints a table for a variant: (table name, data) — Tables 4, 5, 7 are
# held out of our copy of the paper.
PUBLISHED_TABLES = {
    "original": ("Table 3", P.TABLE3_SHORT_PERIOD),
    "inertial-forward": ("Table 6", P.TABLE6_SHORT_PERIOD),
}


@dataclass(frozen=True)
class EigenRow:
    """One short-period row: paper (re, im) and model (re, im) [rad/s]."""

    table: str
    wing: str
    speed_m_s: float
    model: str
    paper_re: float
    paper_im: float
    model_re: float
    model_im: float

    @property
    def re_error(self) -> float:
        """(model − paper)/|paper| of the real part [-]."""
        return (self.model_re - self.paper_re) / abs(self.paper_re)

    @property
    def im_error(self) -> float:
        return (self.model_im - self.paper_im) / abs(self.paper_im)


def short_period_rows(wing_name: str, mass_basis: str = DEFAULT_MASS_BASIS) -> list[EigenRow]:
    """Every published short-period row of ``wing_name`` beside the model's."""
    table, data = PUBLISHED_TABLES[wing_name]
    build = build_wing(VARIANTS[wing_name], mass_basis=mass_basis)
    speeds = sorted({v for v, _ in data})
    rows = []
    for model in ("rigid", "coupled", "qsd"):
        sets = eigen.modes_at(model, speeds, None if model == "rigid" else build.model,
                              airframe=PROTOTYPE_AIRFRAME if model == "rigid" else None)
        for s in sets:
            re_p, im_p = data[(s.speed_m_s, model)]
            sp = s.get("short_period")
            rows.append(EigenRow(table, wing_name, s.speed_m_s, model, re_p, im_p, sp.re, sp.im))
    return rows


@dataclass(frozen=True)
class TrendRow:
    """Change of the short period against rigid at one speed (the paper's Section 4 claims).

    d_frequency_rad_s: ω_n(coupled) − ω_n(rigid); d_damping: ζ(coupled) − ζ(rigid).
    expected: "forward" (frequency down, damping up) or "backward" (frequency up, damping
    down).
    """

    wing: str
    speed_m_s: float
    d_frequency_rad_s: float
    d_damping: float
    expected: str

    @property
    def as_paper(self) -> bool:
        if self.expected == "forward":
            return self.d_frequency_rad_s < 0.0 and self.d_damping > 0.0
        return self.d_frequency_rad_s > 0.0 and self.d_damping < 0.0


def trend_rows(speeds_m_s=(15.0, 20.0), mass_basis: str = DEFAULT_MASS_BASIS) -> list[TrendRow]:
    """Short-period change against rigid for every named variant."""
    rows = []
    rigid = {s.speed_m_s: s.get("short_period") for s in eigen.modes_at("rigid", speeds_m_s,
                                                                   airframe=PROTOTYPE_AIRFRAME)}
    for name, variant in VARIANTS.items():
        expected = "backward" if name.endswith("backward") else "forward"
        build = build_wing(variant, mass_basis=mass_basis)
        for s in eigen.modes_at("coupled", speeds_m_s, build.model):
            sp, r = s.get("short_period"), rigid[s.speed_m_s]
            rows.append(TrendRow(name, s.speed_m_s, sp.frequency_rad_s - r.frequency_rad_s,
                                 sp.damping - r.damping, expected))
    return rows


def flutter_rows(
    range_m_s=(5.0, 30.0), mass_basis: str = DEFAULT_MASS_BASIS
) -> list[eigen.FlutterResult]:
    """Flutter search of every named variant."""
    return [
        eigen.find_flutter(build_wing(v, mass_basis=mass_basis).model, range_m_s)
        for v in VARIANTS.values()
    ]
