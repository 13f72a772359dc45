"""Constrained decoding: a token trie over the step lines applicable now, and a logits processor over it.

The trie holds the token ids of every admissible completion (each applicable ground step with its
true effects, then a terminator). At each decoding position the processor keeps only the tokens that
continue some admissible completion, so the model picks *which* valid step to take but cannot emit
an invalid one. torch/transformers are imported lazily (inside :func:`step_logits_processor`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

_END = -1  # key marking a complete sequence


class TokenTrie:
    """Prefix tree over token-id sequences."""

    def __init__(self, sequences: Iterable[Sequence[int]] = ()) -> None:
        self.root: dict[int, Any] = {}
        self.size = 0
        for seq in sequences:
            self.add(seq)

    def add(self, seq: Sequence[int]) -> None:
        """Insert one sequence."""
        node = self.root
        for tok in seq:
            node = node.setdefault(int(tok), {})
        if _END not in node:
            node[_END] = {}
            self.size += 1

    def next_tokens(self, prefix: Sequence[int]) -> list[int] | None:
        """Tokens that may follow ``prefix`` (``[]`` when it is complete); None when it is no prefix."""
        node = self.root
        for tok in prefix:
            node = node.get(int(tok))
            if node is None:
                return None
        return [t for t in node if t != _END]

    def complete(self, prefix: Sequence[int]) -> bool:
        """True when ``prefix`` is one of the sequences."""
        node = self.root
        for tok in prefix:
            node = node.get(int(tok))
            if node is None:
                return False
        return _END in node


def completion_ids(tokenizer: Any, lines: Sequence[str], terminator: Sequence[int]) -> list[list[int]]:
    """Token ids of each admissible line followed by the terminator (EOS or a newline)."""
    out = []
    for line in lines:
        ids = tokenizer(line, add_special_tokens=False)["input_ids"]
        out.append([*ids, *terminator])
    return out


def step_logits_processor(trie: TokenTrie, prompt_length: int, fallback: int) -> Any:
    """A transformers LogitsProcessor that masks every token leaving the trie (batch size 1)."""
    import torch
    from transformers import LogitsProcessor

    class _TrieProcessor(LogitsProcessor):
        def __call__(self, input_ids: torch.LongTensor, scores: torch.FloatTensor) -> torch.FloatTensor:
            generated = input_ids[0, prompt_length:].tolist()
            allowed = trie.next_tokens(generated)
            if not allowed:  # complete (or off the trie, which masking prevents): force the terminator
                allowed = [fallback]
            mask = torch.full_like(scores, float("-inf"))
            mask[:, allowed] = 0.0
            return scores + mask

    return _TrieProcessor()
