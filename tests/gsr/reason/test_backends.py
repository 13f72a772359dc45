"""The backend registry (gsr.reason.backends): specs to backends, a kind added by register_backend."""

from __future__ import annotations

import pytest

from gsr.errors import GSRError
from gsr.reason import FunctionBackend, make_backend, register_backend, solve
from gsr.reason.backends import BACKENDS
from gsr.reason.grounder_backend import GrounderBackend


def test_specs_name_the_built_in_backends() -> None:
    backend = make_backend("grounder", timeout=5.0)
    assert isinstance(backend, GrounderBackend) and backend.timeout == 5.0
    with pytest.raises(GSRError, match="the grounder backend takes no argument"):
        make_backend("grounder:x")
    with pytest.raises(GSRError, match="transformers:PATH"):
        make_backend("transformers")
    with pytest.raises(GSRError, match="openai:MODEL"):
        make_backend("openai:")
    with pytest.raises(
        GSRError, match=r"unknown backend 'gpt4': use grounder, transformers:PATH, openai:MODEL"
    ):
        make_backend("gpt4")


def test_a_registered_kind_builds_backends_for_its_specs(
    monkeypatch: pytest.MonkeyPatch, graph, domain, box_goal
) -> None:
    monkeypatch.setattr("gsr.reason.backends.BACKENDS", dict(BACKENDS))
    built: list[tuple[str, dict]] = []

    def scripted(arg: str, **options: object) -> FunctionBackend:
        built.append((arg, options))
        return FunctionBackend(lambda text: "(done)", name=f"scripted:{arg}")

    register_backend("scripted", scripted)
    backend = make_backend("scripted:a:b", temperature=0)
    assert backend.name == "scripted:a:b" and built == [("a:b", {"temperature": 0})]
    # a spec string given to solve goes through the same registry
    result = solve(graph, "x", "scripted:z", goal=box_goal, domain=domain)
    assert built[-1] == ("z", {}) and result.status != "solved"  # it answered (done) too early
    with pytest.raises(GSRError, match="without ':'"):
        register_backend("a:b", scripted)
