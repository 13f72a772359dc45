"""Supervised fine-tuning on generated data in the reasoner's prompt/step format (``gsr train``).

``train(TrainConfig(data, "tiny" | checkpoint, out))`` writes a folder that
``--backend transformers:DIR`` loads. torch/transformers are imported only when training runs.
"""

from __future__ import annotations

from gsr.lazy import lazy_exports

#: public name -> defining module; a name loads its module on first use, so importing a submodule
#: of gsr.train does not load the whole package
_EXPORTS = {
    "DEFAULT_TYPES": "gsr.train.format",
    "Example": "gsr.train.format",
    "row_example": "gsr.train.format",
    "train": "gsr.train.sft",
    "TrainConfig": "gsr.train.sft",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports("gsr.train", _EXPORTS, globals())
