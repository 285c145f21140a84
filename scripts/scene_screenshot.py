"""Render docs/img/scene.png from a log: fly the screenshot case (scene_view.SCREENSHOT_CASE)
with the 3-D scene, decode its SceneUpdate and draw the triangles with matplotlib.

    python scripts/scene_screenshot.py [OUT.png]   (default docs/img/scene.png)
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from bioflex_jsb.sinks.mcap.scene_view import SCREENSHOT_CASE, render_screenshot

ROOT = Path(__file__).resolve().parents[1]


def screenshot_log(path: str | Path, exaggeration: float = 1.0) -> Path:
    """Fly SCREENSHOT_CASE and log it with the scene to ``path``."""
    from bioflex_jsb.drivers.gust import RunConfig, run_gust
    from bioflex_jsb.flight_dynamics.wing_model import build_wing, resolve_variant
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.run import RunDescription
    from bioflex_jsb.sinks.mcap.log import RunLog

    c = SCREENSHOT_CASE
    build = build_wing(resolve_variant(c["wing"]))
    desc = RunDescription("gust", c["wing"], c["speed_m_s"], gust=c["gust"],
                          models=(c["model"],), duration_s=c["duration_s"],
                          gust_start_s=c["gust_start_s"])
    log = RunLog.open(path, desc, wing_variant=build.variant.as_dict(), scene=exaggeration)
    try:
        run_gust(Airframe(), build.model, c["model"],
                 RunConfig(c["speed_m_s"], parse_gust(c["gust"]), c["duration_s"],
                          c["gust_start_s"]), recorder=log.recorder(c["model"]))
    finally:
        log.close()
    return Path(path)


def main(argv: list[str]) -> int:
    out = Path(argv[0]) if argv else ROOT / "docs" / "img" / "scene.png"
    with tempfile.TemporaryDirectory() as tmp:
        log = screenshot_log(Path(tmp) / "scene.mcap")
        shot, _ = render_screenshot(log, out)
    print(f"{out}: t = {shot['time_s']:.3f} s, eta = {shot['eta_rad']}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
