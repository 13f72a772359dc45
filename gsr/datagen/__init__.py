"""Manip-Cognition-style dataset generation: catalog scenes, sampled goals, planned and checked tasks.

``generate_dataset(RunConfig(out, samples, seed))`` writes sharded JSONL (see docs/dataset.md);
``generate_shard(seed, shard, size)`` gives one shard's rows in memory; ``decode(row)`` types a row.
"""

from __future__ import annotations

from gsr.lazy import lazy_exports

#: public name -> defining module; a name loads its module on first use, so importing a submodule
#: of gsr.datagen does not load the whole package
_EXPORTS = {
    "Catalog": "gsr.datagen.catalog",
    "CatalogEntry": "gsr.datagen.catalog",
    "decode": "gsr.datagen.schema",
    "generate_dataset": "gsr.datagen.runner",
    "generate_shard": "gsr.datagen.generate",
    "load_catalog": "gsr.datagen.catalog",
    "RunConfig": "gsr.datagen.runner",
    "SAMPLE_TYPES": "gsr.datagen.schema",
    "SampleRow": "gsr.datagen.schema",
    "SCHEMAS": "gsr.datagen.schema",
    "schemas_json": "gsr.datagen.schema",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports("gsr.datagen", _EXPORTS, globals())
