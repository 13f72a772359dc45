"""The backend registry: ``make_backend(spec)`` for ``grounder``, ``transformers:PATH``, ``openai:MODEL``.

A spec is ``KIND`` or ``KIND:ARG``. Each kind maps to a factory ``(arg, **options) -> Backend`` in
:data:`BACKENDS`; :func:`register_backend` adds one (a client for another server, a scripted backend in
a test). The backend modules load the heavy libraries behind them (torch/transformers, httpx) only when a
backend is built, so importing the registry stays cheap. The protocol the backends
implement lives in :mod:`gsr.reason.backend`, which imports none of them.
"""

from __future__ import annotations

from collections.abc import Callable

from gsr.errors import GSRError
from gsr.reason.backend import Backend, FunctionBackend
from gsr.reason.grounder_backend import GrounderBackend
from gsr.reason.hf_backend import TransformersBackend
from gsr.reason.openai_backend import OpenAIBackend

#: A factory gets the text after ``KIND:`` ("" for a bare ``KIND``) and the caller's options.
BackendFactory = Callable[..., Backend]


def _grounder(arg: str, **options: object) -> Backend:
    if arg:
        raise GSRError(f"the grounder backend takes no argument (got 'grounder:{arg}')")
    return GrounderBackend(**options)  # type: ignore[arg-type]


_LOADED: dict[tuple, Backend] = {}


def _transformers(arg: str, **options: object) -> Backend:
    if not arg:
        raise GSRError("the transformers backend needs a model: transformers:PATH")
    # loading weights is slow: reuse a loaded model for the same path and options (service, benchmarks)
    key = (arg, tuple(sorted((k, repr(v)) for k, v in options.items())))
    if key not in _LOADED:
        _LOADED[key] = TransformersBackend(arg, **options)  # type: ignore[arg-type]
    return _LOADED[key]


def _openai(arg: str, **options: object) -> Backend:
    if not arg:
        raise GSRError("the openai backend needs a model name: openai:MODEL")
    return OpenAIBackend(arg, **options)  # type: ignore[arg-type]


#: Backend kinds, in the order the error message lists them.
BACKENDS: dict[str, BackendFactory] = {
    "grounder": _grounder,
    "transformers": _transformers,
    "openai": _openai,
}


def register_backend(kind: str, factory: BackendFactory) -> None:
    """Make ``KIND[:ARG]`` specs build backends with ``factory(arg, **options)``."""
    if not kind or ":" in kind:
        raise GSRError(f"a backend kind is a name without ':' (got {kind!r})")
    BACKENDS[kind] = factory


def make_backend(spec: str, **options: object) -> Backend:
    """The backend a spec names; options go to the backend's constructor."""
    kind, _, arg = spec.partition(":")
    factory = BACKENDS.get(kind)
    if factory is None:
        usage = ", ".join(
            {"grounder": "grounder", "transformers": "transformers:PATH", "openai": "openai:MODEL"}.get(k, k)
            for k in BACKENDS
        )
        raise GSRError(f"unknown backend {spec!r}: use {usage}")
    return factory(arg, **options)


def as_backend(obj: Backend | Callable[[str], str] | str) -> Backend:
    """A backend from a backend object, a ``str -> str`` function or a spec string."""
    if isinstance(obj, str):
        return make_backend(obj)
    if hasattr(obj, "complete"):
        return obj  # type: ignore[return-value]
    if callable(obj):
        return FunctionBackend(obj)
    raise GSRError(f"not a backend: {obj!r}")
