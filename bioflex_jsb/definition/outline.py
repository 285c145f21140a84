"""The drawn outline of an aircraft's rigid airframe (fuselage, horizontal tail, fin) [m]:
what the 3-D scene (:mod:`bioflex_jsb.sinks.mcap.scene`) draws around the elastic wing.

The prototype's outline is its parameters' (Table 1's fuselage, the tail its elevator
derivatives imply: :mod:`bioflex_jsb.parameters.airframe_consistent`). A definition describes
no fuselage or tail: another aircraft's outline is the prototype's scaled by the span ratio,
an ESTIMATE for the drawing only (nothing is computed with it; the wing is drawn from the
aircraft's own planform)."""

from __future__ import annotations

from dataclasses import astuple, dataclass

from bioflex_jsb.parameters.airframe import AIRFRAME_GEOMETRY, PROTOTYPE_AIRFRAME
from bioflex_jsb.parameters.airframe_consistent import FUSELAGE, TAIL


@dataclass(frozen=True)
class AirframeOutline:
    """What the scene draws of the rigid airframe [m]: the fuselage (a prolate spheroid of
    ``fuselage_length_m`` and ``fuselage_max_diameter_m`` on the body x axis, z = 0, its nose
    ``nose_ahead_of_root_le_m`` ahead of the wing's root leading edge), the wing plane at
    ``wing_height_m`` above the fuselage axis, the rectangular horizontal tail (semispan,
    chord, leading edge ``tail_le_x_m`` aft of the wing's root leading edge, on the axis) and
    a fin on the tail (root chord = the tail's, ``fin_height_m`` tall, ``fin_tip_chord_m``)."""

    fuselage_length_m: float
    fuselage_max_diameter_m: float
    nose_ahead_of_root_le_m: float
    wing_height_m: float
    tail_semispan_m: float
    tail_chord_m: float
    tail_le_x_m: float
    fin_height_m: float
    fin_tip_chord_m: float


def airframe_outline(airframe=None) -> AirframeOutline:
    """The outline of ``airframe`` (an ``AirframeData``, the one a wing was built for; None:
    the default aircraft's, the prototype's): the prototype's on its reference geometry,
    else the prototype's scaled by the span ratio (module docstring)."""
    outline = AirframeOutline(
        fuselage_length_m=FUSELAGE.length_m,  # Table 1
        fuselage_max_diameter_m=FUSELAGE.max_diameter_m,  # ESTIMATE there (Fig. 1)
        nose_ahead_of_root_le_m=AIRFRAME_GEOMETRY.wing_root_leading_edge_x_m,
        # airframe_consistent.TAIL: "tail on the fuselage axis, wing on top of the fusiform
        # fuselage: 3 cm between the planes"
        wing_height_m=TAIL.height_m,
        tail_semispan_m=TAIL.semispan_m, tail_chord_m=TAIL.chord_m,
        tail_le_x_m=TAIL.leading_edge_x_m,
        # ESTIMATE (drawing only, nothing is computed with it): "a small fin on a short
        # arm" (airframe.py, C_nβ): as tall as the tail is half-wide, half its chord at the tip
        fin_height_m=0.5 * TAIL.semispan_m, fin_tip_chord_m=0.5 * TAIL.chord_m,
    )
    if airframe is None or airframe.reference == PROTOTYPE_AIRFRAME.reference:
        return outline
    scale = airframe.reference.span_m / PROTOTYPE_AIRFRAME.reference.span_m
    return AirframeOutline(*(scale * v for v in astuple(outline)))
