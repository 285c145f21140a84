"""Render docs/img/scene.png from a log: fly the screenshot case (scene_view.SCREENSHOT_CASE)
with the 3-D scene, decode its SceneUpdate and draw the triangles with matplotlib.

    python scripts/scene_screenshot.py [OUT.png]   (default docs/img/scene.png)
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from bioflex_jsb.sinks.mcap.scene_view import render_screenshot, screenshot_log

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str]) -> int:
    out = Path(argv[0]) if argv else ROOT / "docs" / "img" / "scene.png"
    with tempfile.TemporaryDirectory() as tmp:
        log = screenshot_log(Path(tmp) / "scene.mcap")
        shot, _ = render_screenshot(log, out)
    print(f"{out}: t = {shot['time_s']:.3f} s, eta = {shot['eta_rad']}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
