"""Service settings: API keys, limits, workers. ``from_env`` reads the ``GSR_SERVICE_*`` variables.

Every limit has an environment variable (``GSR_SERVICE_<FIELD NAME IN CAPITALS>``); the error a client
gets when it hits a limit names that variable (docs/service.md lists them all).
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, fields, replace
from pathlib import Path

from gsr.errors import GSRError

MIN_KEY_CHARS = 16


@dataclass(frozen=True)
class ServiceSettings:
    """Limits that keep one client from starving the others (all overridable per deployment)."""

    api_keys: tuple[str, ...] = ()  # empty: no authentication (gsr serve refuses a public bind then)
    max_body_bytes: int = 1 << 20  # 1 MiB: a 50-object graph with a 100-step plan is ~30 KiB
    max_nodes: int = 1000  # scene-graph nodes in one request
    max_edges: int = 5000  # scene-graph edges in one request
    max_steps: int = 1000  # steps in one plan to validate
    max_instruction_chars: int = 2000  # characters of one instruction to ground or solve
    max_plan_seconds: float = 10.0  # time budget of one plan/solve/ground/user-PDDL request
    max_concurrent: int = 8  # in-process requests (check, validate, scenes) computing at once
    isolated_workers: int = 2  # worker processes for plan/solve/ground/user PDDL, per server process
    warm_workers: bool = True  # start the worker processes when the server starts, not on first use
    worker_memory_mb: int = 1024  # address-space limit of each worker process
    worker_nice: int = 5  # worker processes yield the CPU to the server's cheap requests
    max_queue: int = 64  # requests waiting for a worker process; more are refused at once
    queue_timeout: float = 10.0  # how long a request waits for a slot before 429
    max_in_flight: int = 512  # requests inside one server process at once; more are refused (429)
    backends: tuple[str, ...] = ("grounder",)  # reasoner backends /v1/solve may use (server-side choice)
    state_dir: str = ""  # shared by a server's processes: stored scenes, metrics; "" = a default under /tmp
    max_scenes: int = 10000  # scenes kept on disk for /v1/scenes (oldest dropped first)
    keep_alive: int = 75  # seconds an idle HTTP connection stays open (longer than clients' and proxies')
    log_json: bool = False  # one JSON object per log line
    log_requests: bool = True  # one log line per request (INFO)

    def __post_init__(self) -> None:
        short = [k for k in self.api_keys if len(k) < MIN_KEY_CHARS]
        if short:
            raise GSRError(f"API keys must have at least {MIN_KEY_CHARS} characters ({len(short)} shorter)")

    @property
    def state_path(self) -> Path:
        """The state directory (created on first use)."""
        path = Path(self.state_dir or Path(tempfile.gettempdir()) / f"gsr-service-{os.getuid()}")
        path.mkdir(parents=True, exist_ok=True, mode=0o700)
        return path

    @classmethod
    def from_env(cls, environ: dict[str, str] | None = None) -> ServiceSettings:
        """Settings from ``GSR_SERVICE_*`` variables (unset ones keep their defaults).

        Keys come from ``GSR_SERVICE_API_KEYS`` (comma-separated) and/or ``GSR_SERVICE_API_KEY_FILE``
        (one key per line, ``#`` comments). A malformed value is a GSRError naming the variable.
        """
        env = os.environ if environ is None else environ
        values: dict[str, object] = {}
        for f in fields(cls):
            name = f"GSR_SERVICE_{f.name.upper()}"
            raw = env.get(name)
            if f.name == "api_keys" or raw is None or raw == "":
                continue
            default = f.default
            try:
                if isinstance(default, bool):
                    if raw.lower() not in ("1", "0", "true", "false", "yes", "no"):
                        raise ValueError(raw)
                    values[f.name] = raw.lower() in ("1", "true", "yes")
                elif isinstance(default, tuple):
                    values[f.name] = tuple(v.strip() for v in raw.split(",") if v.strip())
                else:
                    values[f.name] = type(default)(raw)
            except ValueError:
                raise GSRError(f"{name}={raw!r}: expected {type(default).__name__}") from None
        values["api_keys"] = load_keys(
            env.get("GSR_SERVICE_API_KEYS", ""), env.get("GSR_SERVICE_API_KEY_FILE")
        )
        return replace(cls(), **values)


def load_keys(listed: str, key_file: str | None) -> tuple[str, ...]:
    """API keys from a comma-separated list and an optional key file (one per line, ``#`` comments)."""
    keys = [k.strip() for k in listed.split(",") if k.strip()]
    if key_file:
        try:
            text = Path(key_file).read_text(encoding="utf-8")
        except OSError as exc:
            raise GSRError(f"{key_file}: cannot read the API key file: {exc.strerror}") from None
        keys += [ln.strip() for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    return tuple(dict.fromkeys(keys))
