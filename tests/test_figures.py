"""Figures a user can read: every line told apart, η₁ defined, one legend, titles that say
what was flown. Drawn from synthetic runs (no flight), checked through matplotlib's figure."""

from __future__ import annotations

import numpy as np
import pytest

from bioflex_jsb.simulation.results import TimeHistory
from bioflex_jsb.sinks import plotting


def _run(model: str, label: str | None = None, gust_at: float | None = 0.5) -> TimeHistory:
    t = np.linspace(0.0, 2.0, 401)
    w_g = np.where(t >= gust_at, 3.0, 0.0) if gust_at is not None else np.zeros_like(t)
    ch = {name: np.sin(t + i) * 0.01 for i, name in
          enumerate(("u", "alpha", "q", "theta", "eta1"))}
    ch["n_z"] = 1.0 + ch["alpha"]
    ch["w_g"] = w_g
    meta = {"label": label} if label else {}
    return TimeHistory(model, t, ch, {k: "-" for k in ch}, meta)


@pytest.fixture()
def captured(monkeypatch):
    """The figure handed to the writer, instead of a file."""
    figures = []
    monkeypatch.setattr(plotting, "_save", lambda fig, path: figures.append(fig) or path)
    return figures


def test_two_wings_flown_with_the_same_model_get_different_colours(captured):
    plotting.time_histories([_run("qsd", "original"), _run("qsd", "optimised")], "x.png", "t")
    ax = captured[0].axes[0]
    colours = [line.get_color() for line in ax.get_lines() if line.get_label() in
               ("original", "optimised")]
    assert len(colours) == 2 and colours[0] != colours[1], colours


def test_one_figure_legend_and_eta1_is_defined(captured):
    plotting.time_histories([_run("rigid"), _run("coupled"), _run("qsd")], "x.png", "t")
    fig = captured[0]
    assert len(fig.legends) == 1
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["rigid", "coupled", "qsd"]
    panel_legends = [ax for ax in fig.axes if ax.get_legend() is not None]
    assert [ax.get_ylabel() for ax in panel_legends] == ["gust w_g [m/s] (up)"]
    notes = " ".join(t.get_text() for t in fig.texts)
    assert "η₁" in notes and "largest section twist" in notes


def test_a_sitl_session_title_says_the_gust_it_flew():
    from bioflex_jsb.cli.plot import _title

    meta = {"command": "sitl", "wing": "optimised", "gust": "none", "speed_m_s": "15.0"}
    title = _title(meta, [_run("coupled", gust_at=1.25)], "f.mcap")
    assert "gust none" not in title and "t = 1.2 s" in title and "3.00 m/s" in title, title
    assert _title(meta, [_run("coupled", gust_at=None)], "f.mcap").endswith("still air")
    gust_meta = {"command": "gust", "wing": "optimised", "gust": "sharp:3", "speed_m_s": "15"}
    assert _title(gust_meta, [], "f.mcap") == "optimised wing, 15 m/s, gust sharp:3"
