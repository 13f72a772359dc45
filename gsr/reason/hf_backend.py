"""``transformers:PATH``: any local causal language model (a folder with config, weights and tokenizer).

Chat models are prompted through the tokenizer's chat template when it has one; others get the plain
prompt text. Decoding is greedy (deterministic) and stops at the end of the first answer line. With
constrained decoding (the query lists the admissible step lines) a token-trie logits processor keeps
the model on applicable steps. torch and transformers are imported when the backend is built.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

from gsr.reason.backend import BackendError, Query
from gsr.reason.compact import FORMATS, MARKER, CompactError
from gsr.reason.compact_decode import GOAL_ORDERS, CompactAnswerer
from gsr.reason.constrained import TokenTrie, completion_ids, step_logits_processor
from gsr.reason.prompt import Prompt


def compact_answerer(path: str, model: Any, tokenizer: Any, device: str) -> Any:
    """The compact-format answerer when the folder holds a compact model's marker, else None."""
    import json
    from pathlib import Path

    marker = Path(path) / MARKER
    if not marker.is_file():
        return None
    try:
        info = json.loads(marker.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise BackendError(f"{marker}: unreadable compact-format marker: {exc}") from None
    if not isinstance(info, dict) or info.get("format") not in FORMATS:
        found = info.get("format") if isinstance(info, dict) else info
        known = ", ".join(map(repr, FORMATS))
        raise BackendError(f"{marker}: format {found!r} is not one of {known} (retrain the model)")
    window = info.get("goal_window")  # open goal literals the model is shown at most (None: all)
    if window is not None and (not isinstance(window, int) or isinstance(window, bool) or window < 1):
        raise BackendError(f"{marker}: goal_window {window!r} is not a positive integer")
    order = info.get("goal_order", "goal")  # the order open goal literals enter the window in
    if order not in GOAL_ORDERS:
        raise BackendError(f"{marker}: goal_order {order!r} is not one of {', '.join(GOAL_ORDERS)}")
    return CompactAnswerer(model, tokenizer, device, FORMATS[info["format"]], window, order)


class TransformersBackend:
    """A local Hugging Face causal LM, loaded from a path (no downloads: ``local_files_only``)."""

    def __init__(
        self,
        path: str,
        device: str | None = None,
        max_new_tokens: int = 160,
        seed: int = 0,
        use_chat_template: bool | None = None,
        max_prompt_tokens: int | None = None,
    ) -> None:
        try:
            import torch
            from transformers import AutoModelForCausalLM, AutoTokenizer
        except ImportError:
            raise BackendError(
                "the transformers backend needs the 'llm' extra: pip install 'gsr[llm]'"
            ) from None
        self.name = f"transformers:{path}"
        try:
            self.tokenizer = AutoTokenizer.from_pretrained(path, local_files_only=True)
            self.model = AutoModelForCausalLM.from_pretrained(path, local_files_only=True)
        except (OSError, ValueError) as exc:
            raise BackendError(f"{path}: cannot load a causal language model: {exc}") from None
        self.device = device or ("cuda" if torch.cuda.is_available() else "cpu")
        self.model.to(self.device).eval()
        self.max_new_tokens = max_new_tokens
        self.seed = seed
        has_template = bool(getattr(self.tokenizer, "chat_template", None))
        self.use_chat_template = has_template if use_chat_template is None else use_chat_template
        limit = getattr(self.model.config, "max_position_embeddings", None) or getattr(
            self.model.config, "n_positions", None
        )
        self.max_prompt_tokens = max_prompt_tokens or (limit - max_new_tokens if limit else None)
        self.eos = self.tokenizer.eos_token_id
        newline = self.tokenizer("\n", add_special_tokens=False)["input_ids"]
        self.terminator = [self.eos] if self.eos is not None else newline[-1:]
        self.last_seconds = 0.0
        self.compact = compact_answerer(path, self.model, self.tokenizer, self.device)

    def encode(self, prompt: Prompt) -> list[int]:
        """Prompt token ids (chat template when used); left-truncated to fit the model's context."""
        if self.use_chat_template:
            text = self.tokenizer.apply_chat_template(
                prompt.messages(), tokenize=False, add_generation_prompt=True
            )
        else:
            text = prompt.text()
        ids = self.tokenizer(text, add_special_tokens=False)["input_ids"]
        if self.max_prompt_tokens is not None and len(ids) > self.max_prompt_tokens:
            ids = ids[-self.max_prompt_tokens :]  # keep the end: the current scene and the question
        return ids

    def complete(self, prompt: Prompt, stop: Sequence[str] = (), query: Query | None = None) -> str:
        """Greedy decode one answer line (constrained to ``query.allowed`` when given)."""
        import torch
        from transformers import LogitsProcessorList, StoppingCriteria, StoppingCriteriaList

        if self.compact is not None:
            return self._compact_complete(query)
        ids = self.encode(prompt)
        input_ids = torch.tensor([ids], device=self.device)
        start = len(ids)
        tokenizer = self.tokenizer

        class _FirstLine(StoppingCriteria):
            """Stop once the answer has a non-blank line followed by a newline (or a stop string)."""

            def __call__(self, input_ids: Any, scores: Any, **kwargs: Any) -> bool:
                text = tokenizer.decode(input_ids[0, start:], skip_special_tokens=True)
                line_done = "\n" in text.lstrip()
                return line_done or any(s in text for s in stop)

        processors = LogitsProcessorList()
        max_new = self.max_new_tokens
        if query is not None and query.allowed:
            sequences = completion_ids(tokenizer, query.allowed, self.terminator)
            processors.append(step_logits_processor(TokenTrie(sequences), start, self.terminator[0]))
            max_new = max(len(s) for s in sequences)
        torch.manual_seed(self.seed)
        t0 = time.perf_counter()
        with torch.no_grad():
            out = self.model.generate(
                input_ids,
                attention_mask=torch.ones_like(input_ids),
                max_new_tokens=max_new,
                do_sample=False,
                logits_processor=processors,
                stopping_criteria=StoppingCriteriaList([_FirstLine()]),
                pad_token_id=self.eos if self.eos is not None else 0,
            )
        self.last_seconds = time.perf_counter() - t0
        text = tokenizer.decode(out[0, start:], skip_special_tokens=True)
        for s in stop:
            text = text.split(s, 1)[0]
        return text

    def _compact_complete(self, query: Query | None) -> str:
        """Answer with a compact-format model: it reads the structured query, not the prompt text."""
        if query is None or query.kind != "step":
            raise BackendError(
                f"{self.name} is a compact-format step model: it answers step queries only "
                "(give the goal, or let the grounder find it)"
            )
        t0 = time.perf_counter()
        try:
            return self.compact.answer(query)
        except CompactError as exc:
            raise BackendError(f"{self.name}: {exc}") from None
        finally:
            self.last_seconds = time.perf_counter() - t0
