"""RLBench-style task families: each builds a scene (variation ``v``) and returns (instruction, goal).

Our own definitions on the tabletop domain, named after RLBench task families (see rlbench.py).
"""

from __future__ import annotations

import random

from gsr.benchmarks.suites.builder import TABLE, SceneBuilder

COLORS = ("red", "blue", "green", "yellow", "purple", "orange")
FOODS = ("milk", "butter", "ketchup", "popcorn", "cream_cheese", "tomato_sauce")


def _distract(b: SceneBuilder, rng: random.Random, n: int = 2) -> None:
    """Distractor objects on the table (never named by the goal)."""
    for i in range(n):
        kind = rng.choice(("cube", "mug", "bowl", "book"))
        b.add(f"{rng.choice(COLORS)}_{kind}_d{i}", kind, color=rng.choice(COLORS))


def _w(word: str) -> str:
    return word.replace("_", " ")


def _listing(items: list[str]) -> str:
    """``the milk, the butter and the popcorn``."""
    words = [f"the {_w(i)}" for i in items]
    return words[0] if len(words) == 1 else f"{', '.join(words[:-1])} and {words[-1]}"


# ----------------------------------------------------------------- Kitchen Operations
def open_microwave(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("microwave", "microwave", states=("closed", "off"))
    _distract(b, rng, v + 1)
    return "open the microwave", "(open microwave)"


def close_microwave(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("microwave", "microwave", states=("open", "off"))
    if v:
        b.add("plate", "plate", inside="microwave")
    _distract(b, rng)
    return "close the microwave", "(not (open microwave))"


def put_item_in_microwave(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("microwave", "microwave", states=("closed", "off"))
    food = FOODS[v % len(FOODS)]
    b.add(food, food)
    _distract(b, rng)
    if v >= 2:
        return (
            f"put the {_w(food)} in the microwave and close it",
            f"(and (in {food} microwave) (not (open microwave)))",
        )
    return f"put the {_w(food)} in the microwave", f"(in {food} microwave)"


def take_item_out_of_microwave(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("microwave", "microwave", states=("closed", "off"))
    food = rng.choice(FOODS)
    b.add(food, food, inside="microwave")
    b.add("plate", "plate")
    return f"take the {_w(food)} out of the microwave and put it on the plate", f"(on {food} plate)"


def put_pot_on_stove(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("stove", "stove", states=("off",))
    b.add("moka_pot", "moka_pot")
    _distract(b, rng)
    if v % 2:
        return "put the moka pot on the stove and turn it on", "(and (on moka_pot stove) (turned_on stove))"
    return "put the moka pot on the stove", "(on moka_pot stove)"


def put_plate_in_rack(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("dish_rack", "rack")
    color = rng.choice(COLORS)
    b.add(f"{color}_plate", "plate", color=color)
    b.add(
        f"{COLORS[(COLORS.index(color) + 1) % 6]}_plate", "plate", color=COLORS[(COLORS.index(color) + 1) % 6]
    )
    return f"put the {color} plate on the dish rack", f"(on {color}_plate dish_rack)"


def put_groceries_in_cupboard(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("cupboard", "cabinet", movable=False)
    b.add("cupboard/interior", "cabinet_interior", parent="cupboard")
    items = rng.sample(FOODS, 2 + v)
    for f in items:
        b.add(f, f)
    goal = " ".join(f"(in {f} cupboard/interior)" for f in items)
    return f"put {_listing(items)} in the cupboard", f"(and {goal})"


def turn_off_stove(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("stove", "stove", states=("on",))
    if v:
        b.add("pan", "pan", on="stove")
    return "turn off the stove", "(not (turned_on stove))"


# ----------------------------------------------------------------- Pick and Place
def pick_up_cup(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    colors = rng.sample(COLORS, 3)
    for c in colors:
        b.add(f"{c}_cup", "cup", color=c)
    return f"pick up the {colors[v % 3]} cup", f"(holding {colors[v % 3]}_cup)"


def put_item_on_plate(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("plate", "plate")
    kind = ("block", "bowl", "cookie_box")[v % 3]
    color = rng.choice(COLORS)
    b.add(f"{color}_{kind}", kind, color=color)
    _distract(b, rng)
    return f"put the {color} {_w(kind)} on the plate", f"(on {color}_{kind} plate)"


def put_rubbish_in_bin(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("bin", "basket")
    n = v + 1
    for i in range(n):
        b.add(f"rubbish_{i + 1}", "thing")
    b.add("apple", "thing")
    goal = " ".join(f"(in rubbish_{i + 1} bin)" for i in range(n))
    return "put the rubbish in the bin", f"(and {goal})"


def put_books_on_bookshelf(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("bookshelf", "shelf", movable=False)
    colors = rng.sample(COLORS, v + 1)
    for c in colors:
        b.add(f"{c}_book", "book", color=c)
    goal = " ".join(f"(on {c}_book bookshelf)" for c in colors)
    return "put the books on the bookshelf", f"(and {goal})"


def place_items_in_tray(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("tray", "tray")
    items = rng.sample(FOODS, v + 2)
    for f in items:
        b.add(f, f)
    goal = " ".join(f"(in {f} tray)" for f in items)
    return f"place {_listing(items)} in the tray", f"(and {goal})"


def empty_container(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("basket", "basket")
    b.add("tray", "tray")
    items = rng.sample(FOODS, v + 2)
    for f in items:
        b.add(f, f, inside="basket")
    goal = " ".join(f"(in {f} tray)" for f in items)
    return "empty the basket into the tray", f"(and {goal})"


def put_item_in_box(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    colors = rng.sample(COLORS, 2)
    for c in colors:
        b.add(f"{c}_box", "box", color=c)
    b.add(f"{colors[1]}_cube", "cube", color=colors[1])
    return (
        f"put the {colors[1]} cube in the {colors[v % 2]} box",
        f"(in {colors[1]}_cube {colors[v % 2]}_box)",
    )


# ----------------------------------------------------------------- Switch operations for Containers
_LEVEL_WORD = ("top", "middle", "bottom")


def open_drawer(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    drawers = b.cabinet()
    _distract(b, rng)
    return f"open the {_LEVEL_WORD[v]} drawer", f"(open {drawers[v]})"


def close_drawer(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    drawers = b.cabinet(open_levels=(2 - v,))
    return f"close the {_LEVEL_WORD[v]} drawer", f"(not (open {drawers[v]}))"


def put_item_in_drawer(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    # variations 2 and 3 start with the top drawer open: lower drawers are reachable only once it is closed
    drawers = b.cabinet(open_levels=(2,) if v >= 2 else ())
    level = (0, 1, 0, 1)[v]
    idx = 2 - level
    color = rng.choice(COLORS)
    b.add(f"{color}_block", "block", color=color)
    _distract(b, rng)
    return (
        f"put the {color} block in the {_LEVEL_WORD[idx]} drawer",
        f"(in {color}_block {drawers[idx]})",
    )


def take_item_out_of_drawer(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    drawers = b.cabinet()
    food = rng.choice(FOODS)
    b.add(food, food, inside=drawers[v])
    return (
        f"take the {_w(food)} out of the {_LEVEL_WORD[v]} drawer and put it on the table",
        f"(on {food} {TABLE})",
    )


def open_box(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("box", "lidded_box", states=("closed",))
    if v:
        b.add("book", "book", on="box")  # something lies on the lid: it must go first
    return "open the box", "(open box)"


def close_box(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("box", "lidded_box", states=("open",))
    if v:
        b.add("red_cube", "cube", color="red", inside="box")
    return "close the box", "(not (open box))"


def put_item_in_box_with_lid(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("box", "lidded_box", states=("closed",))
    color = rng.choice(COLORS)
    b.add(f"{color}_cube", "cube", color=color)
    if v == 2:
        b.add("plate", "plate", on="box")
    if v >= 1:
        return (
            f"put the {color} cube in the box and close the lid",
            f"(and (in {color}_cube box) (not (open box)))",
        )
    return f"put the {color} cube in the box", f"(in {color}_cube box)"


# ----------------------------------------------------------------- Controller Operations
def turn_tap(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    on = v >= 3
    b.add("tap", "tap", states=("on" if on else "off",))
    _distract(b, rng, v % 3)
    return ("turn off the tap", "(not (turned_on tap))") if on else ("turn on the tap", "(turned_on tap)")


def lamp_on(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("lamp", "lamp", states=("off",))
    b.add("lamp/switch", "switch", parent="lamp")
    _distract(b, rng, v)
    return "turn the lamp on", "(turned_on lamp)"


def lamp_off(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("lamp", "lamp", states=("on",))
    b.add("lamp/switch", "switch", parent="lamp", states=("on",))
    _distract(b, rng, v)
    return "turn the lamp off", "(not (turned_on lamp))"


def push_button(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    colors = rng.sample(COLORS, 3)
    b.add("panel", "thing", movable=False)
    for c in colors:
        b.add(f"panel/{c}_button", "button", parent="panel", color=c, states=("off",))
    c = colors[v % 3]
    return f"push the {c} button", f"(turned_on panel/{c}_button)"


def press_switch_stove(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("stove", "stove", states=("off",))
    b.add("stove/switch", "switch", parent="stove", states=("off",))
    if v:
        b.add("pan", "pan")
        return "put the pan on the stove and switch the stove on", "(and (on pan stove) (turned_on stove))"
    return "switch on the stove", "(turned_on stove)"


def turn_on_devices(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("lamp", "lamp", states=("off",))
    b.add("lamp/switch", "switch", parent="lamp")
    b.add("tap", "tap", states=("on",))
    if v == 2:
        b.add("stove", "stove", states=("off",))
        return "turn on the lamp and the stove and turn off the tap", (
            "(and (turned_on lamp) (turned_on stove) (not (turned_on tap)))"
        )
    return "turn on the lamp and turn off the tap", "(and (turned_on lamp) (not (turned_on tap)))"


# ----------------------------------------------------------------- Stacking and Assembly
def stack_blocks(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    n = 2 + v % 3
    colors = rng.sample(COLORS, n + 1)
    for c in colors:
        b.add(f"{c}_block", "block", color=c)
    tower = colors[:n]
    goal = " ".join(f"(on {a}_block {b_}_block)" for a, b_ in zip(tower[1:], tower[:-1], strict=True))
    phrase = " and ".join(
        f"the {a} block on the {b_} block" for a, b_ in zip(tower[1:], tower[:-1], strict=True)
    )
    return f"stack {phrase}", f"(and {goal})"


def stack_cups(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    n = 2 + v % 2
    colors = rng.sample(COLORS, n)
    for c in colors:
        b.add(f"{c}_cup", "cup", color=c)
    goal = " ".join(f"(on {a}_cup {colors[0]}_cup)" for a in colors[1:2]) + " ".join(
        f" (on {colors[i + 1]}_cup {colors[i]}_cup)" for i in range(1, n - 1)
    )
    return f"stack the cups on the {colors[0]} cup", f"(and {goal})"


def unstack_blocks(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    n = 2 + v
    colors = rng.sample(COLORS, n)
    below = TABLE
    for c in colors:
        b.add(f"{c}_block", "block", color=c, on=below)
        below = f"{c}_block"
    goal = " ".join(f"(on {c}_block {TABLE})" for c in colors)
    return "unstack the blocks onto the table", f"(and {goal})"


def reverse_tower(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    n = 2 + v
    colors = rng.sample(COLORS, n)
    below = TABLE
    for c in colors:
        b.add(f"{c}_block", "block", color=c, on=below)
        below = f"{c}_block"
    rev = colors[::-1]
    goal = " ".join(f"(on {a}_block {c}_block)" for a, c in zip(rev[1:], rev[:-1], strict=True))
    return "rebuild the tower upside down", f"(and {goal})"


def stack_blocks_on_plate(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    b.add("plate", "plate")
    colors = rng.sample(COLORS, 2 + v)
    for c in colors:
        b.add(f"{c}_block", "block", color=c)
    parts = [f"(on {colors[0]}_block plate)"] + [
        f"(on {colors[i + 1]}_block {colors[i]}_block)" for i in range(len(colors) - 1)
    ]
    return (
        f"build a tower of the blocks on the plate starting with the {colors[0]} one",
        f"(and {' '.join(parts)})",
    )


def sort_blocks_into_towers(rng: random.Random, v: int, b: SceneBuilder) -> tuple[str, str]:
    c1, c2 = rng.sample(COLORS, 2)
    for c in (c1, c2):
        for i in range(2):
            b.add(f"{c}_block{i + 1}", "block", color=c)
    goal = f"(and (on {c1}_block2 {c1}_block1) (on {c2}_block2 {c2}_block1))"
    return f"make one tower of the {c1} blocks and one of the {c2} blocks", goal
