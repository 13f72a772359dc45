"""The ASGI layer in front of the endpoints: request ids, API keys, body size, in-flight limit,
metrics and one log line per request. Plain ASGI (not BaseHTTPMiddleware) to keep its cost small.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import logging
import re
import time
import uuid
from typing import Any

from gsr.service.handlers import error_body
from gsr.service.metrics import Metrics
from gsr.service.settings import ServiceSettings

log = logging.getLogger("gsr.service")
OPEN_PATHS = frozenset({"/health"})  # answered without an API key (load balancers, probes)
_REQUEST_ID = re.compile(r"[A-Za-z0-9._:-]{1,64}")


class RejectedError(Exception):
    """A request refused before it reached an endpoint."""

    def __init__(
        self, status: int, kind: str, message: str, headers: dict[str, str] | None = None, **details
    ):
        super().__init__(message)
        self.status, self.kind, self.message, self.headers, self.details = (
            status,
            kind,
            message,
            headers,
            details,
        )


class KeyCheck:
    """Bearer API keys compared in constant time (digests of equal length, every key compared)."""

    def __init__(self, keys: tuple[str, ...]) -> None:
        self._digests = [hashlib.sha256(k.encode()).digest() for k in keys]

    @property
    def enabled(self) -> bool:
        return bool(self._digests)

    def verify(self, authorization: str | None) -> None:
        challenge = {"WWW-Authenticate": 'Bearer realm="gsr"'}
        if not authorization:
            raise RejectedError(
                401, "unauthorized", "an API key is required: Authorization: Bearer <key>", challenge
            )
        scheme, _, token = authorization.partition(" ")
        if scheme.lower() != "bearer" or not token.strip():
            raise RejectedError(401, "unauthorized", "expected Authorization: Bearer <key>", challenge)
        digest = hashlib.sha256(token.strip().encode()).digest()
        match = False
        for known in self._digests:  # no early exit: the time does not depend on which key matched
            match |= hmac.compare_digest(digest, known)
        if not match:
            raise RejectedError(401, "unauthorized", "invalid API key", challenge)


class ServiceMiddleware:
    """Wraps the FastAPI app; ``route_of`` maps a path to its metrics label (bounded cardinality)."""

    def __init__(self, app, settings: ServiceSettings, metrics: Metrics, route_of) -> None:
        self.app = app
        self.settings = settings
        self.metrics = metrics
        self.keys = KeyCheck(settings.api_keys)
        self.route_of = route_of

    async def __call__(self, scope, receive, send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        start = time.perf_counter()
        headers = {k.decode("latin-1"): v.decode("latin-1") for k, v in scope["headers"]}
        given = headers.get("x-request-id", "")
        request_id = given if _REQUEST_ID.fullmatch(given) else uuid.uuid4().hex
        scope.setdefault("state", {})["request_id"] = request_id
        path, method = scope["path"], scope["method"]
        status = [500]
        raw_id = request_id.encode()

        async def send_with_id(message: dict[str, Any]) -> None:
            if message["type"] == "http.response.start":
                status[0] = message["status"]
                message["headers"] = [*message.get("headers", []), (b"x-request-id", raw_id)]
            await send(message)

        m = self.metrics
        m.in_flight += 1
        rejected: RejectedError | None = None
        try:
            try:
                if m.in_flight > self.settings.max_in_flight and path not in OPEN_PATHS:
                    raise RejectedError(
                        429,
                        "busy",
                        f"over {self.settings.max_in_flight} requests in flight; retry later",
                        {"Retry-After": "1"},
                        limit="GSR_SERVICE_MAX_IN_FLIGHT",
                        max=self.settings.max_in_flight,
                        retry_after=1,
                    )
                if self.keys.enabled and path not in OPEN_PATHS:
                    self.keys.verify(headers.get("authorization"))
                if method in ("POST", "PUT", "PATCH"):
                    receive = await self._buffered(receive, headers.get("content-length"))
            except RejectedError as exc:
                rejected = exc
                m.inc("gsr_rejections_total", reason=rejection_reason(exc.kind, exc.details))
                body = error_body(exc.kind, exc.message, request_id=request_id, **exc.details)
                await _send_json(send_with_id, exc.status, body, exc.headers)
                return
            await self.app(scope, receive, send_with_id)
        finally:
            m.in_flight -= 1
            seconds = time.perf_counter() - start
            endpoint = self.route_of(path)
            m.observe_request(endpoint, method, status[0], seconds)
            if self.settings.log_requests:
                extra = {"reason": rejected.kind} if rejected else {}
                _log_request(request_id, method, path, status[0], seconds, **extra)

    async def _buffered(self, receive, declared: str | None):
        """Read the body up to the size limit (413 past it) and replay it to the app."""
        limit = self.settings.max_body_bytes
        too_large = RejectedError(
            413,
            "body_too_large",
            f"request body over {limit} bytes",
            limit="GSR_SERVICE_MAX_BODY_BYTES",
            max=limit,
        )
        if declared is not None and (not declared.isdigit() or int(declared) > limit):
            raise too_large
        chunks: list[bytes] = []
        size = 0
        more = True
        while more:
            message = await receive()
            if message["type"] == "http.disconnect":
                break
            chunk = message.get("body", b"")
            size += len(chunk)
            if size > limit:
                raise too_large
            chunks.append(chunk)
            more = message.get("more_body", False)
        body = b"".join(chunks)
        sent = False

        async def replay() -> dict[str, Any]:
            nonlocal sent
            if not sent:
                sent = True
                return {"type": "http.request", "body": body, "more_body": False}
            return await receive()

        return replay


def rejection_reason(kind: str, details: dict[str, Any]) -> str:
    """The metrics label of a refusal: the limit's setting (``max_body_bytes``, ...) or the error type."""
    limit = details.get("limit")
    return limit.removeprefix("GSR_SERVICE_").lower() if isinstance(limit, str) else kind


