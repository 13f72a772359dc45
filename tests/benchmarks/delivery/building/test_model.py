"""Building JSON: bad input is reported with the file and field; writes are atomic."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from gsr.benchmarks.delivery.building.model import load_building, save_building
from gsr.benchmarks.delivery.building.shipped import shipped_building_path

from gsr.errors import GSRError


def _data() -> dict:
    return json.loads(shipped_building_path().read_text(encoding="utf-8"))


def test_unknown_room_reference_is_named(tmp_path: Path) -> None:
    data = _data()
    data["receptacles"][0]["room"] = "ballroom_999"
    p = tmp_path / "b.json"
    p.write_text(json.dumps(data))
    with pytest.raises(GSRError, match=r"b\.json: invalid building: .*ballroom_999"):
        load_building(p)


def test_ragged_grid_is_named(tmp_path: Path) -> None:
    data = _data()
    data["floors"][1]["grid"][4] += "."
    p = tmp_path / "b.json"
    p.write_text(json.dumps(data))
    with pytest.raises(GSRError, match=r"floors\.1\.grid: .*row 4"):
        load_building(p)


def test_broken_json_and_missing_file(tmp_path: Path) -> None:
    p = tmp_path / "b.json"
    p.write_text('{"name": ')
    with pytest.raises(GSRError, match=r"b\.json:1:\d+: invalid JSON"):
        load_building(p)
    with pytest.raises(GSRError, match="no such file"):
        load_building(tmp_path / "missing.json")


def test_routine_gap_rejected(tmp_path: Path) -> None:
    data = _data()
    data["people"][0]["routine"][1]["start"] += 60
    p = tmp_path / "b.json"
    p.write_text(json.dumps(data))
    with pytest.raises(GSRError, match="routine gap"):
        load_building(p)


def test_save_is_atomic(tmp_path: Path, shipped) -> None:
    out = tmp_path / "sub" / "b.json"
    save_building(shipped, out)
    assert load_building(out) == shipped
    assert [p.name for p in out.parent.iterdir()] == ["b.json"]  # no temp file left behind


def test_room_past_the_grid_is_named(tmp_path: Path) -> None:
    data = _data()
    data["rooms"][3]["rect"][3] = 500
    p = tmp_path / "b.json"
    p.write_text(json.dumps(data))
    with pytest.raises(GSRError, match="extends past the floor grid"):
        load_building(p)
