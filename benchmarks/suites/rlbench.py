"""RLBench-style suite: 100 tasks in 5 categories, named after RLBench task families, on our domain.

Only the names and ideas come from RLBench (its code is not openly licensed); every scene, instruction
and goal here is our own definition on the tabletop domain (data/domains/tabletop.pddl). Tasks are
generated deterministically from a seed: each family has a fixed number of variations (which object,
colour, drawer, how many blocks, initial states, distractors), and the seed picks the details.
"""

from __future__ import annotations

import random
from collections.abc import Callable

from gsr.benchmarks.suites.builder import SceneBuilder
from gsr.benchmarks.suites.rlbench_families import (
    close_box,
    close_drawer,
    close_microwave,
    empty_container,
    lamp_off,
    lamp_on,
    open_box,
    open_drawer,
    open_microwave,
    pick_up_cup,
    place_items_in_tray,
    press_switch_stove,
    push_button,
    put_books_on_bookshelf,
    put_groceries_in_cupboard,
    put_item_in_box,
    put_item_in_box_with_lid,
    put_item_in_drawer,
    put_item_in_microwave,
    put_item_on_plate,
    put_plate_in_rack,
    put_pot_on_stove,
    put_rubbish_in_bin,
    reverse_tower,
    sort_blocks_into_towers,
    stack_blocks,
    stack_blocks_on_plate,
    stack_cups,
    take_item_out_of_drawer,
    take_item_out_of_microwave,
    turn_off_stove,
    turn_on_devices,
    turn_tap,
    unstack_blocks,
)

from gsr.task_spec import TaskSpec, task_from_dict

SUITE = "rlbench"
CATEGORIES = (
    "Kitchen Operations",
    "Pick and Place",
    "Switch operations for Containers",
    "Controller Operations",
    "Stacking and Assembly",
)
Family = Callable[[random.Random, int, SceneBuilder], tuple[str, str]]


FAMILIES: dict[str, list[tuple[str, Family, int]]] = {
    "Kitchen Operations": [
        ("open_microwave", open_microwave, 2),
        ("close_microwave", close_microwave, 2),
        ("put_item_in_microwave", put_item_in_microwave, 4),
        ("take_item_out_of_microwave", take_item_out_of_microwave, 2),
        ("put_pot_on_stove", put_pot_on_stove, 4),
        ("put_plate_in_rack", put_plate_in_rack, 2),
        ("put_groceries_in_cupboard", put_groceries_in_cupboard, 2),
        ("turn_off_stove", turn_off_stove, 2),
    ],
    "Pick and Place": [
        ("pick_up_cup", pick_up_cup, 3),
        ("put_item_on_plate", put_item_on_plate, 3),
        ("put_rubbish_in_bin", put_rubbish_in_bin, 3),
        ("put_books_on_bookshelf", put_books_on_bookshelf, 3),
        ("place_items_in_tray", place_items_in_tray, 3),
        ("empty_container", empty_container, 3),
        ("put_item_in_box", put_item_in_box, 2),
    ],
    "Switch operations for Containers": [
        ("open_drawer", open_drawer, 3),
        ("close_drawer", close_drawer, 3),
        ("put_item_in_drawer", put_item_in_drawer, 4),
        ("take_item_out_of_drawer", take_item_out_of_drawer, 3),
        ("open_box", open_box, 2),
        ("close_box", close_box, 2),
        ("put_item_in_box_with_lid", put_item_in_box_with_lid, 3),
    ],
    "Controller Operations": [
        ("turn_tap", turn_tap, 5),
        ("lamp_on", lamp_on, 3),
        ("lamp_off", lamp_off, 3),
        ("push_button", push_button, 3),
        ("press_switch", press_switch_stove, 3),
        ("turn_on_devices", turn_on_devices, 3),
    ],
    "Stacking and Assembly": [
        ("stack_blocks", stack_blocks, 6),
        ("stack_cups", stack_cups, 4),
        ("unstack_blocks", unstack_blocks, 3),
        ("reverse_tower", reverse_tower, 3),
        ("stack_blocks_on_plate", stack_blocks_on_plate, 2),
        ("sort_blocks_into_towers", sort_blocks_into_towers, 2),
    ],
}


def generate_rlbench(seed: int = 0) -> list[TaskSpec]:
    """The 100 RLBench-style tasks (20 per category), deterministic for a seed."""
    tasks = []
    for category, families in FAMILIES.items():
        for family, fn, variations in families:
            for v in range(variations):
                task_seed = random.Random(f"{seed}:{family}:{v}").randrange(2**31)
                rng = random.Random(task_seed)
                b = SceneBuilder(seed=task_seed)
                instruction, goal = fn(rng, v, b)
                data = {
                    "id": f"rlbench_{family}_v{v}",
                    "suite": SUITE,
                    "category": category,
                    "level": family,
                    "instructions": [instruction],
                    "initial": b.graph(),
                    "layout": b.layout(),
                    "goal": goal,
                    "metadata": {"family": family, "variation": v, "seed": seed},
                }
                tasks.append(task_from_dict(data, source=f"rlbench {family} v{v}"))
    return tasks
