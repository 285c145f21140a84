"""Test-session settings: the MCAP logs that runs write by default go to a temporary
directory, not into the working tree."""

from __future__ import annotations

import pytest

from bioflex_jsb.cli.common import LOG_DIR_ENV_VAR


@pytest.fixture(autouse=True, scope="session")
def _log_directory(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setenv(LOG_DIR_ENV_VAR, str(tmp_path_factory.mktemp("logs")))
    yield
    mp.undo()
