"""One camera's wall band in a container, a patch of a cabinet named as an appliance, a pulled-out drawer
that one camera saw: the ``in`` rules of issue 22's last round (exact synthetic clouds, no rendering)."""

from __future__ import annotations

import dataclasses

import numpy as np
from gsr.perception.geometry import Instance, fit_boxes
from gsr.perception.relations import attached_part, supports
from gsr.perception.track import absorb_fixture_pieces, drop_wall_pieces

from tests.perception.test_containment import PARAMS, PLANE, TH, _inst, open_box, solid, table


def _with(inst: Instance, **label: object) -> Instance:
    out = Instance(inst.key, dataclasses.replace(inst.label, **label), inst.points, inst.rgb, inst.views)
    fit_boxes(out)
    return out


def _box() -> Instance:
    return _with(open_box("box_1", (0.3, -0.1, 0.0), (0.46, 0.06, 0.085), views=3), color="blue")


def test_a_band_of_wall_one_camera_saw_from_floor_to_rim_is_dropped_but_what_stands_in_the_box_is_not():
    box = _box()
    # the inner face of the +x wall from its top down to 3 cm, named cookie_box by one camera
    band = np.array(
        [(0.452, y, z) for y in np.arange(-0.09, 0.0501, 0.005) for z in np.arange(0.03, 0.0851, 0.005)]
    )
    piece = _with(_inst("cookie_box_1", "cookie_box", band), color="blue")
    assert supports([table(), box, piece], PLANE, TH)["cookie_box_1"] == ("in", "box_1")
    cube = solid("cube_1", "cube", (0.36, -0.03, 0.008), (0.39, 0.0, 0.038))  # one camera saw it, in the box
    # against the +x wall, below the rim
    mug = solid("mug_1", "mug", (0.40, -0.06, 0.008), (0.445, -0.015, 0.06))
    out = drop_wall_pieces([table(), box, piece, cube, mug], TH)
    assert [i.key for i in out] == ["table", "box_1", "cube_1", "mug_1"]
    sup = supports(out, PLANE, TH)
    assert sup["cube_1"] == ("in", "box_1") and sup["mug_1"] == ("in", "box_1")
    # as tall as the box but away from its walls (a bottle standing in the middle): kept
    bottle = solid("milk_1", "milk", (0.36, -0.04, 0.008), (0.40, 0.0, 0.085))
    assert len(drop_wall_pieces([table(), box, bottle], TH)) == 3
    # a short strip of wall at the rim (not a wall's height), or the band seen by two cameras: kept
    short = _with(_inst("cube_2", "cube", band[band[:, 2] >= 0.07]), color="blue")
    assert len(drop_wall_pieces([table(), box, short], TH)) == 3
    two = _inst("cookie_box_1", "cookie_box", band, views=2)
    assert len(drop_wall_pieces([table(), box, two], TH)) == 3
    # a labelled mask is never dropped
    labelled = _with(piece, id="cookie_box_1")
    assert len(drop_wall_pieces([table(), box, labelled], TH)) == 3


def test_one_cameras_patch_of_a_cabinet_named_an_appliance_joins_the_cabinet_wherever_it_stands():
    cabinet = solid("cabinet_1", "cabinet", (0.3, -0.2, 0.0), (0.6, 0.15, 0.32), views=3)
    front = cabinet.points[np.abs(cabinet.points[:, 0] - 0.3) < 1e-6]
    # the shaded bottom of the front, down to the table, named microwave; a pull bar 1.5 cm proud of it
    low = front[(front[:, 2] < 0.11) & (front[:, 1] > 0.0) & (front[:, 1] < 0.1)]
    bar = np.array([(0.285, y, 0.09) for y in np.arange(0.02, 0.081, 0.004)])
    patch = _inst("microwave_1", "microwave", np.concatenate([low, bar]))
    # a mug standing against the front on the table, its pixels in the same place: movable, stays
    mug = _inst("mug_1", "mug", low.copy())
    out = absorb_fixture_pieces([table(), cabinet, patch, mug], PARAMS)
    assert sorted(i.key for i in out) == ["cabinet_1", "mug_1", "table"]
    # a microwave standing beside the cabinet on the table is no piece of it
    beside = solid("microwave_2", "microwave", (0.62, -0.1, 0.0), (0.8, 0.1, 0.12))
    assert len(absorb_fixture_pieces([table(), cabinet, beside], PARAMS)) == 3


def _drawer(key: str, lo, hi, views: int) -> Instance:
    return _with(solid(key, "drawer", lo, hi, views=views), parent="cabinet_1")


def test_a_pulled_out_drawer_one_camera_saw_holds_what_several_cameras_saw_in_it():
    cabinet = solid("cabinet_1", "cabinet", (0.3, -0.2, 0.0), (0.6, 0.15, 0.32), views=4)
    # the top drawer pulled out towards -x, seen by the camera facing the front only
    drawer = _drawer("cabinet_1/drawer_1", (0.05, -0.18, 0.23), (0.3, 0.13, 0.31), views=1)
    cube = solid("cube_1", "cube", (0.15, -0.05, 0.237), (0.18, -0.02, 0.267), views=3)
    assert attached_part(drawer, cabinet)
    assert supports([table(), cabinet, drawer, cube], PLANE, TH)["cube_1"] == ("in", "cabinet_1/drawer_1")
    # a "drawer" one camera saw away from its cabinet (another box's front) holds nothing several saw
    far = _drawer("cabinet_1/drawer_1", (0.05, -0.5, 0.0), (0.25, -0.3, 0.1), views=1)
    on_table = solid("cube_1", "cube", (0.15, -0.42, 0.0), (0.18, -0.39, 0.03), views=3)
    assert not attached_part(far, cabinet)
    assert supports([table(), cabinet, far, on_table], PLANE, TH)["cube_1"] != ("in", "cabinet_1/drawer_1")
    # nor does a one-camera "drawer" inside the drawer, below its top (the cubes in it read as a drawer)
    outer = _drawer("cabinet_1/drawer_2", (0.05, -0.18, 0.23), (0.3, 0.13, 0.31), views=3)
    inner = _drawer("cabinet_1/drawer_3", (0.12, -0.08, 0.237), (0.2, 0.0, 0.269), views=1)
    sup = supports([table(), cabinet, outer, inner, cube], PLANE, TH)
    assert sup["cube_1"] == ("in", "cabinet_1/drawer_2")


def test_box_contains_share_measures_the_inner_box_inside_the_outer_one_grown_by_the_margin():
    from gsr.perception.geometry import box_contains_share

    outer = solid("box_1", "box", (0.0, 0.0, 0.0), (0.1, 0.1, 0.1))
    inside = solid("cube_1", "cube", (0.02, 0.02, 0.0), (0.06, 0.06, 0.04))
    half_out = solid("cube_2", "cube", (0.08, 0.02, 0.0), (0.12, 0.06, 0.04))  # half of x beyond the wall
    assert box_contains_share(inside, outer) == 1.0
    assert abs(box_contains_share(half_out, outer) - 0.5) < 1e-9
    assert abs(box_contains_share(half_out, outer, 0.01) - 0.75) < 1e-9  # the wall moved out by 1 cm
    assert box_contains_share(outer, inside) < 0.2  # not symmetric: the share of the inner box's volume
