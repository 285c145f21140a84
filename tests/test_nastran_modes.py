"""A Nastran modal deck as the wing's modal data (structures/nastran.py,
``bioflex-jsb import-modes``; docs/structures.md, "From a Nastran deck").

No Nastran runs here and pyyeti has no OP2 writer, so: the mapping (axes, signs, units,
port or starboard) is checked on a deck made in memory from this project's beam, whose
modes are known; the OP2 reading on a deck pyyeti ships for its own tests (a free-free
beam of CBAR elements: its modes are rigid-body ones, which the modal file refuses);
the whole command on the same file up to that refusal."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb.structures.beam import beam_modes, solve_beam, uniform_sections
from bioflex_jsb.structures.modal_file import read_modal_file
from bioflex_jsb.structures.nastran import FEModes, NastranError, fe_modal_data
from tests.cli_helpers import run_cli

SECTIONS = uniform_sections(4.0, bending_stiffness_n_m2=2.0e4, torsional_stiffness_n_m2=8.0e3,
                            mass_per_length_kg_m=2.0, torsional_inertia_kg_m=0.04, chord_m=0.6,
                            x_elastic_frac=0.35, x_inertial_frac=0.42)


def _deck(port: bool = False, mm: bool = False) -> FEModes:
    """The beam's raw (unit generalised mass) modes as a Nastran deck would give them at
    its 41 nodes: x aft, y to starboard (to port: y negative), z up; T3 = -w (w down),
    R2 = twist about +y for the starboard wing (a mirror image keeps R2: an axial vector's
    component along the mirror's normal)."""
    sol = solve_beam(SECTIONS, 3, 40)
    y = sol.nodes_m
    bend, twist = sol.sample(y)
    scale = 1000.0 if mm else 1.0
    sign = -1.0 if port else 1.0
    n, g = bend.shape
    trans = np.zeros((n, g, 3))
    rots = np.zeros((n, g, 3))
    trans[:, :, 2] = -bend * scale
    rots[:, :, 1] = twist
    positions = np.column_stack([0.3 * np.ones(g), sign * y, np.zeros(g)]) * scale
    return FEModes(grid_ids=np.arange(101, 101 + g), positions=positions, translations=trans,
                   rotations=rots, frequencies_rad_s=sol.frequencies_rad_s,
                   generalised_masses=np.ones(n) * scale**2, source="beam deck")


@pytest.mark.parametrize("port, mm", [(False, False), (True, False), (False, True)])
def test_a_deck_of_the_beam_maps_onto_the_beams_own_modal_data(port, mm):
    # the mapping against beam_modes: the same stations, shapes, frequencies and
    # normalised generalised masses (to round-off: measured 4e-16), for a starboard deck in
    # metres, a port one (span -y: the twist's sign follows the handedness) and one in mm
    want = beam_modes(SECTIONS, 3)
    got = fe_modal_data(_deck(port, mm), span="-y" if port else "+y",
                        length_unit="mm" if mm else "m", x_elastic_frac=0.35,
                        x_inertial_frac=0.42)
    np.testing.assert_allclose(got.stations_m, want.stations_m, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.frequencies_rad_s, want.frequencies_rad_s, rtol=1e-15)
    np.testing.assert_allclose(got.generalised_masses_kg_m2, want.generalised_masses_kg_m2,
                               rtol=1e-12)
    np.testing.assert_allclose(got.twist_rad, want.twist_rad, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.bending_m, want.bending_m, rtol=0,
                               atol=1e-12 * np.max(np.abs(want.bending_m)))
    assert np.all(got.x_elastic_frac == 0.35) and np.all(got.x_inertial_frac == 0.42)


def test_mapping_refusals_are_one_line():
    deck = _deck()
    for kwargs, word in (({"span": "+y", "up": "+y"}, "different axes"),
                         ({"span": "+q"}, "accepted +x"),
                         ({"length_unit": "furlong"}, "accepted length"),
                         ({"span": "-y"}, "not outboard"),  # the grids run the other way
                         ({"mass_unit": "slinch", "length_unit": "in"}, None)):
        if word is None:  # a unit change alone is accepted and scales the masses
            m = fe_modal_data(deck, **kwargs).generalised_masses_kg_m2
            ref = fe_modal_data(deck).generalised_masses_kg_m2
            # lbf s²/in = 175.126835 kg, times the length unit squared
            np.testing.assert_allclose(m / ref, 175.126835 * 0.0254**2, rtol=1e-8)
            continue
        with pytest.raises(NastranError) as err:
            fe_modal_data(deck, **kwargs)
        assert word in str(err.value) and "\n" not in str(err.value)


def _pyyeti_deck() -> Path:
    pyyeti = pytest.importorskip("pyyeti", reason="the nastran extra: pip install pyyeti")
    path = Path(pyyeti.__file__).parent / "tests" / "nas2cam_extseout" / "cant_beam.op2"
    if not path.is_file():
        pytest.fail(f"pyyeti {pyyeti.__version__} no longer ships {path.name}")
    return path


def test_reading_pyyetis_cbar_deck_gives_consistent_grid_motions():
    # cant_beam.op2 (pyyeti's OP2 reader test; NX Nastran SOL 103, mm-kg-s): 8221 grids on
    # the x axis 10 mm apart, CBAR elements, no constraint: its 4 modes are rigid-body ones
    # (0.0011..0.0026 rad/s in LAMA). Euler-Bernoulli bars: each grid's rotation about y is
    # minus the slope of its z motion along x, and about z the slope of its y motion: the
    # columns (T1..T3, R1..R3) are read in the order Nastran writes them. Central
    # differences over 1 m (the deck is single precision: over its 10 mm spacing the
    # differences lose 4 of their 7 digits): measured 1.0e-5; bar 1e-4.
    from bioflex_jsb.structures.nastran import read_op2_modes

    fe = read_op2_modes(_pyyeti_deck(), range(1, 8222))
    assert fe.positions.shape == (8221, 3)
    np.testing.assert_allclose(fe.positions[:, 0], 10.0 * np.arange(8221), atol=1e-9)
    assert fe.translations.shape == fe.rotations.shape == (4, 8221, 3)
    np.testing.assert_allclose(fe.frequencies_rad_s,
                               [2.64567765e-03, 1.46990421e-03, 1.46912062e-03, 1.05077680e-03],
                               rtol=1e-8)
    np.testing.assert_allclose(fe.generalised_masses, 1.0)
    every = slice(0, None, 100)
    x = fe.positions[every, 0]
    worst = 0.0
    for i in range(4):
        for t, r, sign in ((2, 1, -1.0), (1, 2, 1.0)):
            slope = np.gradient(fe.translations[i, every, t], x)
            rot = sign * fe.rotations[i, every, r]
            worst = max(worst, np.max(np.abs(slope[1:-1] - rot[1:-1])) / np.max(np.abs(rot)))
    print(f"slope against rotation: {worst:.2e}")
    assert worst < 1e-4


def test_import_modes_command_refuses_a_free_free_deck_in_one_line(tmp_path, capsys):
    deck = _pyyeti_deck()
    out = tmp_path / "modes.toml"
    code, _, err = run_cli(capsys, *["import-modes", "--op2", str(deck), "--grids", "1-8221",
                            "--span", "+x", "--aft=-y",
                            "--length-unit", "mm", "--out", str(out)])
    assert code == 2 and not out.exists()
    assert "increasing frequency" in err or "rad/s" in err
    assert err.strip().count("\n") == 0
    # a grid that is not in the deck
    code, _, err = run_cli(capsys, *["import-modes", "--op2", str(deck), "--grids", "1,99999",
                            "--out", str(out)])
    assert code == 2 and "grid 99999" in err


def test_import_modes_writes_a_deck_as_a_modal_file(tmp_path, monkeypatch, capsys):
    # the command end to end on the in-memory deck of the beam (read_op2_modes replaced:
    # no OP2 of an elastic wing ships anywhere at hand): the file reads back as the beam's
    # modes, and an existing file is kept without --force
    from bioflex_jsb.structures import nastran

    monkeypatch.setattr(nastran, "read_op2_modes", lambda path, grids: _deck(mm=True))
    out = tmp_path / "wing_modes.toml"
    code, text, err = run_cli(capsys, *["import-modes", "--op2", "deck.op2", "--grids", "101-141",
                               "--length-unit", "mm", "--elastic-axis", "0.35",
                               "--centre-of-mass", "0.42", "--out", str(out), "--json"])
    assert code == 0, err
    summary = json.loads(text)
    assert summary["n_modes"] == 3 and summary["semispan_m"] == pytest.approx(4.0)
    modes = read_modal_file(out)
    want = beam_modes(SECTIONS, 3)
    np.testing.assert_allclose(modes.frequencies_rad_s, want.frequencies_rad_s, rtol=1e-12)
    np.testing.assert_allclose(modes.twist_rad, want.twist_rad, atol=1e-12)
    before = out.read_bytes()
    code, _, err = run_cli(capsys, *["import-modes", "--op2", "deck.op2", "--grids", "101-141",
                            "--out", str(out)])
    assert code == 2 and "already exists" in err and out.read_bytes() == before
