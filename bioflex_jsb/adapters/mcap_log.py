"""MCAP logs of runs (the only module that imports ``mcap``).

Topics (JSON-schema encoded, one set per wing model of the run; units in every field name
and in the schema descriptions):

* ``/bioflex/<model>/rigid_body``: perturbations from trim and the flight state;
* ``/bioflex/<model>/modal``: modal coordinates η [rad] and rates η̇ [rad/s];
* ``/bioflex/<model>/modal_loads``: the elastic wing's loads on the airframe;
* ``/bioflex/<model>/gust``: the vertical gust w_g [m/s, up].

Log time is simulation time [ns from the run's start]. A metadata record ``bioflex.run``
holds the command, its arguments, the wing variant and the package versions.
"""

from __future__ import annotations

import json
import platform
from pathlib import Path

from mcap.writer import CompressionType, Writer

from bioflex_jsb import __version__

_SCHEMAS = {
    "rigid_body": {
        "title": "bioflex.RigidBody",
        "description": "Airframe state; perturbations are from the trim at the run start.",
        "type": "object",
        "properties": {
            "t_s": {"type": "number", "description": "simulation time [s]"},
            "u_m_s": {"type": "number", "description": "airspeed perturbation [m/s]"},
            "alpha_rad": {"type": "number",
                          "description": "angle-of-attack perturbation against the air [rad]"},
            "q_rad_s": {"type": "number", "description": "pitch rate, body y, nose up [rad/s]"},
            "theta_rad": {"type": "number", "description": "pitch-angle perturbation [rad]"},
            "n_z": {"type": "number", "description": "load factor, up, 1 in level flight [-]"},
            "airspeed_m_s": {"type": "number", "description": "true airspeed [m/s]"},
            "altitude_m": {"type": "number", "description": "altitude above sea level [m]"},
        },
    },
    "modal": {
        "title": "bioflex.Modal",
        "description": "Modal coordinates of the elastic wing (perturbations from trim).",
        "type": "object",
        "properties": {
            "t_s": {"type": "number", "description": "simulation time [s]"},
            "eta_rad": {"type": "array", "items": {"type": "number"},
                        "description": "η_i, mode i+1, normalised on twist [rad]"},
            "eta_dot_rad_s": {"type": "array", "items": {"type": "number"},
                              "description": "η̇_i [rad/s]"},
        },
    },
    "modal_loads": {
        "title": "bioflex.ModalLoads",
        "description": "Incremental loads of the elastic wing applied to the airframe.",
        "type": "object",
        "properties": {
            "t_s": {"type": "number", "description": "simulation time [s]"},
            "lift_n": {"type": "number", "description": "lift, up, normal to the air velocity [N]"},
            "drag_n": {"type": "number", "description": "drag, aft, along the air velocity [N]"},
            "pitch_moment_n_m": {"type": "number",
                                 "description": "pitching moment about the CG, nose up [N*m]"},
        },
    },
    "gust": {
        "title": "bioflex.Gust",
        "description": "Vertical gust applied to the airframe.",
        "type": "object",
        "properties": {
            "t_s": {"type": "number", "description": "simulation time [s]"},
            "w_g_m_s": {"type": "number", "description": "vertical gust velocity, up [m/s]"},
        },
    },
}


def _version(package: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(package)
    except PackageNotFoundError:
        return "unknown"


class RunLog:
    """An open MCAP file that runs write their samples into."""

    def __init__(self, path: Path, writer: Writer, stream) -> None:
        self.path = path
        self._writer = writer
        self._stream = stream
        self._schema_ids: dict[str, int] = {}
        self._channels: dict[tuple[str, str], int] = {}
        self._seq: dict[int, int] = {}
        for name, schema in _SCHEMAS.items():
            self._schema_ids[name] = writer.register_schema(
                name=schema["title"], encoding="jsonschema", data=json.dumps(schema).encode()
            )
        self.closed = False

    @classmethod
    def open(cls, path: str | Path, command: str, args, build) -> RunLog:
        p = Path(path)
        try:
            stream = open(p, "wb")  # noqa: SIM115 - closed in close()
        except OSError as exc:
            from bioflex_jsb.cli.common import UsageError

            raise UsageError(f"cannot write log {str(p)!r}: {exc.strerror}") from None
        writer = Writer(stream, chunk_size=64 * 1024, compression=CompressionType.ZSTD)
        writer.start(profile="", library=f"bioflex-jsb {__version__}")
        log = cls(p, writer, stream)
        arguments = {
            k: (v.text() if hasattr(v, "text") else v)
            for k, v in vars(args).items()
            if k != "run"
        }
        writer.add_metadata(
            "bioflex.run",
            {
                "command": command,
                "arguments": json.dumps(arguments, default=str),
                "wing": json.dumps(build.variant.as_dict()),
                "mass_basis": build.mass_basis,
                "bioflex_jsb_version": __version__,
                "jsbsim_version": _version("jsbsim"),
                "python": platform.python_version(),
            },
        )
        return log

    def _channel(self, model: str, group: str) -> int:
        key = (model, group)
        if key not in self._channels:
            self._channels[key] = self._writer.register_channel(
                topic=f"/bioflex/{model}/{group}",
                message_encoding="json",
                schema_id=self._schema_ids[group],
            )
        return self._channels[key]

    def _write(self, model: str, group: str, t_s: float, payload: dict) -> None:
        cid = self._channel(model, group)
        seq = self._seq.get(cid, 0)
        self._seq[cid] = seq + 1
        ns = int(round(t_s * 1e9))
        self._writer.add_message(cid, ns, json.dumps(payload).encode(), ns, seq)

    def sample(self, model: str, t_s: float, row: dict[str, float]) -> None:
        """Write one co-simulation sample (a row of the run's channels)."""
        self._write(model, "rigid_body", t_s, {
            "t_s": t_s, "u_m_s": row["u"], "alpha_rad": row["alpha"], "q_rad_s": row["q"],
            "theta_rad": row["theta"], "n_z": row["n_z"], "airspeed_m_s": row["airspeed_m_s"],
            "altitude_m": row["altitude_m"],
        })
        n = sum(1 for k in row if k.startswith("eta") and not k.endswith("_dot"))
        self._write(model, "modal", t_s, {
            "t_s": t_s,
            "eta_rad": [row[f"eta{i + 1}"] for i in range(n)],
            "eta_dot_rad_s": [row[f"eta{i + 1}_dot"] for i in range(n)],
        })
        self._write(model, "modal_loads", t_s, {
            "t_s": t_s, "lift_n": row["lift_n"], "drag_n": row["drag_n"],
            "pitch_moment_n_m": row["pitch_moment_n_m"],
        })
        self._write(model, "gust", t_s, {"t_s": t_s, "w_g_m_s": row["w_g"]})

    def close(self) -> None:
        if not self.closed:
            self._writer.finish()
            self._stream.close()
            self.closed = True
