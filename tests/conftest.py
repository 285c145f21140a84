"""Test-session settings: the MCAP logs that runs write by default go to a temporary
directory, not into the working tree; under pytest-xdist (``-n``, on by default in
pyproject.toml's addopts) every worker's BLAS runs on one thread."""

from __future__ import annotations

import os

import pytest

from bioflex_jsb.cli.common import LOG_DIR_ENV_VAR

# One BLAS/OpenMP thread per xdist worker (and per child process a test starts): OpenBLAS
# starts one thread per core by default (2 here), so two workers would run 4 busy-waiting
# BLAS threads on 2 cores. Measured on this 2-core machine under the other engineers' load:
# tests/test_consistent_aircraft.py::test_script_json took 15.6 s serial and 240 s under
# -n 2 with the default threads. The variables are set in the controller before it starts
# the workers, so each worker's numpy reads them at its first import; a run without -n
# keeps the library defaults. The thread count only changes how BLAS splits the work, within
# the cross-processor spread the golden tolerances already allow (docs/validation.md).
THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def pytest_configure(config):
    workers = config.getoption("numprocesses", None)  # None: pytest-xdist not loaded
    if workers and not os.environ.get("PYTEST_XDIST_WORKER"):
        for name in THREAD_VARIABLES:
            os.environ.setdefault(name, "1")


@pytest.fixture(autouse=True, scope="session")
def _log_directory(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    mp.setenv(LOG_DIR_ENV_VAR, str(tmp_path_factory.mktemp("logs")))
    yield
    mp.undo()


@pytest.fixture(scope="module")
def optimised_wing():
    """The optimised wing's build (api.load_wing), for the API's input tests."""
    from bioflex_jsb import api

    return api.load_wing("optimised")


@pytest.fixture(scope="module")
def optimised_run(optimised_wing):
    """A 0.6 s coupled run of the optimised wing through the default gust from 0.1 s."""
    from bioflex_jsb import api

    return api.fly_gust(optimised_wing, models=("coupled",), duration_s=0.6,
                        gust_start_s=0.1)["coupled"]


# The physics tests run with numpy's floating-point errors raised: a division by zero, an
# overflow or an invalid operation (0/0, inf - inf, sqrt of a negative) in the numerical core
# fails the test where it happens instead of passing a NaN or an inf on to a comparison that
# may not look at it. Underflow (a decayed mode reaching denormals) is not an error.
PHYSICS_TEST_MODULES = frozenset({
    "test_aerodynamics", "test_goland", "test_structures", "test_free_aircraft", "test_lti",
    "test_lti_phugoid", "test_unsteady_aero", "test_paper_validation", "test_elastic_trim",
    "test_mode_labels", "test_beam_point_masses", "test_planform_stations",
    "test_state_space", "test_loads", "test_consistent_aircraft", "test_sensors_core",
    "test_values",
})


@pytest.fixture(autouse=True)
def _raise_floating_point_errors(request):
    if request.module.__name__.rsplit(".", 1)[-1] not in PHYSICS_TEST_MODULES:
        yield
        return
    import numpy as np

    with np.errstate(divide="raise", over="raise", invalid="raise", under="ignore"):
        yield
