"""``gsr serve``: settings from options and the environment, the bind check, uvicorn with N workers."""

from __future__ import annotations

import ipaddress
import os
import shutil
import sys
import tempfile
from pathlib import Path

from gsr.errors import GSRError
from gsr.service.settings import ServiceSettings

MAX_DEFAULT_WORKERS = 4


def is_loopback(host: str) -> bool:
    """True for localhost and loopback addresses (127.0.0.0/8, ::1); a hostname otherwise counts as public."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def default_workers() -> int:
    """``GSR_SERVICE_WORKERS``, else one per usable core, at most 4 (each also has an isolated worker)."""
    raw = os.environ.get("GSR_SERVICE_WORKERS")
    if raw:
        try:
            return max(1, int(raw))
        except ValueError:
            raise GSRError(f"GSR_SERVICE_WORKERS={raw!r}: expected int") from None
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:
        cores = os.cpu_count() or 1
    return max(1, min(cores, MAX_DEFAULT_WORKERS))


def serve(
    host: str,
    port: int,
    workers: int | None = None,
    api_key_file: Path | None = None,
    insecure: bool = False,
    log_json: bool = False,
    max_plan_seconds: float | None = None,
    max_concurrent: int | None = None,
) -> None:
    """Run the service until interrupted; a GSRError (one line) for a refused configuration."""
    import uvicorn

    env = os.environ
    if api_key_file is not None:
        env["GSR_SERVICE_API_KEY_FILE"] = str(api_key_file)
    if log_json:
        env["GSR_SERVICE_LOG_JSON"] = "1"
    if max_plan_seconds is not None:
        env["GSR_SERVICE_MAX_PLAN_SECONDS"] = str(max_plan_seconds)
    if max_concurrent is not None:
        env["GSR_SERVICE_MAX_CONCURRENT"] = str(max_concurrent)
    settings = ServiceSettings.from_env()  # fail here, once, on a bad variable or key file
    if not settings.api_keys and not is_loopback(host) and not insecure:
        raise GSRError(
            f"refusing to serve on {host} without API keys: anyone who can reach the port could use it; "
            "set GSR_SERVICE_API_KEYS or --api-key-file (or pass --insecure)"
        )
    n = workers if workers is not None else default_workers()
    own_state = not settings.state_dir
    if own_state:  # this server's processes share stored scenes and metrics here
        env["GSR_SERVICE_STATE_DIR"] = tempfile.mkdtemp(prefix="gsr-service-")
    auth = f"{len(settings.api_keys)} API key(s)" if settings.api_keys else "no API keys"
    print(f"gsr serve: http://{host}:{port} with {n} worker(s), {auth}", file=sys.stderr, flush=True)
    try:
        uvicorn.run(
            "gsr.service.asgi:app",
            host=host,
            port=port,
            workers=n,
            log_level="warning",
            access_log=False,  # the service logs each request itself, with its id
            timeout_graceful_shutdown=5,
            timeout_keep_alive=settings.keep_alive,
        )
    finally:
        if own_state:
            shutil.rmtree(env["GSR_SERVICE_STATE_DIR"], ignore_errors=True)
