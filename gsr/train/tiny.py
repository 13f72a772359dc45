"""The ``tiny`` model: a byte-level BPE tokenizer trained on the data and a small Llama from scratch.

Small enough to train on a 2-core CPU in minutes, yet a real ``LlamaForCausalLM`` with a
``PreTrainedTokenizerFast``: ``save_pretrained`` gives a folder that ``AutoModelForCausalLM`` /
``AutoTokenizer`` load, which is what ``--backend transformers:DIR`` needs.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

EOS = "<|endoftext|>"
PAD = "<|pad|>"


@dataclass(frozen=True)
class TinySpec:
    """Size of the tiny model (defaults: ~1.7M parameters, 640-token context)."""

    vocab_size: int = 2048
    hidden: int = 192
    layers: int = 3
    heads: int = 4
    intermediate: int = 512
    context: int = 640


# Models trained from scratch, by name (``--model NAME``). ``tiny`` fits a 2-core CPU in minutes;
# ``small`` (~12M parameters, 2,048-token context: the whole scene of ~85% of prompts) is sized for
# one GPU for a few minutes and still runs inference on a CPU.
SCRATCH_SPECS: dict[str, TinySpec] = {
    "tiny": TinySpec(),
    "small": TinySpec(vocab_size=4096, hidden=384, layers=6, heads=6, intermediate=1024, context=2048),
}
# Texts the tokenizer is fitted on at most: BPE merges converge long before, and it keeps prep fast.
TOKENIZER_TEXTS = 20000


def train_tokenizer(texts: Iterable[str], vocab_size: int) -> Any:
    """A byte-level BPE tokenizer fitted to ``texts`` (never an unknown token), as PreTrainedTokenizerFast."""
    from tokenizers import Tokenizer, decoders, models, pre_tokenizers, trainers
    from transformers import PreTrainedTokenizerFast

    tok = Tokenizer(models.BPE())
    tok.pre_tokenizer = pre_tokenizers.ByteLevel(add_prefix_space=False)
    tok.decoder = decoders.ByteLevel()
    trainer = trainers.BpeTrainer(
        vocab_size=vocab_size,
        special_tokens=[EOS, PAD],
        initial_alphabet=pre_tokenizers.ByteLevel.alphabet(),
        show_progress=False,
    )
    tok.train_from_iterator(texts, trainer)
    return PreTrainedTokenizerFast(
        tokenizer_object=tok, eos_token=EOS, bos_token=EOS, pad_token=PAD, clean_up_tokenization_spaces=False
    )


def tiny_model(tokenizer: Any, spec: TinySpec, seed: int) -> Any:
    """A freshly initialised LlamaForCausalLM sized by ``spec`` (deterministic for a seed); any spec with
    ``hidden``, ``intermediate``, ``layers``, ``heads`` and ``context`` will do (the compact models use it)."""
    import torch
    from transformers import LlamaConfig, LlamaForCausalLM

    config = LlamaConfig(
        vocab_size=len(tokenizer),
        hidden_size=spec.hidden,
        intermediate_size=spec.intermediate,
        num_hidden_layers=spec.layers,
        num_attention_heads=spec.heads,
        num_key_value_heads=spec.heads,
        max_position_embeddings=spec.context,
        rms_norm_eps=1e-5,
        tie_word_embeddings=True,
        bos_token_id=tokenizer.eos_token_id,
        eos_token_id=tokenizer.eos_token_id,
        pad_token_id=tokenizer.pad_token_id,
    )
    torch.manual_seed(seed)
    return LlamaForCausalLM(config)
