"""Plans in GSR-Bench's action language: pick+place become one move; open/close pass through."""

from __future__ import annotations

import pytest

from gsr.errors import GSRError
from gsr.gsr_bench_format import gsr_bench_commands
from gsr.plan_format import parse_plan


def _steps(text: str):
    return parse_plan(text).steps


def test_moves_opens_and_closes() -> None:
    plan = _steps(
        "(open short_cabinet/drawer_low)\n(pick red_cube1 table)\n(place_in red_cube1 short_cabinet/drawer_low)\n"
        "(close short_cabinet/drawer_low)\n(pick blue_cube1 table)\n(place_on blue_cube1 red_box)\n"
        "(pick a_block table)\n(stack a_block b_block)"
    )
    assert gsr_bench_commands(plan) == [
        "open short_cabinet/drawer_low",
        "move red_cube1 in short_cabinet/drawer_low",
        "close short_cabinet/drawer_low",
        "move blue_cube1 on red_box",
        "move a_block on b_block",
    ]


@pytest.mark.parametrize(
    "text",
    [
        "(turn_on stove_1)",  # no such GSR-Bench action
        "(pick red_cube1 table)",  # never placed
        "(pick red_cube1 table)\n(place_in blue_cube1 red_box)",  # places another object
        "(pick red_cube1 table)\n(open red_box)",  # opening with a full hand is not one GSR-Bench command
    ],
)
def test_inexpressible_plans_are_refused(text: str) -> None:
    with pytest.raises(GSRError):
        gsr_bench_commands(_steps(text))
