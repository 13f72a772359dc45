"""The PRS station importer and its calibration, on a synthetic folder and (when present) PRS's data."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from gsr.benchmarks.delivery.building.prs import load_station
from gsr.benchmarks.delivery.building.prs_calibrate import observations_from_tasks, schedule_agreement
from gsr.benchmarks.delivery.building.prs_files import PrsDataError
from gsr.benchmarks.delivery.building.prs_station import location_key

from tests.benchmarks.delivery.building.prs_synthetic import SCALE, X0, Z0, make_folder


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    return make_folder(tmp_path)


def test_location_keys_match_room_names() -> None:
    assert location_key("Bedroom_0") == location_key("bed room 0")
    assert location_key("OfficeRoom01") == location_key("office room 1")
    assert location_key("OfficeSpaceRoom") == location_key("office space")
    assert location_key("HallRoom02") != location_key("hall room 3")


def test_rooms_receptacles_and_free_space(folder: Path) -> None:
    st = load_station(folder, None)
    floor = st.floors[0]
    assert floor.tag_offset == 1  # grid values one below their tags, found from the room extents
    assert {r.name for r in st.rooms} == {"kitchen room", "office space", "bed room 0"}
    recs = {(r.name, st.room(r.room).name) for r in st.receptacles}
    assert recs == {("kitchen counter", "kitchen room"), ("desk", "office space"), ("table", "bed room 0")}
    assert not floor.walkable[2, 6] and floor.walkable[5, 5] and floor.walkable[11, 20]
    assert st.room_at(0, (5, 5)).name == "kitchen room" and st.room_at(0, (11, 20)) is None
    assert floor.transform is None  # uncalibrated without observations


def test_calibration_recovers_transform_and_codes(folder: Path) -> None:
    st = load_station(folder)  # calibrates from the folder's delivery_tasks_dev.json
    t = st.floors[0].transform
    assert t is not None
    # inclusion in room extents bounds the transform, not pins it: within 10 % / 1 m on three rooms
    assert t.scale == pytest.approx(SCALE, rel=0.1)
    assert t.x0 == pytest.approx(X0, abs=1.0) and t.z0 == pytest.approx(Z0, abs=1.0)
    assert st.room_of_location("F1_Bedroom_5").name == "bed room 0"  # re-assigned by position
    hits, total = schedule_agreement(st, observations_from_tasks(st, folder / "delivery_tasks_dev.json"))
    assert hits / total >= 0.95


def test_malformed_files_name_file_and_field(folder: Path) -> None:
    good = (folder / "map_room_data.json").read_text()
    rooms = json.loads(good)
    rooms["0"]["room1"]["x"] = [10, 1]
    (folder / "map_room_data.json").write_text(json.dumps(rooms))
    with pytest.raises(PrsDataError, match=r"map_room_data.json: .*room1.x: expected \[lo, hi\]"):
        load_station(folder, None)
    (folder / "npc_schedule.json").write_text("{bad json")
    (folder / "map_room_data.json").write_text(good)
    with pytest.raises(PrsDataError, match=r"npc_schedule.json: bad JSON at line 1"):
        load_station(folder, None)
    (folder / "semantic_map_0.txt").write_text("1\t2\n1\tx\n")
    with pytest.raises(PrsDataError, match=r"semantic_map_0.txt: row 1: non-integer"):
        load_station(folder, None)


def test_prs_dev_person_positions_fall_in_scheduled_rooms(shared_data: Path) -> None:
    data = shared_data / "prs"
    if not (data / "delivery_tasks_dev.json").is_file():
        pytest.skip(f"PRS data not found at {data}")
    st = load_station(data)
    obs = observations_from_tasks(st, data / "delivery_tasks_dev.json")
    hits, total = schedule_agreement(st, obs)
    assert total == 324 and hits / total >= 0.95
    # held-out check: calibrate on one half, measure on the other
    from gsr.benchmarks.delivery.building.prs_calibrate import calibrate_station

    half = load_station(data, None)
    calibrate_station(half, obs[::2])
    h, n = schedule_agreement(half, obs[1::2])
    assert h / n >= 0.9


def test_station_scene_graph(folder: Path) -> None:
    from gsr.benchmarks.delivery.building.prs_graph import room_adjacency, station_graph

    st = load_station(folder)
    g = station_graph(
        st, objects=[{"id": "RedApple_1", "category": "RedApple", "receptacle": "F0.rec0", "room": "F0.room0"}],
        people_rooms={1: "F0.room1"},
    )  # fmt: skip
    ids = {n.id for n in g.nodes}  # scene-graph ids are lower case
    assert {"station", "floor_0", "f0.room0", "f0.corridor1", "person_1", "redapple_1"} <= ids
    rels = {(e.source, e.relation, e.target) for e in g.edges}
    assert ("f0.room0", "adjacent", "f0.corridor1") in rels and ("redapple_1", "on", "f0.rec0") in rels
    assert ("F0.room0", "F0.room1") not in room_adjacency(st)  # a wall between them, no doorway
    kitchen = next(n for n in g.nodes if n.id == "f0.room0")
    assert kitchen.bbox is not None and kitchen.bbox.min.x == pytest.approx(-5 + 0.3 * 0.5, abs=1.0)


def test_objects_placed_by_geometry(folder: Path) -> None:
    from gsr.benchmarks.delivery.building.prs_station import place_object

    from tests.benchmarks.delivery.building.prs_synthetic import world

    st = load_station(folder)
    x, z = world(2, 6)
    apple = place_object(st, "RedApple_1", "RedApple", (x, 0.9, z))
    assert apple.floor == 0 and st.room(apple.room).name == "kitchen room"
    assert next(r.name for r in st.receptacles if r.id == apple.receptacle) == "kitchen counter"
    x, z = world(5, 14)  # middle of the kitchen floor, no furniture within two cells
    assert place_object(st, "Cup_9", "Cup", (x, 0.0, z)).receptacle is None


def test_register_shift_recovers_a_moved_outline() -> None:
    import numpy as np
    from gsr.benchmarks.delivery.building.prs_calibrate import register_shift

    rng = np.random.default_rng(3)
    ref = np.zeros((60, 80), dtype=bool)
    ref[5:50, 8:70] = True
    ref[20:30, 30:60] = False  # a courtyard
    ref &= rng.random(ref.shape) > 0.05  # furniture
    moved = np.zeros_like(ref)
    moved[0:57, 0:76] = ref[3:60, 4:80]  # cell (i, j) of moved is (i + 3, j + 4) of ref
    di, dj, iou = register_shift(moved, ref, max_shift=10)
    assert (di, dj) == (3, 4) and iou > 0.9
    other = np.zeros_like(ref)
    other[30:58, 2:30] = True  # a different building
    assert register_shift(other, ref, max_shift=10)[2] < 0.75


def test_prs_floors_without_observations_register_from_the_maps(shared_data: Path) -> None:
    """Floors 0 and 1 have no dev task: floor 1 takes floor 2's transform through the maps' overlay (its
    outline matches floor 2's at shift (0, 0)), with PRS's floor height; floor 0's basement outline matches
    no calibrated floor and stays uncalibrated, with the reason."""
    data = shared_data / "prs"
    if not (data / "delivery_tasks_dev.json").is_file():
        pytest.skip(f"PRS data not found at {data}")
    st = load_station(data)
    reg = st.calibration["registered"]
    f1, f2 = st.floors[1].transform, st.floors[2].transform
    assert f1 is not None and f2 is not None and reg[1]["shift"] == [0, 0] and reg[1]["iou"] >= 0.75
    assert (f1.x0, f1.z0, f1.scale) == (f2.x0, f2.z0, f2.scale) and f1.height < f2.height - 3
    assert st.floors[0].transform is None and "IoU" in reg[0]["uncalibrated"]
    assert st.locate(f2.x0 + 50 * f2.scale, -5.2, f2.z0 + 60 * f2.scale) == (1, (50, 60))
    assert st.locate(0.0, -16.7, 0.0) is None  # below every calibrated floor: no floor, not floor 1
