"""A long simulated SITL session at --speedup 8, logged in split files, keeps a flat RSS
after warm-up (issue 16). The test flies 8 simulated minutes (1 min of wall time, in CI);
the issue's 30-minute figure is measured by the same script, ``python scripts/sitl_rss.py
--minutes 30 --speedup 8`` (~4 min), and reported in docs/sitl.md."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from mcap.reader import make_reader

pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[1]


MINUTES = 8.0


def test_long_session_has_flat_rss_and_finished_log_files(tmp_path):
    out = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "sitl_rss.py"), "--minutes", str(MINUTES),
         "--speedup", "8", "--log", str(tmp_path), "--log-max-mb", "40"],
        capture_output=True, text=True, timeout=3600, check=True).stdout
    r = json.loads(out)
    assert r["exit"] == 0 and r["summary"]["simulated_s"] == pytest.approx(MINUTES * 60.0)
    lo, hi = r["rss_after_warmup_mb"]
    assert hi - lo < 8.0, r["samples_min_mb"]  # the old loop grew ~2 MB per simulated minute
    files = r["summary"]["log_files"]
    assert len(files) >= 3
    end = 0.0
    for f in files:  # every file finished (summary and statistics), times contiguous
        with open(f, "rb") as fh:
            stats = make_reader(fh).get_summary().statistics
        assert stats.message_count > 0 and stats.message_start_time / 1e9 >= end - 1.0
        end = stats.message_end_time / 1e9
    assert end == pytest.approx(MINUTES * 60.0, abs=1.0)
