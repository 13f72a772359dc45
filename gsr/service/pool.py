"""Isolated worker processes with a hard time budget: a job that overruns is killed, not abandoned.

Planning, solving, grounding and anything over user-supplied PDDL can take unbounded time and memory
(grounding alone is exponential in the operators' arity). Those jobs run here: each in a worker process
with an address-space limit, answered within ``budget`` seconds or the process is killed (SIGKILL) and
replaced, and the request gets a 422 ``time_limit`` error naming the limit. A thread cannot be stopped
like that; a process can.

Workers are forked from a forkserver that has imported gsr once, so a replacement starts in
milliseconds. Each server process (uvicorn worker) has its own pool.
"""

from __future__ import annotations

import asyncio
import contextlib
import gc
import logging
import multiprocessing
import os
import resource
import signal
from typing import Any

from gsr.service.handlers import ApiError, api_error_from, limit_error, run_handler
from gsr.service.settings import ServiceSettings

log = logging.getLogger("gsr.service")
_PRELOAD = ["gsr.service.handlers", "gsr.plan", "gsr.check", "gsr.validate", "gsr.language", "gsr.reason"]


def _worker_main(conn, settings: ServiceSettings) -> None:
    """A worker: receive (handler name, args), answer ("ok", result) or ("error", ApiError parts)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the server stops us; Ctrl-C is for it
    gc.freeze()  # the preloaded modules stay out of the collector's way
    if settings.worker_nice > 0:
        os.nice(settings.worker_nice)
    if settings.worker_memory_mb > 0:
        limit = settings.worker_memory_mb << 20
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    while True:
        try:
            name, req, scene = conn.recv()
        except (EOFError, OSError):
            return
        out_of_memory = False
        try:
            reply: tuple = ("ok", run_handler(name, req, settings, scene))
        except MemoryError:  # answered below, once the failed frames (and their memory) are gone
            out_of_memory, reply = True, ()
        except BaseException as exc:
            err = api_error_from(exc)
            if err is None:
                reply = ("crash", f"{type(exc).__name__}: {exc}")
            else:
                reply = ("error", err.status, err.kind, err.message, err.details)
        if out_of_memory:
            gc.collect()
            err = api_error_from(MemoryError())
            reply = ("error", err.status, err.kind, err.message, err.details)
        try:
            conn.send(reply)
        except (EOFError, OSError):
            return
        except Exception as exc:
            conn.send(("crash", f"cannot send the result: {exc}"))


class _Worker:
    def __init__(self, ctx, settings: ServiceSettings) -> None:
        self.conn, child = ctx.Pipe()
        self.process = ctx.Process(target=_worker_main, args=(child, settings), daemon=True)
        self.process.start()
        child.close()

    def kill(self) -> None:
        with contextlib.suppress(OSError, ValueError):
            self.process.kill()
        self.process.join(timeout=5)
        self.conn.close()


class IsolatedPool:
    """``size`` worker processes shared by one server process's requests; lazily started."""

    def __init__(self, settings: ServiceSettings, on_event=None) -> None:
        self.settings = settings
        self._idle: list[_Worker] = []
        self._started = 0
        self._waiting = 0
        self._slots: asyncio.Semaphore | None = None
        self._on_event = on_event or (lambda name: None)
        self._ctx = None

    def _context(self):
        if self._ctx is None:
            method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
            self._ctx = multiprocessing.get_context(method)
            if method == "forkserver":
                self._ctx.set_forkserver_preload(_PRELOAD)
        return self._ctx

    async def run(self, name: str, req: Any, scene: Any, budget: float) -> dict[str, Any]:
        """Run handler ``name`` in a worker within ``budget`` seconds (429 when no worker frees in time)."""
        s = self.settings
        if self._slots is None:
            self._slots = asyncio.Semaphore(max(s.isolated_workers, 0))
        if self._waiting >= s.max_queue or s.isolated_workers <= 0:
            raise _busy(s, "max_queue", s.max_queue, "too many requests are waiting for a worker")
        self._waiting += 1
        try:
            await asyncio.wait_for(self._slots.acquire(), timeout=s.queue_timeout)
        except TimeoutError:
            raise _busy(s, "queue_timeout", s.queue_timeout, "no worker freed in time") from None
        finally:
            self._waiting -= 1
        try:
            worker = self._idle.pop() if self._idle else await asyncio.to_thread(self._start)
            reply = await self._ask(worker, (name, req, scene), budget)
            if len(self._idle) < max(s.isolated_workers, 1):
                self._idle.append(worker)
            else:  # warm() and a request both started one
                worker.kill()
        finally:
            self._slots.release()
        kind = reply[0]
        if kind == "ok":
            return reply[1]
        if kind == "error":
            _, status, err_kind, message, details = reply
            raise ApiError(status, err_kind, message, **details)
        raise RuntimeError(f"worker failed: {reply[1]}")

    async def warm(self) -> None:
        """Start the workers ahead of the first request (the first start imports gsr: seconds)."""
        n = self.settings.isolated_workers - len(self._idle)
        if n > 0:
            started = await asyncio.to_thread(lambda: [self._start() for _ in range(n)])
            self._idle.extend(started)

    def _start(self) -> _Worker:
        self._started += 1
        return _Worker(self._context(), self.settings)

    async def _ask(self, worker: _Worker, job: tuple, budget: float) -> tuple:
        loop = asyncio.get_running_loop()
        ready = loop.create_future()
        fd = worker.conn.fileno()
        try:
            worker.conn.send(job)
            loop.add_reader(fd, lambda: ready.done() or ready.set_result(None))
            try:
                await asyncio.wait_for(ready, timeout=budget)
            finally:
                loop.remove_reader(fd)
            return worker.conn.recv()
        except TimeoutError:
            self._replace(worker, "time_limit")
            raise limit_error(
                422,
                "time_limit",
                "max_plan_seconds",
                self.settings.max_plan_seconds,
                f"the request ran past its time budget of {budget:g} s and was stopped",
            ) from None
        except (EOFError, OSError):
            self._replace(worker, "worker_died")
            code = worker.process.exitcode
            log.error(
                "worker process %s ended while running a request (exit code %s)", worker.process.pid, code
            )
            raise ApiError(
                422,
                "worker_died",
                f"the worker process running this request ended (exit code {code}); the request likely "
                "needs more memory than a worker may use",
                limit="GSR_SERVICE_WORKER_MEMORY_MB",
                max=self.settings.worker_memory_mb,
            ) from None
        except BaseException:  # cancelled (client gone, server stopping): the worker may still be busy
            self._replace(worker, "cancelled")
            raise

    def _replace(self, worker: _Worker, why: str) -> None:
        log.warning("stopping worker process %s (%s)", worker.process.pid, why)
        self._on_event(why)
        worker.kill()

    def close(self) -> None:
        """Stop every idle worker (busy ones are killed by their requests' cancellation)."""
        while self._idle:
            self._idle.pop().kill()


def _busy(settings: ServiceSettings, setting: str, limit: float, why: str) -> ApiError:
    err = limit_error(429, "busy", setting, limit, f"{why}; retry later")
    err.details["retry_after"] = 1
    return err
