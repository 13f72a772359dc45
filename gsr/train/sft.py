"""Supervised fine-tuning with the transformers Trainer on the reasoner's prompt/step format.

Each example is tokenised as ``prompt + answer + "\\n" + eos`` with the loss on the answer only. The
prompt is left-truncated to the model's context exactly as the transformers backend truncates it at
inference (it keeps the end: the current scene and the question), so training and use see the same
tokens. ``--lora`` trains LoRA adapters (peft) and merges them before saving, so the output folder is
a plain checkpoint that ``AutoModelForCausalLM.from_pretrained`` loads.
"""

from __future__ import annotations

import glob
import json
import math
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from gsr.errors import GSRError
from gsr.resources import load_builtin_domain
from gsr.train.format import DEFAULT_TYPES, Example, read_rows, row_example
from gsr.train.tiny import SCRATCH_SPECS, TOKENIZER_TEXTS, TinySpec, tiny_model, train_tokenizer


@dataclass
class TrainConfig:
    """What to train on, from what, and for how long."""

    data: Path
    model: str  # a from-scratch size ("tiny", "small") or a local checkpoint folder
    out: Path
    lora: bool = False
    max_steps: int = 300
    batch_size: int = 8
    learning_rate: float | None = None  # default: 1e-3 tiny, 2e-4 LoRA, 5e-5 full fine-tuning
    train_rows: int = 20000
    eval_rows: int = 400
    types: tuple[str, ...] = DEFAULT_TYPES
    seed: int = 0
    max_length: int | None = None  # default: the model's context
    time_budget: float | None = None  # stop training after this many seconds (then evaluate and save)
    tiny: TinySpec | None = None  # the from-scratch size; default: SCRATCH_SPECS[model]

    @property
    def scratch(self) -> bool:
        """True when the model is trained from scratch (a SCRATCH_SPECS name), not loaded."""
        return self.model in SCRATCH_SPECS

    @property
    def spec(self) -> TinySpec:
        """The size of a from-scratch model."""
        return self.tiny or SCRATCH_SPECS.get(self.model, SCRATCH_SPECS["tiny"])


def _split_files(data: Path, split: str) -> list[str]:
    files = sorted(glob.glob(str(data / "data" / split / "*.jsonl")))
    return files


def load_examples(cfg: TrainConfig, split: str, limit: int, chat: Any | None = None) -> list[Example]:
    """Text examples of ``split`` (train/val/test) in the reasoner's format."""
    files = _split_files(cfg.data, split)
    if not files and split == "train":
        raise GSRError(f"{cfg.data}: no data/train/*.jsonl files (generate them with gsr datagen)")
    domain = load_builtin_domain()
    out = []
    for row in read_rows(files, cfg.types, limit):
        ex = row_example(row, domain, chat)
        if ex is not None:
            out.append(ex)
    return out


def _tokenise(examples: list[Example], tokenizer: Any, max_length: int) -> list[dict[str, list[int]]]:
    if not examples:
        return []
    eos = tokenizer.eos_token_id
    prompts = tokenizer([e.prompt for e in examples], add_special_tokens=False)["input_ids"]
    answers = tokenizer([e.answer + "\n" for e in examples], add_special_tokens=False)["input_ids"]
    features = []
    for p, a in zip(prompts, answers, strict=True):
        a = [*a, eos]
        if len(a) >= max_length // 2:
            continue  # an answer longer than half the context leaves too little scene to learn from
        p = p[-(max_length - len(a)) :]
        features.append({"input_ids": p + a, "labels": [-100] * len(p) + a})
    return features


class _Collator:
    """Right-pads a batch; padding is masked out of attention and loss."""

    def __init__(self, pad_id: int) -> None:
        self.pad_id = pad_id

    def __call__(self, batch: list[dict[str, list[int]]]) -> dict[str, Any]:
        import torch

        n = max(len(b["input_ids"]) for b in batch)
        ids = [b["input_ids"] + [self.pad_id] * (n - len(b["input_ids"])) for b in batch]
        labels = [b["labels"] + [-100] * (n - len(b["labels"])) for b in batch]
        mask = [[1] * len(b["input_ids"]) + [0] * (n - len(b["input_ids"])) for b in batch]
        return {
            "input_ids": torch.tensor(ids),
            "labels": torch.tensor(labels),
            "attention_mask": torch.tensor(mask),
        }


