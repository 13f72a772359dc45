"""Service limits: request size, planner budget, concurrency. Read from the environment by ``gsr serve``."""

from __future__ import annotations

import os
from dataclasses import dataclass


@dataclass(frozen=True)
class ServiceSettings:
    """Limits that keep one client from starving the others (all overridable per deployment)."""

    max_body_bytes: int = 1 << 20  # 1 MiB: a 50-object graph with a 100-step plan is ~30 KiB
    max_plan_seconds: float = 10.0  # planner wall-time cap per request (a request may ask for less)
    max_concurrent: int = 8  # CPU-heavy requests (plan, solve, validate) running at once
    queue_timeout: float = 10.0  # how long a request waits for a slot before 503
    max_steps: int = 1000  # steps in one plan to validate
    backends: tuple[str, ...] = ("grounder",)  # reasoner backends /v1/solve may use (server-side choice)

    @classmethod
    def from_env(cls) -> ServiceSettings:
        """Settings from ``GSR_SERVICE_*`` environment variables (unset ones keep their defaults)."""
        d = cls()

        def get(name: str, default: float) -> float:
            raw = os.environ.get(f"GSR_SERVICE_{name}")
            return type(default)(raw) if raw else default

        return cls(
            max_body_bytes=int(get("MAX_BODY_BYTES", d.max_body_bytes)),
            max_plan_seconds=float(get("MAX_PLAN_SECONDS", d.max_plan_seconds)),
            max_concurrent=int(get("MAX_CONCURRENT", d.max_concurrent)),
            queue_timeout=float(get("QUEUE_TIMEOUT", d.queue_timeout)),
            max_steps=int(get("MAX_STEPS", d.max_steps)),
            backends=tuple(b for b in os.environ.get("GSR_SERVICE_BACKENDS", "").split(",") if b)
            or d.backends,
        )
