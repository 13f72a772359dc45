"""The transformers backend end to end with a tiny random GPT-2 (no downloads), with and without constraints."""

from __future__ import annotations

import pytest

pytest.importorskip("transformers")
pytest.importorskip("tokenizers")

from gsr.reason import BackendError, applicable_steps, build_prompt, format_step, make_backend, solve
from gsr.reason.constrained import TokenTrie

from .tiny_lm import CHAT_TEMPLATE, build_tiny_lm


@pytest.fixture(scope="module")
def model_dir(tmp_path_factory, domain):
    from gsr.gsr_bench_format import graph_from_gsr_bench

    from .conftest import SCENE

    graph = graph_from_gsr_bench(SCENE)
    texts = [build_prompt(graph, domain, "put the red cube in the blue box").text()]
    texts += [format_step(s) for s in applicable_steps(domain, graph)]
    return build_tiny_lm(tmp_path_factory.mktemp("tiny-gpt2"), texts * 3)


def test_random_model_output_is_diagnosed_and_repaired_never_executed(model_dir, graph, domain, box_goal):
    backend = make_backend(f"transformers:{model_dir}", device="cpu", max_new_tokens=24)
    result = solve(graph, "x", backend, goal=box_goal, domain=domain, max_repairs=2, max_steps=3)
    # a random model does not produce a valid step: every answer is rejected with a reason, K+1 tries
    assert result.status == "stuck" and result.steps == []
    assert result.model_calls == 3 and result.rejections == 3
    for attempt in result.unrepaired[0]:
        assert attempt.error or (attempt.diagnosis is not None and not attempt.diagnosis.ok)
    assert "rejected:" in result.transcript[1].prompt.user  # the diagnosis went back to the model


def test_constrained_decoding_only_emits_applicable_steps(model_dir, graph, domain, box_goal):
    backend = make_backend(f"transformers:{model_dir}", device="cpu")
    result = solve(graph, "x", backend, goal=box_goal, domain=domain, constrained=True, max_steps=4)
    assert result.rejections == 0 and len(result.steps) >= 1
    for exchange, step in zip(result.transcript, result.steps, strict=False):
        assert exchange.response.strip() == format_step(step.step)  # one admissible line, with its effects
        assert step.diagnosis.ok and step.source == "model"


def test_chat_template_is_used(tmp_path, graph, domain):
    path = build_tiny_lm(tmp_path / "chat", ["hello world (pick a b)"], chat_template=CHAT_TEMPLATE)
    backend = make_backend(f"transformers:{path}", device="cpu", max_new_tokens=4)
    prompt = build_prompt(graph, domain, "x", examples=())
    text = backend.tokenizer.decode(backend.encode(prompt))
    assert text.startswith("<|system|>\n") and text.endswith("<|assistant|>\n")
    assert isinstance(backend.complete(prompt), str)


def test_bad_model_path(tmp_path):
    with pytest.raises(BackendError, match="cannot load"):
        make_backend(f"transformers:{tmp_path / 'nothing'}")


def test_token_trie():
    trie = TokenTrie([[1, 2, 3], [1, 4], [1, 2, 3]])
    assert trie.size == 2
    assert sorted(trie.next_tokens([1])) == [2, 4]
    assert trie.next_tokens([1, 4]) == [] and trie.complete([1, 4])
    assert trie.next_tokens([9]) is None and not trie.complete([1, 2])


def test_loaded_models_are_reused(model_dir):
    first = make_backend(f"transformers:{model_dir}", device="cpu")
    assert make_backend(f"transformers:{model_dir}", device="cpu") is first
    assert make_backend(f"transformers:{model_dir}", device="cpu", max_new_tokens=8) is not first
