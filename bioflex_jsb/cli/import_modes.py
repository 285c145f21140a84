"""``bioflex-jsb import-modes``: a Nastran modal deck (OP2) written as a modal-data file."""

from __future__ import annotations

import argparse

from bioflex_jsb.cli.common import UsageError, check_new_file, print_json

HELP = """Read the modes of a Nastran SOL 103 run (an OP2 file written with PARAM,POST,-1
and DISP(PLOT) = ALL) at the grids of the wing's reference line, root first, and write them
as a modal-data file (docs/structures.md, "From a Nastran deck") that an aircraft
definition flies with [structure] kind = "modal", modes_file = FILE. Needs pyyeti
(pip install "bioflex-jsb[nastran]"). The deck: one half wing clamped at its root grid
(the first of --grids), grids with the basic frame as output frame (CD = 0). Bending is the
grids' displacement along -UP [m, positive down], twist their rotation about SPAN [rad,
positive leading edge up], stations their distance from the first grid along SPAN [m];
generalised masses from the deck's LAMA table in SI (x mass unit x length unit^2). Units
of the deck: --length-unit m|mm|cm|in|ft, --mass-unit kg|t|g|slinch|slug. Axes: --span,
--up, --aft each one of +x, -x, +y, -y, +z, -z of the deck's basic frame (defaults +y, +z,
+x: x aft, y to starboard, z up; a negative axis is written --aft=-y). --elastic-axis
and --centre-of-mass: chord fractions 0..1 aft of the leading edge (the chord fraction of
the grids' line, and of the sections' centre of mass). Frequencies must be 0.01..1e5
rad/s (a free-free deck's rigid-body modes are refused). An existing --out is refused
unless --force."""


def _grids(text: str) -> list[int]:
    """``101,102,110-120`` (ranges inclusive) as a list of grid ids."""
    out: list[int] = []
    try:
        for part in text.split(","):
            part = part.strip()
            if "-" in part:
                lo, hi = (int(v) for v in part.split("-", 1))
                if hi < lo:
                    raise ValueError
                out.extend(range(lo, hi + 1))
            else:
                out.append(int(part))
    except ValueError:
        raise argparse.ArgumentTypeError(f"--grids {text!r}: give grid ids root first, e.g. "
                                         "101,102,103 or 101-141") from None
    return out


def _fraction(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not 0.0 <= v <= 1.0:
        raise argparse.ArgumentTypeError(f"{text!r}: a chord fraction 0..1 is accepted")
    return v


def register(sub) -> None:
    from bioflex_jsb.structures.nastran import AXES, LENGTH_UNITS_M, MASS_UNITS_KG

    p = sub.add_parser("import-modes", help="a Nastran OP2 modal deck as a modal-data file",
                       description=HELP)
    p.add_argument("--op2", required=True, metavar="FILE.op2", help="the Nastran OP2 file")
    p.add_argument("--grids", required=True, type=_grids, metavar="IDS",
                   help="the reference line's grid ids, root first (101,102 or 101-141)")
    p.add_argument("--out", required=True, metavar="FILE.toml", help="the modal-data file")
    p.add_argument("--span", choices=AXES, default="+y", help="root-to-tip axis (default +y)")
    p.add_argument("--up", choices=AXES, default="+z", help="upward axis (default +z)")
    p.add_argument("--aft", choices=AXES, default="+x", help="aft axis (default +x)")
    p.add_argument("--length-unit", choices=tuple(LENGTH_UNITS_M), default="m",
                   help="the deck's length unit (default m)")
    p.add_argument("--mass-unit", choices=tuple(MASS_UNITS_KG), default="kg",
                   help="the deck's mass unit (default kg)")
    p.add_argument("--elastic-axis", type=_fraction, default=0.5, metavar="FRAC",
                   help="chord fraction of the grids' line, 0..1 (default 0.5)")
    p.add_argument("--centre-of-mass", type=_fraction, default=0.5, metavar="FRAC",
                   help="chord fraction of the sections' centre of mass, 0..1 (default 0.5)")
    p.add_argument("--force", action="store_true", help="replace an existing --out")
    p.add_argument("--json", action="store_true", help="print what was written as JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from bioflex_jsb.structures.modal_file import format_modal_text, parse_modal_text
    from bioflex_jsb.structures.nastran import op2_modal_data

    check_new_file(args.out, args.force, "--out", (".toml",))
    if args.op2 == args.out:
        raise UsageError("--out names the OP2 file itself; give another name")
    modes = op2_modal_data(args.op2, args.grids, span=args.span, up=args.up, aft=args.aft,
                           length_unit=args.length_unit, mass_unit=args.mass_unit,
                           x_elastic_frac=args.elastic_axis,
                           x_inertial_frac=args.centre_of_mass)
    header = (f"Modes of the Nastran deck {args.op2} at grids {args.grids[0]}.."
              f"{args.grids[-1]} (bioflex-jsb import-modes)")
    text = format_modal_text(modes, header=header)
    # the file must read back: the reader's ranges (frequencies 0.01..1e5 rad/s, a free-free
    # deck's rigid-body modes are below; generalised masses) are checked before writing
    parse_modal_text(text, name=f"the modes of {args.op2}")
    Path(args.out).write_text(text, encoding="utf-8")
    summary = {"out": args.out, "op2": args.op2, "n_modes": modes.n_modes,
               "frequencies_hz": modes.frequencies_hz.tolist(),
               "generalised_masses_kg_m2": modes.generalised_masses_kg_m2.tolist(),
               "semispan_m": float(modes.stations_m[-1]), "n_stations": modes.n_stations}
    if args.json:
        print_json(summary)
    else:
        f = ", ".join(f"{v:.4g}" for v in modes.frequencies_hz)
        print(f"wrote {args.out}: {modes.n_modes} modes ({f} Hz) at {modes.n_stations} "
              f"stations over {summary['semispan_m']:.4g} m")
    return 0
