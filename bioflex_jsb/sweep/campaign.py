"""Campaign files and their cases (pure: parsing, validation, expansion, case ids, columns).

A campaign is a TOML file (``docs/sweeps.md``)::

    name = "example"
    metrics = ["gust", "flutter", "eigenvalues", "coefficients"]

    [run]                       # settings shared by every case
    duration_s = 5.0
    gust_start_s = 0.5

    [axes]                      # lists, or ranges {start, stop, step} / {start, stop, num}
    wings = ["original", "optimised"]
    aircraft = ["bioflex_original"]   # definitions: shipped or files (sweep/aircraft_axis.py)
    speeds_m_s = [15.0, 18.0]
    gusts = ["sharp:3", "dryden:1:100"]
    seeds = [1, 2]              # turbulence seeds (dryden / vonkarman gusts only)
    models = ["coupled", "qsd"]
    controllers = ["none", "gla_optimised", "my_gla.toml"]  # in the loop of the gust runs

The cases are the Cartesian product of the axes. Every case has a stable id: a hash of
everything that determines its result (the wing's full definition, speed, gust, model, run
settings and metrics), so a rerun with ``--resume`` recognises finished cases whatever their
order or the campaign file they came from. Errors are :class:`CampaignError`, one line that
names the key.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bioflex_jsb.errors import unprintable
from bioflex_jsb.flight_dynamics.lti import MODELS
from bioflex_jsb.flight_dynamics.wing_model import (
    DEFAULT_MASS_BASIS,
    MASS_BASES,
    VARIANTS,
    VariantError,
    WingVariant,
    load_variant_file,
)
from bioflex_jsb.inputs import (
    CHORD_FRACTION,
    Choice,
    Count,
    Interval,
    Invalid,
    Kind,
    Real,
    Table,
    Text,
    check_keys,
    problem,
    read_table,
)
from bioflex_jsb.simulation.gusts import GustSpecError, parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S, MAX_DT_S, MIN_DT_S
from bioflex_jsb.sweep.columns import DEFAULT_AERO, result_columns
from bioflex_jsb.sweep.columns import RUN_INFO_COLUMNS as RUN_INFO_COLUMNS  # re-exported
from bioflex_jsb.sweep.errors import CampaignError as CampaignError  # re-exported
from bioflex_jsb.tomlfile import read_toml

CASE_ID_VERSION = 1  # bump when the meaning of a case's inputs changes
MAX_CASES = 1_000_000

METRICS = ("gust", "flutter", "eigenvalues", "coefficients")
TOP_KEYS = {"name", "description", "metrics", "run", "axes"}
AERO_MODELS = ("quasi-steady", "unsteady")  # the coupled step's strips (run.aero)
# the metrics the unsteady strips are offered for: the gust run (the coupled step) and the
# wing's coefficients (no aerodynamics); flutter and eigenvalues are the quasi-steady LTI
# model's, so with run.aero = "unsteady" they are refused rather than given quasi-steady
UNSTEADY_METRICS = ("gust", "coefficients")
AXIS_KEYS = {"wings", "aircraft", "x_inertial_frac", "x_elastic_frac", "speeds_m_s", "gusts",
             "seeds", "models", "controllers"}
NO_CONTROLLER = "none"  # axes.controllers' entry for the gust run without a controller
RANGE_KEYS = {"start", "stop", "step", "num"}
TURBULENCE = ("dryden", "vonkarman")


class RecordingError(Exception):
    """A case that could not be run or recorded because of the machine, not the case: no
    space left for its log, a log directory that cannot be written, a lost cluster. It is
    not a result: the sweep stops (exit status 4) and the case stays missing, so that
    ``--resume`` runs it once the cause is fixed. Raised in workers, so it pickles: the
    only argument is the one-line message."""

    def __init__(self, message: str) -> None:
        super().__init__(" ".join(str(message).split()))

    def __str__(self) -> str:
        return str(self.args[0])



# ---------------------------------------------------------------------------------------
# Cases
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class RunSettings:
    """Settings shared by every case: gust-run duration and gust start [s], co-simulation
    step [s], mass basis, flutter search range [m/s] (None: each wing's default,
    ``definition.clamped.free_speed_range_m_s``: the paper's 5-40 m/s for the prototype's
    airframe, derived from the wing for another aircraft), the coupled step's strips
    (``aero``: quasi-steady or unsteady)."""

    duration_s: float = 5.0
    gust_start_s: float = 0.5
    dt_s: float = DEFAULT_DT_S
    mass_basis: str = DEFAULT_MASS_BASIS
    flutter_range_m_s: tuple[float, float] | None = None
    aero: str = DEFAULT_AERO


# the range a case id records for "none given": the prototype's (its stored ids stay valid;
# another airframe's ids record "derived": aircraft_axis.aircraft_identity)
DEFAULT_FLUTTER_RANGE_ID = (5.0, 40.0)


def settings_identity(settings: RunSettings) -> dict[str, Any]:
    """The settings as hashed into case ids: ``aero`` only when it is not the default, so
    a quasi-steady case has the id it has in a store written without ``aero``."""
    d = dataclasses.asdict(settings)
    if d["aero"] == DEFAULT_AERO:
        del d["aero"]
    if d["flutter_range_m_s"] is None:
        d["flutter_range_m_s"] = DEFAULT_FLUTTER_RANGE_ID
    return d


@dataclass(frozen=True)
class Case:
    """One point of a campaign: a wing at a speed through a gust, as one model. A case of
    the ``aircraft`` axis has its :class:`~bioflex_jsb.definition.aircraft.Aircraft` in
    ``aircraft`` (``wing`` its wing's variant); ``aircraft_column``: the campaign's table has
    the ``aircraft`` column, ``turbulence_columns`` the RMS columns (a turbulence gust)."""

    index: int
    wing: WingVariant
    speed_m_s: float
    gust: str  # command-line form, seed included for turbulence
    model: str
    settings: RunSettings
    metrics: tuple[str, ...]
    case_id: str = ""
    aircraft: Any = None
    aircraft_column: bool = False
    turbulence_columns: bool = False
    controller: str | None = None  # a controller file's absolute path or a shipped name
    controller_column: bool = False  # the campaign has axes.controllers

    def columns(self) -> dict[str, str]:
        """The columns of this case's results table."""
        return result_columns(self.metrics, self.settings.aero, self.aircraft_column,
                              self.turbulence_columns, self.controller_column)

    def inputs(self) -> dict[str, Any]:
        """The input columns of this case's row."""
        g = parse_gust(self.gust)
        return {
            "case_id": self.case_id,
            "case_index": self.index,
            "wing": self.wing.name,
            "x_inertial_frac": self.wing.x_inertial_frac,
            "x_elastic_frac": self.wing.x_elastic_frac,
            "pinned_c_eta1_q1": self.wing.pinned_c_eta1_q1,
            "speed_m_s": self.speed_m_s,
            "gust": self.gust,
            "gust_kind": g.kind,
            "gust_amplitude_m_s": g.amplitude_m_s,
            "gust_length_m": g.length_m,
            "seed": g.seed if g.kind in TURBULENCE else None,
            "model": self.model,
            **({"controller": self.controller or NO_CONTROLLER}
               if self.controller_column else {}),
            "duration_s": self.settings.duration_s,
            "gust_start_s": self.settings.gust_start_s,
            "dt_s": self.settings.dt_s,
            "mass_basis": self.settings.mass_basis,
            **({} if self.settings.aero == DEFAULT_AERO else {"aero": self.settings.aero}),
            **({"aircraft": self.aircraft.name if self.aircraft is not None else None}
               if self.aircraft_column else {}),
        }


def _wing_identity(wing: WingVariant, aircraft=None) -> dict[str, Any]:
    """The wing's definition for hashing; a modes file enters by its content, not its path
    (read once per process and file: a regular file within the modal-file size limit); an
    aircraft's wing also by its definition file's content (``sweep/aircraft_axis.py``)."""
    d = wing.as_dict()
    if aircraft is not None:
        from bioflex_jsb.sweep.aircraft_axis import aircraft_identity

        d["aircraft"] = aircraft_identity(aircraft)
    d.pop("description", None)
    if wing.modes_file:
        digest = _modes_digest(wing.modes_file)
        if digest is not None:
            d["modes_file"] = digest
        # else: the build will fail and record the case as failed
    return d


_MODES_DIGESTS: dict[str, str | None] = {}


def _modes_digest(path: str) -> str | None:
    if path not in _MODES_DIGESTS:
        from bioflex_jsb.files import read_input_bytes
        from bioflex_jsb.structures.modal_file import MAX_MODAL_BYTES, ModalFileError

        try:
            data = read_input_bytes(path, "modal-data file", MAX_MODAL_BYTES, ModalFileError)
            _MODES_DIGESTS[path] = hashlib.sha256(data).hexdigest()
        except ModalFileError:
            _MODES_DIGESTS[path] = None
    return _MODES_DIGESTS[path]


def controller_identity(source: str | None) -> dict[str, str] | None:
    """A controller as hashed into case ids: its file's name and the SHA-256 of its content
    (a shipped controller's file alike; read bounded), None without one (a case without a
    controller keeps the id it has in a store written before controllers)."""
    if source is None:
        return None
    from bioflex_jsb.files import read_input_bytes
    from bioflex_jsb.simulation.controller import MAX_CONTROLLER_BYTES, controller_path

    path = controller_path(source)
    data = read_input_bytes(path, "controller file", MAX_CONTROLLER_BYTES, CampaignError)
    return {"file": path.name, "sha256": hashlib.sha256(data).hexdigest()}


def _id_text(wing_json: str, speed_m_s: float, gust: str, model: str, settings_json: str,
             metrics_json: str, controller_json: str | None = None) -> str:
    """The hashed text: exactly ``json.dumps(payload, sort_keys=True, default=str)`` of
    :func:`case_id`'s payload, assembled from its parts (the wing's and the settings' parts
    are serialised once per campaign, not once per case; the controller's key, first in
    sorted order, only with one)."""
    head = "{" if controller_json is None else f'{{"controller": {controller_json}, '
    return (f'{head}"gust": {json.dumps(gust)}, "metrics": {metrics_json}, '
            f'"model": {json.dumps(model)}, "settings": {settings_json}, '
            f'"speed_m_s": {json.dumps(speed_m_s)}, "v": {CASE_ID_VERSION}, '
            f'"wing": {wing_json}}}')


def case_id(case: Case) -> str:
    """Stable id of ``case``: 16 hex digits of the SHA-256 of its inputs."""
    payload = {
        "v": CASE_ID_VERSION,
        "wing": _wing_identity(case.wing, case.aircraft),
        "speed_m_s": case.speed_m_s,
        "gust": case.gust,
        "model": case.model,
        "settings": settings_identity(case.settings),
        "metrics": sorted(case.metrics),
    }
    if case.controller is not None:
        payload["controller"] = controller_identity(case.controller)
    text = json.dumps(payload, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def failed_row(case: Case, error: str) -> dict[str, Any]:
    """The row of a case that produced no result (every metric None)."""
    row: dict[str, Any] = {name: None for name in case.columns()}
    row.update(case.inputs())
    row["status"] = "failed"
    row["error"] = " ".join(str(error).split())  # one line
    return row


@dataclass(frozen=True)
class Campaign:
    name: str
    description: str
    metrics: tuple[str, ...]
    settings: RunSettings
    wings: tuple[WingVariant, ...]
    speeds_m_s: tuple[float, ...]
    gusts: tuple[str, ...]
    models: tuple[str, ...]
    source: str = ""
    aircraft: tuple = ()  # Aircraft of the aircraft axis (sweep/aircraft_axis.py)
    controllers: tuple = (None,)  # axes.controllers (None: no controller)
    controller_column: bool = False  # the campaign has axes.controllers

    def cases(self) -> list[Case]:
        """The Cartesian product wings × speeds × gusts × models, with ids (a list; a sweep
        uses :meth:`iter_cases`)."""
        return list(self.iter_cases())

    def iter_cases(self):
        """The cases one at a time, in campaign order: a million-case campaign starts its
        first case at once and never holds every case in memory (≈ 2 µs a case)."""
        dumps = json.dumps
        settings_json = dumps(settings_identity(self.settings), sort_keys=True, default=str)
        metrics_json = dumps(sorted(self.metrics))
        index = 0
        column, turbulence = bool(self.aircraft), self.has_turbulence
        wings = [(w, None) for w in self.wings] + [(a.variant(), a) for a in self.aircraft]
        controllers = [(c, None if c is None else dumps(controller_identity(c), sort_keys=True))
                       for c in self.controllers]
        for wing, aircraft in wings:
            wing_json = dumps(_wing_identity(wing, aircraft), sort_keys=True, default=str)
            for speed in self.speeds_m_s:
                for gust in self.gusts:
                    for model in self.models:
                        for controller, controller_json in controllers:
                            text = _id_text(wing_json, speed, gust, model, settings_json,
                                            metrics_json, controller_json)
                            cid = hashlib.sha256(text.encode()).hexdigest()[:16]
                            yield Case(index, wing, speed, gust, model, self.settings,
                                       self.metrics, cid, aircraft, column, turbulence,
                                       controller, self.controller_column)
                            index += 1

    @property
    def n_cases(self) -> int:
        return (len(self.wings) + len(self.aircraft)) * len(self.speeds_m_s) * \
            len(self.gusts) * len(self.models) * len(self.controllers)

    @property
    def has_turbulence(self) -> bool:
        """Whether a gust of the campaign is turbulence (its table has the RMS columns)."""
        return any(parse_gust(g).kind in TURBULENCE for g in self.gusts)

    def columns(self) -> dict[str, str]:
        return result_columns(self.metrics, self.settings.aero, bool(self.aircraft),
                              self.has_turbulence, self.controller_column)


# ---------------------------------------------------------------------------------------
# Parsing
# ---------------------------------------------------------------------------------------
def load_campaign(path: str | Path) -> Campaign:
    """Read and check a campaign file; :class:`CampaignError` (one line) if it is bad."""
    p = Path(path)
    data = read_toml(p, "campaign file", CampaignError)
    return parse_campaign(data, source=p.name, base_dir=p.parent, default_name=p.stem)


def _unknown(table: dict, allowed: set[str], where: str) -> None:
    """An unknown key of table ``where`` ("" the top level): ``<where>: unknown key 'X';
    accepted: …`` (:func:`bioflex_jsb.inputs.unknown_key_text`)."""
    try:
        check_keys(table, sorted(allowed))
    except Invalid as exc:
        raise problem(CampaignError, "", where, exc.text) from None


def _check(kind: Kind, v: Any, key: str) -> Any:
    """``v`` checked by ``kind`` (:mod:`bioflex_jsb.inputs`); the problem names ``key``."""
    try:
        return kind.check(v)
    except Invalid as exc:
        raise problem(CampaignError, "", key, exc.text) from None


MIN_SPEED_M_S = 1.0  # DECISION: a case's lowest airspeed [m/s] (1e-300 would be a failed row)
MAX_SPEED_M_S = 100.0  # a case's highest airspeed [m/s]: the prototype's 10-30 m/s with room
AXIS_VALUE = Real("the axis unit")  # a range's start and stop
AXIS_STEP = Real("the axis unit", positive=True)
SPEED = Real("m/s", MIN_SPEED_M_S, MAX_SPEED_M_S)
SEED = Count(0)


class RunTable(Table):
    """A campaign's [run] table (:class:`RunSettings`' fields, each with its range)."""

    duration_s: Real("s", hi=600.0, positive=True).type() = RunSettings.duration_s
    gust_start_s: Real("s", lo=0.0).type() = RunSettings.gust_start_s
    dt_s: Real("s", MIN_DT_S, MAX_DT_S).type() = RunSettings.dt_s
    mass_basis: Choice(MASS_BASES, noun="mass basis").type() = RunSettings.mass_basis
    flutter_range_m_s: Interval("m/s").type() | None = None
    aero: Choice(AERO_MODELS, noun="aerodynamics").type() = RunSettings.aero


# The decimals an axis value keeps: a range's start + k * step carries the float error of
# the product (15.1 + 3 * 0.3 = 16.000000000000004); a value given in a list is rounded
# alike, so 15.0 and 15.0000000000001 are one speed (refused as given twice), not two cases
# of two ids that fly the same.
GRID_DECIMALS = 12


def grid_values(values: list[float]) -> list[float]:
    """``values`` rounded to :data:`GRID_DECIMALS` decimals, as every numeric axis is."""
    return [round(x, GRID_DECIMALS) for x in values]


def _values(v: Any, key: str, integer: bool = False) -> list:
    """An axis: a non-empty list, or a range table {start, stop, step | num} (stop included)."""
    if isinstance(v, dict):
        _unknown(v, RANGE_KEYS, key)
        for k in ("start", "stop"):
            if k not in v:
                raise CampaignError(f"{key}.{k}: missing; a range is {{start, stop, step}} or "
                                    "{start, stop, num}")
        start = _check(AXIS_VALUE, v["start"], f"{key}.start")
        stop = _check(AXIS_VALUE, v["stop"], f"{key}.stop")
        if stop < start:
            raise CampaignError(f"{key}: empty axis (stop {stop:g} < start {start:g})")
        if "step" in v and "num" in v:
            raise CampaignError(f"{key}: give step or num, not both")
        if "num" in v:
            num = _check(Count(1), v["num"], f"{key}.num")
            n, step = num, (stop - start) / max(num - 1, 1)
        else:
            step = v.get("step", 1 if integer else None)
            if step is None:
                raise CampaignError(f"{key}: a range needs step or num")
            step = _check(AXIS_STEP, step, f"{key}.step")
            n = int(math.floor((stop - start) / step + 1e-9)) + 1
        if n > MAX_CASES:  # before the list is made (num = 1e8 hung the command)
            raise CampaignError(f"{key}: {n} values is too many; accepted: up to {MAX_CASES}")
        values = grid_values([start + k * step for k in range(n)])
        if integer:
            if not all(float(x).is_integer() for x in values):
                raise CampaignError(f"{key}: must give whole numbers")
            values = [int(x) for x in values]
        return values
    if not isinstance(v, list):
        raise CampaignError(f"{key}: must be a list or a range table {{start, stop, step}}, "
                            f"got {v!r}")
    if not v:
        raise CampaignError(f"{key}: empty axis; give at least one value")
    return list(v)


def _unique(values: list, key: str) -> list:
    seen: set = set()
    for x in values:
        try:
            dup = x in seen
            seen.add(x)
        except TypeError:  # an unhashable value (a table): refused by the caller's checks
            dup = False
        if dup:
            raise CampaignError(f"{key}: {x!r} appears twice")
    return list(values)


# The default --out "<name>.parquet" within the usual 255-byte file-name limit (ASCII names;
# a longer UTF-8 name meets the file system's own limit, reported in one line).
MAX_NAME_CHARS = 200


def _check_plain_name(name: str) -> None:
    """A campaign's ``name`` is the default output's file name (``<name>.parquet``): a plain
    file-name component, so that it cannot point outside the current folder."""
    bad = next((c for c in name if c in "/\\" or ord(c) < 32 or ord(c) == 127), None)
    if bad is None and unprintable(name):  # a bidirectional override, a line separator
        raise CampaignError(f"name: {ascii(name[:60])} holds {unprintable(name)}; accepted: "
                            "printable text")
    if (bad is not None or name.strip() in (".", "..") or name.startswith(".")
            or len(name) > MAX_NAME_CHARS):
        why = (f"contains {bad!r}" if bad is not None else
               f"is longer than {MAX_NAME_CHARS} characters" if len(name) > MAX_NAME_CHARS
               else "begins with a dot")
        raise CampaignError(f"name: {name[:60]!r} {why}; a campaign name is a plain file name "
                            "(letters, digits, '-', '_', no '/' or '\\', not starting with '.')")


def parse_campaign(
    data: dict, source: str = "campaign", base_dir: Path | None = None,
    default_name: str = "campaign",
) -> Campaign:
    """Check a parsed campaign mapping and build the :class:`Campaign`."""
    _unknown(data, TOP_KEYS, "")
    name = data.get("name", default_name)
    if not isinstance(name, str) or not name.strip():
        raise CampaignError(f"name: must be a non-empty string, got {name!r}")
    if "name" in data:
        _check_plain_name(name)
    description = _check(Text(empty=True), data.get("description", ""), "description")

    metrics_raw = data.get("metrics", ["gust"])
    if not isinstance(metrics_raw, list):
        raise CampaignError(f"metrics: must be a list of {', '.join(METRICS)}")
    if not metrics_raw:
        raise CampaignError(f"metrics: empty; give some of {', '.join(METRICS)}")
    for m in metrics_raw:
        _check(Choice(METRICS, noun="metric"), m, "metrics")
    metrics = tuple(m for m in METRICS if m in metrics_raw)

    settings = _settings(data.get("run", {}))

    axes = data.get("axes")
    if not isinstance(axes, dict):
        raise CampaignError("axes: missing table [axes] (wings, speeds_m_s, gusts, seeds, "
                            "models)")
    _unknown(axes, AXIS_KEYS, "axes")

    aircraft: list = []
    if "aircraft" in axes:
        from bioflex_jsb.sweep.aircraft_axis import aircraft_axis

        aircraft = aircraft_axis(_values(axes["aircraft"], "axes.aircraft"), base_dir, metrics)
    wings = _wings(axes, base_dir, required=not aircraft)

    if "speeds_m_s" not in axes:
        raise CampaignError("axes.speeds_m_s: missing; give the airspeeds [m/s]")
    speeds = [_check(SPEED, v, f"axes.speeds_m_s[{i}]")
              for i, v in enumerate(_values(axes["speeds_m_s"], "axes.speeds_m_s"))]
    speeds = _unique(grid_values(speeds), "axes.speeds_m_s")

    gusts = _gusts(axes, metrics)

    models_raw = _values(axes.get("models", ["coupled"]), "axes.models")
    for i, m in enumerate(models_raw):
        _check(Choice(MODELS, noun="model"), m, f"axes.models[{i}]")
    models = _unique(models_raw, "axes.models")
    if settings.aero != DEFAULT_AERO:
        other = next((m for m in models if m != "coupled"), None)
        if other is not None:
            raise CampaignError(f"run.aero: {settings.aero!r} is for the coupled model, and "
                                f"axes.models has {other!r} (the rigid and qsd wings are "
                                "quasi-steady); accepted with it: models = [\"coupled\"]")
        extra = next((m for m in metrics if m not in UNSTEADY_METRICS), None)
        if extra is not None:
            raise CampaignError(f"run.aero: {settings.aero!r} flies the gust runs; metric "
                                f"{extra!r} is the quasi-steady LTI model's; accepted with it: "
                                f"metrics from {', '.join(UNSTEADY_METRICS)}")

    controllers = _controllers(axes, metrics, base_dir)
    n = (len(wings) + len(aircraft)) * len(speeds) * len(gusts) * len(models) * \
        len(controllers)
    if n > MAX_CASES:
        raise CampaignError(f"axes: {n} cases is more than {MAX_CASES}")
    return Campaign(name.strip(), description, metrics, settings, tuple(wings), tuple(speeds),
                    tuple(gusts), tuple(models), source, tuple(aircraft), tuple(controllers),
                    "controllers" in axes)


def _controllers(axes: dict, metrics: tuple[str, ...], base_dir: Path | None) -> list:
    """axes.controllers: each a controller file (relative to the campaign's folder; kept
    by its absolute path, which the workers and a case's log read) or a shipped controller's
    name, or "none" (None: the gust run without a controller); each loaded once here, so a
    bad file is one line before any case runs. Without the axis: [None]."""
    if "controllers" not in axes:
        return [None]
    if "gust" not in metrics:
        raise CampaignError("axes.controllers: given but metrics has no 'gust' (a controller "
                            "flies in the gust runs)")
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.simulation.controller import load_controller, shipped_controllers

    out: list[str | None] = []
    for i, c in enumerate(_values(axes["controllers"], "axes.controllers")):
        key = f"axes.controllers[{i}]"
        if not isinstance(c, str) or not c:
            raise CampaignError(f"{key}: must be a controller file, a shipped controller's "
                                f"name or \"{NO_CONTROLLER}\", got {c!r}")
        if c == NO_CONTROLLER:
            out.append(None)
            continue
        if c not in shipped_controllers() and (Path(c).suffix or Path(c).exists()):
            path = Path(c)
            if base_dir is not None and not path.is_absolute():
                path = base_dir / path
            c = str(path.resolve())
        try:
            outputs = load_controller(c).outputs
        except InputError as exc:
            raise CampaignError(f"{key}: {exc}") from None
        if "aileron" in outputs:  # a campaign's gust runs fly the half wing
            raise CampaignError(f"{key}: {c!r} commands the aileron, which needs both wing "
                                "halves; a campaign's runs fly the half wing (accepted: "
                                "elevator, throttle, flaperon)")
        out.append(c)
    return _unique(out, "axes.controllers")


def _settings(run: Any) -> RunSettings:
    if not isinstance(run, dict):
        raise CampaignError("run: must be a table [run]")
    t = read_table(RunTable, run, "", CampaignError, "run")
    if t.gust_start_s >= t.duration_s:
        raise CampaignError(f"run.gust_start_s: {t.gust_start_s:g} s must be before the end of "
                            f"the run (run.duration_s {t.duration_s:g} s)")
    return RunSettings(t.duration_s, t.gust_start_s, t.dt_s, t.mass_basis,
                       t.flutter_range_m_s, t.aero)


def _wings(axes: dict, base_dir: Path | None, required: bool = True) -> list[WingVariant]:
    wings: list[WingVariant] = []
    if "wings" in axes:
        for i, w in enumerate(_values(axes["wings"], "axes.wings")):
            key = f"axes.wings[{i}]"
            if not isinstance(w, str):
                raise CampaignError(f"{key}: must be a wing name or a variant file, got {w!r}")
            if w.endswith(".toml"):
                path = Path(w)
                if base_dir is not None and not path.is_absolute():
                    path = base_dir / path
                try:
                    wings.append(load_variant_file(path))
                except VariantError as exc:
                    raise CampaignError(f"{key}: {exc}") from None
            elif w in VARIANTS:
                wings.append(VARIANTS[w])
            else:
                raise CampaignError(f"{key}: unknown wing {w!r}; accepted: "
                                    f"{', '.join(VARIANTS)} or a variant file (.toml)")
    has_xi, has_xe = "x_inertial_frac" in axes, "x_elastic_frac" in axes
    if has_xi != has_xe:
        missing = "axes.x_elastic_frac" if has_xi else "axes.x_inertial_frac"
        raise CampaignError(f"{missing}: missing; axis positions need both x_inertial_frac "
                            "and x_elastic_frac")
    if has_xi:
        grids = {}
        for key in ("x_inertial_frac", "x_elastic_frac"):
            values = _values(axes[key], f"axes.{key}")
            grids[key] = _unique(grid_values(
                [_check(CHORD_FRACTION, v, f"axes.{key}[{i}]")
                 for i, v in enumerate(values)]), f"axes.{key}")
        for xi in grids["x_inertial_frac"]:
            for xe in grids["x_elastic_frac"]:
                wings.append(axis_variant(xi, xe))
    if not wings and required:
        raise CampaignError("axes.wings: missing; give axes.wings, axes.aircraft or "
                            "axes.x_inertial_frac and axes.x_elastic_frac")
    names: set[str] = set()
    for w in wings:
        if w.name in names:
            raise CampaignError(f"axes.wings: wing {w.name!r} appears twice")
        names.add(w.name)
    return wings


def axis_variant(x_inertial_frac: float, x_elastic_frac: float) -> WingVariant:
    """The original wing with its axes moved to these chord fractions, unpinned (the strip
    model's physical coefficients)."""
    return dataclasses.replace(
        VARIANTS["original"],
        name=f"xI{x_inertial_frac:g}-xE{x_elastic_frac:g}",
        x_inertial_frac=float(x_inertial_frac),
        x_elastic_frac=float(x_elastic_frac),
        pinned_c_eta1_q1=None,
        published_c_eta1_q1=None,
        description="axis positions of a campaign",
    )


def _gusts(axes: dict, metrics: tuple[str, ...]) -> list[str]:
    if "gust" not in metrics:
        for key in ("gusts", "seeds"):
            if key in axes:
                raise CampaignError(f"axes.{key}: given but metrics has no 'gust' (no gust "
                                    "runs)")
        return ["none"]
    if "gusts" not in axes:
        raise CampaignError("axes.gusts: missing; give the gusts (sharp:A, 1cos:A:L, "
                            "dryden:S:L, vonkarman:S:L)")
    specs = []
    for i, g in enumerate(_values(axes["gusts"], "axes.gusts")):
        key = f"axes.gusts[{i}]"
        if not isinstance(g, str):
            raise CampaignError(f"{key}: must be a gust string such as 'sharp:3', got {g!r}")
        try:
            specs.append((key, g, parse_gust(g)))
        except GustSpecError as exc:
            raise CampaignError(f"{key}: {exc}") from None
    seeds = None
    if "seeds" in axes:
        seeds = _values(axes["seeds"], "axes.seeds", integer=True)
        for i, s in enumerate(seeds):
            _check(SEED, s, f"axes.seeds[{i}]")
        seeds = _unique(seeds, "axes.seeds")
        if not any(spec.kind in TURBULENCE for _, _, spec in specs):
            raise CampaignError("axes.seeds: given but no gust is turbulence (dryden, "
                                "vonkarman)")
    out: list[str] = []
    for key, text, spec in specs:
        if spec.kind in TURBULENCE:
            if seeds is not None:
                if len(text.split(":")) == 4:
                    raise CampaignError(f"{key}: {text!r} names a seed and axes.seeds is given; "
                                        "give one or the other")
                out.extend(dataclasses.replace(spec, seed=s).text() for s in seeds)
            else:
                out.append(spec.text())
        else:
            out.append(spec.text())
    return _unique(out, "axes.gusts")
