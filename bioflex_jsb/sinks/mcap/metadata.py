"""The ``bioflex.run`` metadata record: the run description as JSON, with readable copies.

A log records :meth:`RunDescription.to_dict` under ``description`` (what ``rerun`` flies
again) and, for ``info`` and plots, the wing, speed, gust, models, time step and the
versions of the package, JSBSim and mcap as separate keys. Logs written before run
descriptions existed hold ``arguments`` (the command's argparse arguments) and ``argv``
(the argument list that repeats the run) instead; they stay readable
(:func:`description_from_metadata` returns None for them).
"""

from __future__ import annotations

import json
import platform
from collections.abc import Mapping
from typing import Any

from bioflex_jsb import __version__
from bioflex_jsb.simulation.gusts import GustSpecError, parse_gust
from bioflex_jsb.simulation.run import RunDescription, RunDescriptionError
from bioflex_jsb.sinks.mcap_io.errors import LogError

DESCRIPTION_KEY = "description"
TIME_BASE = "log and publish times are simulation time [ns from the run start]"


def _version(package: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(package)
    except PackageNotFoundError:
        return "unknown"


def run_metadata(description: RunDescription,
                 wing_variant: Mapping[str, Any] | None = None,
                 overrides: Mapping[str, float] | None = None) -> dict[str, str]:
    """The ``bioflex.run`` record of the run ``description`` (all values strings).

    ``wing_variant``: the built wing's variant as a dict (its parameters, so a log of a
    variant file still says what was flown when the file has changed); ``overrides``: the
    coefficient overrides of the build. Plain data, no command-line arguments.
    """
    d = description
    variant = dict(wing_variant) if wing_variant is not None else {}
    try:
        seed = str(parse_gust(d.gust).seed)
    except GustSpecError:  # a description's gust is text; an unparsed one has no seed
        seed = ""
    return {
        DESCRIPTION_KEY: json.dumps(d.to_dict(), default=str),
        "command": d.kind,
        "wing": str(variant.get("name", d.wing)),
        "wing_variant": json.dumps(variant, default=str),
        "overrides": json.dumps(dict(overrides or {}), default=str),
        "mass_basis": d.mass_basis,
        "speed_m_s": repr(float(d.speed_m_s)),
        "gust": d.gust,
        "gust_seed": seed,
        "models": ",".join(d.models),
        "duration_s": repr(float(d.duration_s)),
        "gust_start_s": repr(float(d.gust_start_s)),
        "dt_s": repr(float(d.dt_s)),
        "time_base": TIME_BASE,
        "bioflex_jsb_version": __version__,
        "jsbsim_version": _version("jsbsim"),
        "mcap_version": _version("mcap"),
        "python": platform.python_version(),
    }


def description_from_metadata(meta: Mapping[str, str]) -> RunDescription | None:
    """The run description a log's ``bioflex.run`` record holds; None for a log written
    before descriptions were recorded (it has ``arguments``/``argv`` instead). A record whose
    description is not valid is a :class:`LogError` (one line)."""
    text = meta.get(DESCRIPTION_KEY)
    if text is None:
        return None
    try:
        data = json.loads(text)
    except ValueError:
        raise LogError("the run metadata's description is not JSON") from None
    if not isinstance(data, dict):
        raise LogError("the run metadata's description is not a JSON object")
    try:
        return RunDescription.from_dict(data)
    except (RunDescriptionError, TypeError) as exc:  # TypeError: models not a list, …
        raise LogError(f"the run metadata's description is not valid: {exc}") from None
