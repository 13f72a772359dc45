"""Objects standing in an open container whose pixels the detector left in the container's segment
(``gsr.perception.inner``; exact synthetic clouds, no rendering)."""

from __future__ import annotations

import dataclasses

import numpy as np
from gsr.perception.geometry import Instance, fit_boxes
from gsr.perception.inner import objects_in_containers, parts_read_on_objects, pieces_in_closed
from gsr.perception.relations import supports
from gsr.perception.track import along_walls

from tests.perception.test_containment import PLANE, TH, _grid, open_box, solid, table

BLUE = (30, 60, 200)


def _coloured(inst: Instance, rgb=BLUE, **label: object) -> Instance:
    out = Instance(
        inst.key,
        dataclasses.replace(inst.label, **label),
        inst.points,
        np.tile(np.array(rgb, np.uint8), (len(inst.points), 1)),
        inst.views,
    )
    fit_boxes(out)
    return out


def _box_holding(*things: Instance, views: int = 3) -> Instance:
    """A blue open box whose cloud also holds ``things`` (one segment in every view)."""
    box = open_box("box_1", (0.3, -0.1, 0.0), (0.46, 0.06, 0.085), views=views)
    pts = np.concatenate([box.points] + [t.points for t in things])
    merged = Instance("box_1", box.label, pts, np.zeros((len(pts), 3), np.uint8), views)
    return _coloured(merged, color="blue")


def test_a_cube_of_the_boxs_colour_left_in_the_boxs_segment_becomes_an_object_in_the_box():
    cube = solid("x", "cube", (0.35, -0.05, 0.008), (0.40, 0.0, 0.05))
    box = _box_holding(cube)
    n_before = len(box.points)
    out = objects_in_containers([table(), box])
    assert len(out) == 3
    new = out[-1]
    assert new.label.category == "cube" and new.label.color == "blue" and new.label.id is None
    assert new.key == "unknown_1" and new.label.attributes["inferred_from"] == "box_1"
    # the cube's points left the box; its walls and floor stay
    assert len(box.points) + len(new.points) == n_before
    assert along_walls(new, box) == 0.0
    assert supports(out, PLANE, TH)[new.key] == ("in", "box_1")


def test_an_empty_box_a_closed_lid_a_labelled_mask_and_a_one_camera_box_give_nothing():
    assert len(objects_in_containers([table(), _box_holding()])) == 2
    # a lid over the mouth: the rim band is a surface, not wall tops
    lid_xy = _grid(np.array([0.3, -0.1]), np.array([0.46, 0.06])).reshape(-1, 2)
    lid = solid("x", "cube", (0.35, -0.05, 0.008), (0.40, 0.0, 0.05))
    # (with a post from the floor up to the lid, so that only the lid test keeps it out)
    post = solid("x", "cube", (0.36, -0.04, 0.008), (0.39, -0.01, 0.085)).points
    lid.points = np.concatenate([np.column_stack([lid_xy, np.full(len(lid_xy), 0.085)]), post])
    assert len(objects_in_containers([table(), _box_holding(lid)])) == 2
    cube = solid("x", "cube", (0.35, -0.05, 0.008), (0.40, 0.0, 0.05))
    labelled = _coloured(_box_holding(cube), id="blue_box")
    assert len(objects_in_containers([table(), labelled])) == 2
    assert len(objects_in_containers([table(), _box_holding(cube, views=1)])) == 2
    # what another object's cloud already holds is that object, not a new one
    seen = _coloured(solid("cube_1", "cube", (0.35, -0.05, 0.008), (0.40, 0.0, 0.05), views=2))
    assert len(objects_in_containers([table(), _box_holding(cube), seen])) == 3


def test_a_thin_strip_or_a_piece_hanging_from_the_rim_is_no_object():
    # a 1 cm high ledge just above the floor: too flat
    flat = solid("x", "cube", (0.35, -0.05, 0.008), (0.40, 0.0, 0.016))
    assert len(objects_in_containers([table(), _box_holding(flat)])) == 2
    # a piece high in the box, not standing on its floor (a lid's tab leaning in)
    hanging = solid("x", "cube", (0.35, -0.05, 0.06), (0.40, 0.0, 0.08))
    assert len(objects_in_containers([table(), _box_holding(hanging)])) == 2


def test_one_cameras_patch_of_a_closed_boxs_colour_in_it_is_dropped_but_not_another_colour_or_two_views():
    box = _coloured(open_box("lidded_box_1", (0.3, -0.1, 0.0), (0.46, 0.06, 0.12), views=3), color="blue")
    patch = _coloured(solid("cookie_box_1", "cookie_box", (0.35, -0.05, 0.008), (0.40, 0.0, 0.05)))
    book = _coloured(solid("book_1", "book", (0.38, -0.05, 0.008), (0.40, 0.0, 0.05)), rgb=(220, 200, 30))
    insts = [table(), box, patch, book]
    support = {"cookie_box_1": ("in", "lidded_box_1"), "book_1": ("in", "lidded_box_1")}
    closed = frozenset({"lidded_box_1"})
    assert [x.key for x in pieces_in_closed(insts, support, closed)] == ["table", "lidded_box_1", "book_1"]
    # an open box, or the patch seen by two cameras, or a labelled mask: kept
    assert len(pieces_in_closed(insts, support, frozenset())) == 4
    two = _coloured(solid("cookie_box_1", "cookie_box", (0.35, -0.05, 0.008), (0.40, 0.0, 0.05), views=2))
    assert len(pieces_in_closed([table(), box, two, book], support, closed)) == 4
    labelled = _coloured(patch, id="cookie_box_1")
    assert len(pieces_in_closed([table(), box, labelled, book], support, closed)) == 4


def test_one_cameras_drawer_lying_in_a_box_of_its_colour_is_that_box_but_a_pulled_drawer_stays():
    cabinet = solid("cabinet_1", "cabinet", (0.0, 0.2, 0.0), (0.3, 0.5, 0.33), views=4)
    box = _coloured(open_box("lidded_box_1", (0.3, -0.1, 0.0), (0.46, 0.06, 0.12), views=2))
    misread = _coloured(open_box("cabinet_1/drawer_1", (0.301, -0.098, 0.01), (0.459, 0.058, 0.12)))
    misread.label = dataclasses.replace(misread.label, category="drawer", parent="cabinet_1")
    pulled = _coloured(open_box("cabinet_1/drawer_2", (-0.2, 0.22, 0.2), (0.05, 0.48, 0.3)))
    pulled.label = dataclasses.replace(pulled.label, category="drawer", parent="cabinet_1")
    out = parts_read_on_objects([table(), cabinet, box, misread, pulled])
    assert [x.key for x in out] == ["table", "cabinet_1", "lidded_box_1", "cabinet_1/drawer_2"]
    # seen by two cameras, or of another colour: kept
    misread.views = 2
    assert len(parts_read_on_objects([table(), cabinet, box, misread])) == 4
    misread.views = 1
    red = _coloured(misread, rgb=(200, 30, 30))
    assert len(parts_read_on_objects([table(), cabinet, box, red])) == 4