def _time_budget(seconds: float) -> Any:
    """A Trainer callback that ends training once ``seconds`` of training have passed."""
    from transformers import TrainerCallback

    class _Budget(TrainerCallback):
        def on_train_begin(self, args: Any, state: Any, control: Any, **kwargs: Any) -> None:
            self.start = time.perf_counter()

        def on_step_end(self, args: Any, state: Any, control: Any, **kwargs: Any) -> None:
            if time.perf_counter() - self.start >= seconds:
                control.should_training_stop = True

    return _Budget()


def _scratch_names() -> str:
    return " or ".join(repr(n) for n in SCRATCH_SPECS)


def _length_grouping(gpu: bool) -> dict[str, Any]:
    """On a GPU, batch examples of similar length (prompts run from ~300 to ~2,500 tokens): far less padding.

    Off on the CPU, where batches are small and the recorded CPU runs used random order.
    """
    if not gpu:
        return {}
    from transformers import TrainingArguments

    fields = TrainingArguments.__dataclass_fields__
    if "train_sampling_strategy" in fields:  # transformers >= 5.x
        return {"train_sampling_strategy": "group_by_length"}
    return {"group_by_length": True} if "group_by_length" in fields else {}


def _model_and_tokenizer(cfg: TrainConfig, train_texts: list[Example]) -> tuple[Any, Any]:
    if cfg.scratch:
        # the prompt tails the model will see (about 4 characters per token)
        texts = [e.prompt[-4 * cfg.spec.context :] + e.answer for e in train_texts[:TOKENIZER_TEXTS]]
        tokenizer = train_tokenizer(texts, cfg.spec.vocab_size)
        return tiny_model(tokenizer, cfg.spec, cfg.seed), tokenizer
    from transformers import AutoModelForCausalLM, AutoTokenizer

    path = Path(cfg.model)
    if not path.is_dir():
        raise GSRError(f"--model {cfg.model}: not {_scratch_names()} and not a local checkpoint folder")
    try:
        tokenizer = AutoTokenizer.from_pretrained(path, local_files_only=True)
        model = AutoModelForCausalLM.from_pretrained(path, local_files_only=True)
    except (OSError, ValueError) as exc:
        raise GSRError(f"--model {cfg.model}: cannot load a causal language model: {exc}") from None
    if tokenizer.pad_token_id is None:
        tokenizer.pad_token = tokenizer.eos_token
    return model, tokenizer


def _apply_lora(model: Any) -> Any:
    from peft import LoraConfig, get_peft_model

    names = {n.rsplit(".", 1)[-1] for n, _ in model.named_modules()}
    targets = [
        t
        for t in ("q_proj", "k_proj", "v_proj", "o_proj", "c_attn", "c_proj", "query_key_value")
        if t in names
    ]
    if not targets:
        raise GSRError("--lora: no known attention projection modules in this model")
    config = LoraConfig(r=16, lora_alpha=32, lora_dropout=0.05, target_modules=targets, task_type="CAUSAL_LM")
    return get_peft_model(model, config)


