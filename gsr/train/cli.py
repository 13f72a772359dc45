"""``gsr train``: the command behind the thin typer function in gsr/cli.py."""

from __future__ import annotations

from pathlib import Path

from gsr.datagen.schema import SAMPLE_TYPES
from gsr.errors import GSRError
from gsr.train.sft import TrainConfig, train


def train_command(
    data: Path,
    model: str,
    out: Path,
    lora: bool,
    max_steps: int,
    batch_size: int,
    learning_rate: float | None,
    train_rows: int,
    eval_rows: int,
    types: str,
    seed: int,
    time_budget: float | None = None,
) -> int:
    """Validate the options, train, print the metrics (JSON line); exit code 0."""
    if not (data / "data" / "train").is_dir():
        raise GSRError(f"--data {data}: no data/train folder (generate one with gsr datagen)")
    wanted = tuple(t.strip() for t in types.split(",") if t.strip())
    unknown = [t for t in wanted if t not in SAMPLE_TYPES]
    if unknown or not wanted:
        raise GSRError(f"--types: unknown {unknown or types!r}; choose from {', '.join(SAMPLE_TYPES)}")
    if time_budget is not None and time_budget <= 0:
        raise GSRError(f"--time-budget must be positive seconds, got {time_budget}")
    if batch_size < 1 or train_rows < 1 or eval_rows < 0:
        raise GSRError("--batch-size and --train-rows must be >= 1, --eval-rows >= 0")
    cfg = TrainConfig(
        data=data,
        model=model,
        out=out,
        lora=lora,
        max_steps=max_steps,
        batch_size=batch_size,
        learning_rate=learning_rate,
        train_rows=train_rows,
        eval_rows=eval_rows,
        types=wanted,
        seed=seed,
        time_budget=time_budget,
    )
    try:
        train(cfg)  # torch and transformers load inside train
    except ImportError as exc:  # pragma: no cover - depends on the installed extras
        raise GSRError(f"training needs the 'llm' extra (pip install 'gsr[llm]'): {exc}") from None
    return 0