async def _send_json(send, status: int, body: dict[str, Any], headers: dict[str, str] | None = None) -> None:
    raw = json.dumps(body).encode()
    hdrs = [(b"content-type", b"application/json"), (b"content-length", str(len(raw)).encode())]
    hdrs += [(k.lower().encode(), v.encode()) for k, v in (headers or {}).items()]
    await send({"type": "http.response.start", "status": status, "headers": hdrs})
    await send({"type": "http.response.body", "body": raw})


def _log_request(request_id: str, method: str, path: str, status: int, seconds: float, **extra: Any) -> None:
    if not log.isEnabledFor(logging.INFO):
        return
    log.info(
        "%s %s %s %.1f ms",
        method,
        path,
        status,
        seconds * 1e3,
        extra={
            "request_id": request_id,
            "fields": {
                "method": method,
                "path": path,
                "status": status,
                "ms": round(seconds * 1e3, 2),
                **extra,
            },
        },
    )


class JsonFormatter(logging.Formatter):
    """One JSON object per line: time, level, logger, message, request_id and the request fields."""

    def format(self, record: logging.LogRecord) -> str:
        out: dict[str, Any] = {
            "time": time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime(record.created))
            + f".{int(record.msecs):03d}Z",
            "level": record.levelname.lower(),
            "logger": record.name,
            "message": record.getMessage(),
        }
        if getattr(record, "request_id", None):
            out["request_id"] = record.request_id
        out.update(getattr(record, "fields", {}))
        if record.exc_info:
            out["exception"] = self.formatException(record.exc_info)
        return json.dumps(out)


class TextFormatter(logging.Formatter):
    """``time level [request id] message``."""

    def format(self, record: logging.LogRecord) -> str:
        rid = getattr(record, "request_id", None)
        stamp = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(record.created))
        text = f"{stamp} {record.levelname} {'[' + rid + '] ' if rid else ''}{record.getMessage()}"
        if record.exc_info:
            text += "\n" + self.formatException(record.exc_info)
        return text


def configure_logging(json_lines: bool, level: int = logging.INFO) -> None:
    """Send the service's log to stderr (idempotent), as JSON lines or text."""
    import sys

    for handler in list(log.handlers):
        if getattr(handler, "_gsr_service", False):
            log.removeHandler(handler)
    handler = logging.StreamHandler(sys.stderr)
    handler._gsr_service = True  # type: ignore[attr-defined]
    handler.setFormatter(JsonFormatter() if json_lines else TextFormatter())
    log.addHandler(handler)
    log.setLevel(level)
    log.propagate = False
