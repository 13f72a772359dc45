"""Supervised fine-tuning on generated data in the reasoner's prompt/step format (``gsr train``).

``train(TrainConfig(data, "tiny" | checkpoint, out))`` writes a folder that
``--backend transformers:DIR`` loads. torch/transformers are imported only when training runs.
"""

from __future__ import annotations

from gsr.train.format import DEFAULT_TYPES, Example, row_example
from gsr.train.sft import TrainConfig, train

__all__ = ["DEFAULT_TYPES", "Example", "TrainConfig", "row_example", "train"]
