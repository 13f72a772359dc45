"""The object catalog: size, agreement with the category registry, clear errors."""

from __future__ import annotations

import json

import pytest

from gsr.categories import affordances, is_category
from gsr.datagen.catalog import load_catalog
from gsr.errors import GSRError


def test_catalog_has_sixty_types_with_registered_categories() -> None:
    catalog = load_catalog()
    assert len(catalog.objects) >= 60
    roles = {o.role for o in catalog.objects}
    assert roles == {"fixture", "container", "supporter", "item"}
    for o in catalog.objects:
        assert is_category(o.category), o.name
        assert o.colors and len(o.size) == 3 and all(s > 0 for s in o.size)
    articulated = [o for o in catalog.objects if o.parts]
    assert any(p.category == "drawer" and p.level is not None for o in articulated for p in o.parts)
    assert sum(1 for o in catalog.objects if o.keypoints) >= 60


def test_catalog_affordances_match_registry() -> None:
    for o in load_catalog().objects:
        want = set(affordances(o.category))
        if o.role == "fixture":
            want -= {"movable", "pushable"}
        assert set(o.affordances) == want, o.name


def _write(tmp_path, objects):
    path = tmp_path / "catalog.json"
    path.write_text(json.dumps({"version": 1, "objects": objects}))
    return path


def test_bad_catalog_entries_are_named(tmp_path) -> None:
    good = {
        "name": "mug",
        "category": "mug",
        "role": "item",
        "colors": ["red"],
        "size": [0.1, 0.1, 0.1],
        "material": "ceramic",
        "affordances": ["movable"],
    }
    with pytest.raises(GSRError, match=r"objects.0 \(mug\): affordances"):
        load_catalog(_write(tmp_path, [good]))
    bad_color = {**good, "colors": ["mauve"], "affordances": sorted(affordances("mug"))}
    with pytest.raises(GSRError, match=r"objects\.0\.colors"):
        load_catalog(_write(tmp_path, [bad_color]))
    unknown = {**good, "category": "spaceship", "name": "x", "affordances": []}
    with pytest.raises(GSRError, match=r"not in gsr\.categories"):
        load_catalog(_write(tmp_path, [unknown]))
    (tmp_path / "broken.json").write_text("{")
    with pytest.raises(GSRError, match=r"broken\.json:1:2: invalid JSON"):
        load_catalog(tmp_path / "broken.json")
