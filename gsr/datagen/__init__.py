"""Manip-Cognition-style dataset generation: catalog scenes, sampled goals, planned and checked tasks.

``generate_dataset(RunConfig(out, samples, seed))`` writes sharded JSONL (see docs/dataset.md);
``generate_shard(seed, shard, size)`` gives one shard's rows in memory; ``decode(row)`` types a row.
"""

from __future__ import annotations

from gsr.datagen.catalog import Catalog, CatalogEntry, load_catalog
from gsr.datagen.generate import generate_shard
from gsr.datagen.runner import RunConfig, generate_dataset
from gsr.datagen.schema import SAMPLE_TYPES, SCHEMAS, SampleRow, decode, schemas_json

__all__ = [
    "SAMPLE_TYPES",
    "SCHEMAS",
    "Catalog",
    "CatalogEntry",
    "RunConfig",
    "SampleRow",
    "decode",
    "generate_dataset",
    "generate_shard",
    "load_catalog",
    "schemas_json",
]
