"""``openai:MODEL``: any OpenAI-compatible chat endpoint (vLLM, Ollama, llama.cpp server, hosted APIs).

The base URL and key come from the options or from ``OPENAI_BASE_URL`` / ``OPENAI_API_KEY``; a local
server needs no key. httpx is imported when the backend is built.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from typing import Any

from gsr.reason.backend import BackendError, Query
from gsr.reason.prompt import Prompt

DEFAULT_BASE_URL = "https://api.openai.com/v1"
_RETRY_STATUS = frozenset({429, 500, 502, 503, 504})


class OpenAIBackend:
    """Chat completions (``/chat/completions``) or plain completions (``chat=False``) over HTTP."""

    def __init__(
        self,
        model: str,
        base_url: str | None = None,
        api_key: str | None = None,
        temperature: float = 0.0,
        max_tokens: int = 256,
        timeout: float = 60.0,
        retries: int = 2,
        chat: bool = True,
        seed: int | None = 0,
    ) -> None:
        try:
            import httpx
        except ImportError:
            raise BackendError("the openai backend needs httpx: pip install 'gsr[serve]'") from None
        self.model = model
        self.name = f"openai:{model}"
        self.base_url = (base_url or os.environ.get("OPENAI_BASE_URL") or DEFAULT_BASE_URL).rstrip("/")
        key = api_key if api_key is not None else os.environ.get("OPENAI_API_KEY")
        headers = {"Authorization": f"Bearer {key}"} if key else {}
        self.client = httpx.Client(base_url=self.base_url, headers=headers, timeout=timeout)
        self.temperature = temperature
        self.max_tokens = max_tokens
        self.retries = retries
        self.chat = chat
        self.seed = seed

    def _body(self, prompt: Prompt, stop: Sequence[str]) -> tuple[str, dict[str, Any]]:
        body: dict[str, Any] = {
            "model": self.model,
            "temperature": self.temperature,
            "max_tokens": self.max_tokens,
        }
        if self.seed is not None:
            body["seed"] = self.seed
        if stop:
            body["stop"] = list(stop)
        if self.chat:
            body["messages"] = prompt.messages()
            return "/chat/completions", body
        body["prompt"] = prompt.text()
        return "/completions", body

    def complete(self, prompt: Prompt, stop: Sequence[str] = (), query: Query | None = None) -> str:
        """POST the prompt and return the first choice's text; BackendError on HTTP or format errors."""
        import httpx

        path, body = self._body(prompt, stop)
        url = f"{self.base_url}{path}"
        for attempt in range(self.retries + 1):
            try:
                response = self.client.post(path, json=body)
            except httpx.HTTPError as exc:
                if attempt < self.retries:
                    time.sleep(0.5 * 2**attempt)
                    continue
                raise BackendError(f"{url}: request failed: {exc}") from None
            if response.status_code in _RETRY_STATUS and attempt < self.retries:
                time.sleep(0.5 * 2**attempt)
                continue
            if response.status_code != 200:
                raise BackendError(f"{url}: HTTP {response.status_code}: {response.text[:300]}")
            return self._text(response, url)
        raise BackendError(f"{url}: no answer after {self.retries + 1} tries")  # pragma: no cover

    def _text(self, response: Any, url: str) -> str:
        try:
            choice = response.json()["choices"][0]
            text = choice["message"]["content"] if self.chat else choice["text"]
        except (ValueError, KeyError, IndexError, TypeError):
            raise BackendError(f"{url}: not an OpenAI completion response: {response.text[:300]}") from None
        return text if isinstance(text, str) else ""

    def close(self) -> None:
        """Close the HTTP connection pool."""
        self.client.close()