def train(cfg: TrainConfig, log: Any = print) -> dict[str, Any]:
    """Fine-tune (or train ``tiny`` from scratch), save a loadable checkpoint to ``cfg.out``, return metrics."""
    import torch
    from transformers import Trainer, TrainingArguments, set_seed

    if cfg.max_steps < 1:
        raise GSRError(f"--max-steps must be at least 1, got {cfg.max_steps}")
    if not cfg.scratch and not Path(cfg.model).is_dir():
        raise GSRError(f"--model {cfg.model}: not {_scratch_names()} and not a local checkpoint folder")
    if cfg.out.exists() and any(cfg.out.iterdir()):
        raise GSRError(f"{cfg.out} exists and is not empty; choose a new --out")
    set_seed(cfg.seed)
    torch.set_num_threads(max(1, os.cpu_count() or 1))
    start = time.perf_counter()
    probe = None
    if not cfg.scratch:  # a chat model is trained on the chat-template text the backend will send
        from transformers import AutoTokenizer

        try:
            probe = AutoTokenizer.from_pretrained(cfg.model, local_files_only=True)
        except (OSError, ValueError) as exc:
            raise GSRError(f"--model {cfg.model}: cannot load its tokenizer: {exc}") from None
        if not getattr(probe, "chat_template", None):
            probe = None
    train_ex = load_examples(cfg, "train", cfg.train_rows, probe)
    val_ex = load_examples(cfg, "val", cfg.eval_rows, probe)
    if not train_ex:
        raise GSRError(f"{cfg.data}: no training rows of types {', '.join(cfg.types)}")
    model, tokenizer = _model_and_tokenizer(cfg, train_ex)
    limit = getattr(model.config, "max_position_embeddings", None) or 1024
    max_length = min(cfg.max_length or limit, limit)
    train_set = _tokenise(train_ex, tokenizer, max_length)
    val_set = _tokenise(val_ex, tokenizer, max_length)
    prepared = time.perf_counter() - start
    if cfg.lora:
        model = _apply_lora(model)
    lr = cfg.learning_rate or (1e-3 if cfg.scratch else 2e-4 if cfg.lora else 5e-5)
    gpu = torch.cuda.is_available()
    work = cfg.out.with_name(f".{cfg.out.name}.trainer")
    args = TrainingArguments(
        output_dir=str(work),
        max_steps=cfg.max_steps,
        per_device_train_batch_size=cfg.batch_size,
        per_device_eval_batch_size=cfg.batch_size,
        learning_rate=lr,
        lr_scheduler_type="cosine",
        warmup_steps=max(1, cfg.max_steps // 20),
        weight_decay=0.01,
        logging_steps=max(1, min(50, cfg.max_steps // 10)),
        save_strategy="no",
        eval_strategy="no",
        report_to=[],
        seed=cfg.seed,
        use_cpu=not gpu,
        bf16=gpu and torch.cuda.is_bf16_supported(),
        dataloader_num_workers=0,
        disable_tqdm=True,
        **_length_grouping(gpu),
    )
    trainer = Trainer(
        model=model,
        args=args,
        train_dataset=train_set,
        eval_dataset=val_set or None,
        data_collator=_Collator(tokenizer.pad_token_id),
        callbacks=[_time_budget(cfg.time_budget)] if cfg.time_budget else None,
    )
    t0, c0 = time.perf_counter(), time.process_time()
    result = trainer.train()
    train_seconds = time.perf_counter() - t0
    # CPU seconds (all threads) say what the run costs on an unshared machine; wall time depends on load
    metrics: dict[str, Any] = {
        "train_loss": round(result.training_loss, 4),
        "train_seconds": round(train_seconds, 1),
        "train_cpu_seconds": round(time.process_time() - c0, 1),
        "steps": trainer.state.global_step,
        "tokens_per_step_max": cfg.batch_size * max_length,
    }
    if val_set:
        ev = trainer.evaluate()
        metrics["val_loss"] = round(ev["eval_loss"], 4)
        metrics["val_perplexity"] = round(math.exp(min(ev["eval_loss"], 50)), 3)
    if cfg.lora:
        model = trainer.model.merge_and_unload()  # a plain checkpoint: loads without peft
    _save(
        model,
        tokenizer,
        cfg,
        metrics,
        len(train_set),
        len(val_set),
        max_length,
        prepared,
        time.perf_counter() - start,
    )
    import shutil

    shutil.rmtree(work, ignore_errors=True)
    log(json.dumps(metrics))
    return metrics


def _save(model, tokenizer, cfg: TrainConfig, metrics, n_train, n_val, max_length, prepared, total) -> None:
    """Write the checkpoint to a temporary folder, then rename it to ``cfg.out`` (never half-written)."""
    import shutil

    tmp = cfg.out.with_name(f".{cfg.out.name}.tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    model.save_pretrained(tmp)
    tokenizer.save_pretrained(tmp)
    params = sum(p.numel() for p in model.parameters())
    info = {
        "config": {k: (str(v) if isinstance(v, Path) else v) for k, v in asdict(cfg).items()},
        "parameters": params,
        "train_examples": n_train,
        "val_examples": n_val,
        "max_length": max_length,
        "prepare_seconds": round(prepared, 1),
        "total_seconds": round(total, 1),
        "metrics": metrics,
        "format": "gsr.reason prompt/step language (gsr.train.format)",
    }
    (tmp / "gsr_training.json").write_text(json.dumps(info, indent=1))
    if cfg.out.exists():
        cfg.out.rmdir()  # checked empty above
    os.replace(tmp, cfg.out)
