"""The offline PRS environment, agent, metrics and command on a synthetic station; PRS's data when present."""

from __future__ import annotations

import json
from datetime import datetime
from pathlib import Path

import pytest
from gsr.benchmarks.delivery.building.prs import load_station
from gsr.benchmarks.delivery.building.prs_files import PrsDataError
from gsr.benchmarks.delivery.prs_cli import prs_command
from gsr.benchmarks.delivery.prs_env import ActionError, PrsEnv
from gsr.benchmarks.delivery.prs_metrics import aggregate, score_entry
from gsr.benchmarks.delivery.prs_parse import RoomMatcher, label_score, parse_request, split_sentences
from gsr.benchmarks.delivery.prs_run import run_prs
from gsr.benchmarks.delivery.prs_tasks import PrsTruth, inventory, load_tasks

from gsr.errors import GSRError
from tests.benchmarks.delivery.building.prs_synthetic import make_folder


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    return make_folder(tmp_path)


def test_sentences_joined_without_space_split() -> None:
    assert split_sentences("Bring the cup to me.Take the cup to Ann; she wears a hat.") == [
        "Bring the cup to me.",
        "Take the cup to Ann; she wears a hat.",
    ]


def test_lid_colour_binds_to_lid() -> None:
    toks = ["white", "plastic", "bottle", "green", "lid"]
    labels = ["PlasticBottleWithWhiteLid", "PlasticBottleWithGreenLid", "WaterBottleBlue"]
    assert max(labels, key=lambda lab: label_score(lab, toks)) == "PlasticBottleWithGreenLid"
    assert label_score("WaterBottleBlue", ["blue", "water", "bottle"]) > label_score(
        "PlasticBottleWithBlueLid", ["blue", "water", "bottle"]
    )


def test_parse_source_destination_and_own_place(folder: Path) -> None:
    st = load_station(folder)
    p = parse_request(
        "Go to the kitchen and grab the shiny red apple from the counter, then bring it to my bedroom.",
        RoomMatcher(st),
        ["RedApple", "BlueMug"],
    )
    assert "apple" in p.object_tokens and "shiny" in p.object_tokens
    assert [st.room(r).name for r in p.source_rooms] == ["kitchen room"]
    assert [st.room(r).name for r in p.dest_rooms] == ["bed room 0"] and p.own_place == "bed"


def test_agent_delivers_on_synthetic_station(folder: Path) -> None:
    run = run_prs(folder, folder / "delivery_tasks_dev.json")
    s = run["summary"]
    assert s["tasks"] == 40
    assert s["Task SR"] >= 0.9, s["failure_reasons"]
    rec = run["records"][0]
    assert set(rec) >= {
        "grasp",
        "object_found",
        "human_found",
        "deliver",
        "success",
        "sim_minutes",
        "failure_reason",
    }
    sub = run["submission"]["t0"]
    assert set(sub) == {"task_id", "npc_id", "agent_object_name", "agent_position", "start_time", "end_time"}
    assert datetime.fromisoformat(sub["end_time"]) > datetime.fromisoformat(sub["start_time"])


def test_environment_refuses_impossible_actions(folder: Path) -> None:
    st = load_station(folder)
    tasks = load_tasks(folder / "delivery_tasks_dev.json", st)
    env = PrsEnv(st, inventory(st, tasks), tasks[0])
    with pytest.raises(ActionError, match="not been observed"):
        env.grasp("RedApple_1")
    with pytest.raises(ActionError, match="no stairs or elevator"):
        env.navigate(env.cell, floor=3)
    with pytest.raises(ActionError, match="not walkable"):
        env.navigate((2, 6))  # the kitchen counter
    env.seconds = 599.0
    env.observe()  # crosses the 10-minute limit
    assert env.done
    with pytest.raises(ActionError, match="ended"):
        env.observe()


def test_ground_truth_stays_in_the_environment(folder: Path) -> None:
    st = load_station(folder)
    tasks = load_tasks(folder / "delivery_tasks_dev.json", st)
    env = PrsEnv(st, inventory(st, tasks), tasks[0])
    public = vars(env.request)
    assert set(public) == {"task_id", "instruction", "npc_information", "time"}
    seen = env.observe()
    for p in seen.people:
        assert "Bob" not in p.appearance and "Ann" not in p.appearance


def test_scoring_rules() -> None:
    truth = PrsTruth(0, "Ann", (0.0, 0.0, 0.0), "stand", "Cup_3", "Cup", (1.0, 1.0, 1.0))

    def entry(name: str | None, x: float, minutes: float) -> dict:
        end = f"2025-01-01T12:{minutes:02.0f}:00"
        return {"agent_object_name": name, "agent_position": {"x": x, "y": 0, "z": 0},
                "start_time": "2025-01-01T12:00:00", "end_time": end}  # fmt: skip

    assert score_entry(entry("Cup_3", 2.9, 5), truth)["success"]
    s = score_entry(entry("Cup_1", 4.0, 5), truth)
    assert (s["grasp"], s["human_found"], s["deliver"], s["success"]) == (0.5, 0.5, 0.25, False)
    assert score_entry(entry("Apple_1", 1, 5), truth)["grasp"] == 0
    late = score_entry(entry("Cup_3", 1, 11), truth)
    assert not late["success"]
    agg = aggregate([score_entry(entry("Cup_3", 1, 5), truth), late], annotated=4)
    assert agg["Task SR"] == 0.25 and agg["Object Manipulation SR"] == 0.25 and agg["Time Used"] == 2.5
    # eval.py's own Task SR: int((grasp + object_find + deliver + human) / 4) with object_find never set
    assert agg["Task SR (eval.py)"] == 0 and agg["eval.py"]["Task SR"] == 0
    assert {k: agg["eval.py"][k] for k in ("Object Manipulation SR", "Human Search SR", "Time Used")} == {
        "Object Manipulation SR": 0.25, "Human Search SR": 0.25, "Time Used": 2.5
    }  # fmt: skip


def test_bad_task_file_one_clear_error(folder: Path, tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    data = json.loads((folder / "delivery_tasks_dev.json").read_text())
    del data["t3"]["npc_position"]["z"]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(PrsDataError, match=r"bad.json: t3 -> npc_position -> z: missing"):
        load_tasks(bad, load_station(folder))
    assert prs_command(folder, bad, tmp_path / "out") == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "t3 -> npc_position -> z" in err[0]
    assert not (tmp_path / "out" / "results.json").exists()


def test_unparsable_request_fails_that_task_only(folder: Path, tmp_path: Path) -> None:
    data = json.loads((folder / "delivery_tasks_dev.json").read_text())
    data["t1"]["directive"] = ["Hello there.", "Nice weather today."]
    f = tmp_path / "tasks.json"
    f.write_text(json.dumps(data))
    assert prs_command(folder, f, tmp_path / "out") == 0
    recs = {r["task_id"]: r for r in json.loads((tmp_path / "out" / "results.json").read_text())["tasks"]}
    assert recs["t1"]["failure_reason"].startswith("request not understood")
    assert sum(r["success"] for r in recs.values()) >= 30
    sub = json.loads((tmp_path / "out" / "prs_submission.json").read_text())
    assert set(sub) == set(data)
    assert "<svg" in (tmp_path / "out" / "report.html").read_text()


def test_prs_dev_subset_matches_prs_eval(shared_data: Path, tmp_path: Path) -> None:
    data = shared_data / "prs"
    if not (data / "eval.py").is_file():
        pytest.skip(f"PRS data not found at {data}")
    from gsr.benchmarks.delivery.prs_eval_check import compare

    tasks = json.loads((data / "delivery_tasks_dev.json").read_text())
    subset = tmp_path / "subset.json"
    subset.write_text(json.dumps(dict(list(tasks.items())[:40])))
    run = run_prs(data, subset, captions="none")
    check = compare(data / "eval.py", subset, run["submission"])
    assert check["equal"], check
    # eval.py as published: Task SR 0 (object_find is never set), reproduced exactly by our eval.py block
    assert check["eval.py"]["Task SR"] == 0 == check["ours (eval.py rule)"]["Task SR"]
    assert check["eval.py"] == check["ours (eval.py rule)"]
    assert check["simulator rule Task SR"]["ours"] >= 0.6
    assert run["summary"]["Task SR (eval.py)"] == 0 and run["summary"]["eval.py"] == check["eval.py"]


def test_bench_run_prs_suite(folder: Path, tmp_path: Path) -> None:
    from gsr.benchmarks.cli import run, summary_text

    doc = run("prs", source=str(folder), limit=10, out=str(tmp_path / "bench"))
    assert doc["suite"] == "prs" and len(doc["tasks"]) == 10
    assert set(doc["submission"]) == {f"t{k}" for k in range(10)}
    assert doc["metrics"]["Task SR"] == sum(t["success"] for t in doc["tasks"]) / 10
    assert "Task SR" in summary_text(doc)
    assert (tmp_path / "bench" / "results.json").is_file()
    from gsr.errors import GSRError

    with pytest.raises(GSRError, match="not a folder"):
        run("prs", source=str(tmp_path / "missing"))


def test_crossfit_calibrates_each_fold_on_the_others(folder: Path, tmp_path: Path) -> None:
    from gsr.benchmarks.delivery.prs_run import run_prs_crossfit

    run = run_prs_crossfit(folder, folder / "delivery_tasks_dev.json", folds=2)
    assert run["summary"]["tasks"] == 40 and run["summary"]["captions"].startswith("crossfit")
    assert list(run["submission"]) == [f"t{k}" for k in range(40)]  # file order kept
    assert run["summary"]["Task SR"] >= 0.8
    assert prs_command(folder, folder / "delivery_tasks_dev.json", tmp_path / "o", crossfit=1) == 1


def test_crossfit_honours_captions_none_and_refuses_what_it_cannot_do(
    folder: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from gsr.benchmarks.delivery.prs_run import run_prs_crossfit

    tasks = folder / "delivery_tasks_dev.json"
    run = run_prs_crossfit(folder, tasks, folds=2, captions="none")
    assert run["summary"]["captions"] == "none"  # was silently the folds' captions
    with pytest.raises(GSRError, match="bypass the folds"):
        run_prs_crossfit(folder, tasks, folds=2, captions=str(tasks))
    assert prs_command(folder, tasks, tmp_path / "o", workers=2, crossfit=2) == 1
    assert "--workers" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("request_text", "label", "source", "dest"),
    [
        (
            "Could you bring me the red apple that is on the counter in the kitchen? I'm in my bedroom.",
            "RedApple", ["kitchen room"], ["bed room 0"],
        ),
        (
            "I need the blue mug from the desk in the office space brought to the kitchen.",
            "BlueMug", ["office space"], ["kitchen room"],
        ),
        (
            "Take the blue mug sitting on the desk of the office space to Ann, who wears a kitchen apron.",
            "BlueMug", ["office space"], [],
        ),
        (
            "Head to the kitchen, grab the apple off the kitchen counter and bring it to Bob in the bedroom.",
            "RedApple", ["kitchen room"], ["bed room 0"],
        ),
    ],
)  # fmt: skip
def test_parse_general_constructions(
    folder: Path, request_text: str, label: str, source: list[str], dest: list[str]
) -> None:
    st = load_station(folder)
    p = parse_request(request_text, RoomMatcher(st), ["RedApple", "BlueMug"])
    assert max(["RedApple", "BlueMug"], key=lambda lab: label_score(lab, p.object_tokens)) == label
    assert [st.room(r).name for r in p.source_rooms] == source
    assert [st.room(r).name for r in p.dest_rooms] == dest


class _Boundary:
    """The environment seen through the simulator's boundary only: any other attribute raises."""

    ALLOWED = frozenset(
        [
            "request",
            "station",
            "observe",
            "navigate",
            "grasp",
            "hand_over",
            "give_up",
            "cell",
            "floor",
            "world",
            "cell_size",
            "done",
            "seconds",
        ]
    )

    def __init__(self, env: PrsEnv) -> None:
        object.__setattr__(self, "_env", env)

    def __getattr__(self, name: str) -> object:
        if name not in self.ALLOWED:
            raise AttributeError(f"the agent read {name!r}, which PRS does not give a robot")
        return getattr(object.__getattribute__(self, "_env"), name)


def test_agent_uses_only_the_simulator_boundary(folder: Path) -> None:
    from gsr.benchmarks.delivery.prs_agent import PrsAgent

    st = load_station(folder)
    tasks = load_tasks(folder / "delivery_tasks_dev.json", st)
    objects = inventory(st, tasks)
    agent = PrsAgent(st, sorted({o.type for o in objects}))
    done = 0
    for task in tasks[:6]:
        env = PrsEnv(st, objects, task)
        out = agent.run(_Boundary(env))  # type: ignore[arg-type]
        done += out.delivered and score_entry(env.result(), task.truth)["success"]
    assert done >= 5


def test_uncalibrated_folder_is_one_clear_error(
    folder: Path, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    tasks = tmp_path / "tasks.json"
    (folder / "delivery_tasks_dev.json").rename(tasks)
    assert prs_command(folder, tasks, tmp_path / "out") == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no floor is calibrated" in err[0]


@pytest.mark.slow
def test_prs_dev_acceptance(shared_data: Path) -> None:
    """Issue 19's benchmark: all 324 dev tasks, cross-fitted (no task scored on its own calibration or
    captions), Task SR >= 0.80 and PRS's eval.py agreeing on every figure."""
    data = shared_data / "prs"
    if not (data / "eval.py").is_file():
        pytest.skip(f"PRS data not found at {data}")
    from gsr.benchmarks.delivery.prs_eval_check import compare
    from gsr.benchmarks.delivery.prs_run import run_prs_crossfit

    run = run_prs_crossfit(data, data / "delivery_tasks_dev.json", folds=2)
    assert run["summary"]["tasks"] == 324 and run["summary"]["Task SR"] >= 0.80
    check = compare(data / "eval.py", data / "delivery_tasks_dev.json", run["submission"])
    assert check["equal"], check
    assert check["eval.py"]["Task SR"] == 0 and check["simulator rule Task SR"]["prs"] >= 0.80


# ---- the request parser on the language stack: constructions and paraphrases it was not tuned on --------

LABELS = ["RedApple", "BlueMug", "MobilePhone", "PlasticBottleWithGreenLid", "PlasticBottleWithWhiteLid"]


@pytest.mark.parametrize(
    ("request_text", "label", "source", "dest"),
    [
        # verbs from the vocabulary's classes, particles, pronoun and name before the object
        # "the kitchen counter" names furniture: no source room (the agent ranks rooms by their receptacles)
        ("Would you obtain the red apple on the kitchen counter and hand it over to me in the bed room?",
         "RedApple", [], ["bed room 0"]),
        ("Kindly get me that cellphone lying on the desk of the shared office, then carry it to the kitchen.",
         "MobilePhone", ["office space"], ["kitchen room"]),
        ("Give Ann the navy mug which is on the table in the bedroom; she is in the kitchen area.",
         "BlueMug", ["bed room 0"], ["kitchen room"]),
        ("Track down the crimson apple resting on the counter inside the kitchen and transport it to Bob.",
         "RedApple", ["kitchen room"], []),
        ("Head over to the office space, collect a smartphone from the desk and deliver it to the bedroom.",
         "MobilePhone", ["office space"], ["bed room 0"]),
        # no determiner
        ("Fetch red apple from kitchen counter, bring to bedroom.", "RedApple", [], ["bed room 0"]),
        # the object's place in a sentence of its own
        ("Can you bring the blue mug to Ann in the kitchen? It should be sitting on the desk in the office space.",
         "BlueMug", ["office space"], ["kitchen room"]),
        ("Locate Bob in the office space, then deliver to him the white bottle with a greenish cap from the kitchen.",
         "PlasticBottleWithGreenLid", ["kitchen room"], ["office space"]),
    ],
)  # fmt: skip
def test_parser_handles_unseen_paraphrases(
    folder: Path, request_text: str, label: str, source: list[str], dest: list[str]
) -> None:
    st = load_station(folder)
    p = parse_request(request_text, RoomMatcher(st), LABELS)
    assert max(LABELS, key=lambda lab: label_score(lab, p.object_tokens)) == label, p.object_tokens
    assert [st.room(r).name for r in p.source_rooms] == source
    assert [st.room(r).name for r in p.dest_rooms] == dest


def test_parser_structure_colour_lid_material_recipient(folder: Path) -> None:
    st = load_station(folder)
    p = parse_request(
        "Bring me the white plastic bottle with a green lid from the wooden counter in the kitchen."
        "Take the white plastic bottle with a green lid to Ann in the bedroom; she is wearing a green scarf.",
        RoomMatcher(st),
        LABELS,
    )
    ob = p.objects[0]
    assert ob.colors == ["white"] and ob.lid_color == "green" and ob.materials == ["plastic"]
    assert ob.head == ["plastic", "bottle", "green", "lid"]
    assert p.recipient.requester and p.recipient.names == ["Ann"]
    assert {"green", "scarf"} <= set(p.recipient.appearance)
    assert (
        "wood" not in ob.materials and "wooden" in p.source_tokens
    )  # the counter's material, not the bottle's


def test_parser_words_come_from_the_language_vocabulary() -> None:
    from gsr.benchmarks.delivery.prs_parse import base_color, classify, label_words, material_of, normalise

    from gsr.language.lexicon import vocabulary

    v = vocabulary()
    assert "cellphone" in v["synonyms"] and "navy" in v["shades"] and "bedroom" in v["spellings"]
    assert label_words("ConsolegamingPad") == ["console", "gaming", "pad"]  # a closed compound split
    assert base_color("bluish") == "blue" and base_color("navy") == "blue" and base_color("sleek") is None
    assert material_of("marble") == "stone" and material_of("wooden") == "wood"
    assert normalise("the officespace's meeting room") == "the office space s conference room"
    classes = [w.cls for w in classify("Please fetch me the cup, Ann.")]
    assert classes == ["FILLER", "PICK", "ME", "DET", "NOUN", "PUNCT", "WORD", "PUNCT"]


def test_request_without_an_object_names_the_reason(folder: Path) -> None:
    from gsr.benchmarks.delivery.prs_parse import RequestParseError

    st = load_station(folder)
    with pytest.raises(RequestParseError, match="no object phrase"):
        parse_request("Go to the kitchen and wait for Ann.", RoomMatcher(st), LABELS)


def _paraphrase(sentence: str, k: int) -> str:
    """A dev request said another way: another verb of the same class, another wording of its places."""
    import re

    verbs = ["Could you get", "I would like you to obtain", "Kindly retrieve", "Go ahead and grab"]
    s = re.sub(
        r"^(?:Please )?(?:fetch|grasp|retrieve|collect|grab|pick up|take)\b",
        verbs[k % 4],
        sentence,
        flags=re.I,
    )
    s = re.sub(r"\bfrom the\b", ["that is sitting on the", "off the", "located on the", "from the"][k % 4], s)
    s = s.replace("bedroom", "bed room").replace("office space", "shared office")
    return s.replace("officespace", "office space")


def _dev_requests(shared_data: Path) -> tuple[dict, RoomMatcher, list[str]]:
    """PRS's dev tasks, the station's room matcher and the object labels (skips without the data)."""
    data = shared_data / "prs"
    if not (data / "delivery_tasks_dev.json").is_file():
        pytest.skip(f"PRS data not found at {data}")
    tasks = json.loads((data / "delivery_tasks_dev.json").read_text())
    return (
        tasks,
        RoomMatcher(load_station(data, None)),
        sorted({t["target_object_type"] for t in tasks.values()}),
    )


def _parse_alike(original: str, rewritten: str, task: dict, rooms: RoomMatcher, labels: list[str]) -> bool:
    """Both wordings give the task's object type and the same source and destination rooms."""
    a = parse_request(original, rooms, labels)
    b = parse_request(rewritten, rooms, labels)
    best = [max(labels, key=lambda lab: label_score(lab, p.object_tokens)) for p in (a, b)]
    return (
        best[0] == best[1] == task["target_object_type"]
        and set(a.source_rooms) == set(b.source_rooms)
        and set(a.dest_rooms) == set(b.dest_rooms)
    )


def test_prs_dev_requests_paraphrased_parse_alike(shared_data: Path) -> None:
    """Dev requests rewritten with verbs and place wordings the parser's tests never saw: the object type,
    source rooms and destination rooms agree with the original parse on at least 95 % of them."""
    tasks, rooms, labels = _dev_requests(shared_data)
    same = total = 0
    for k, t in enumerate(tasks.values()):
        rewritten = "".join(_paraphrase(s, k) for s in t["directive"])
        total += 1
        same += _parse_alike("".join(t["directive"]), rewritten, t, rooms, labels)
    assert same >= 0.95 * total, f"{same} / {total}"


def test_task_on_an_uncalibrated_floor_fails_with_a_reason(folder: Path, tmp_path: Path) -> None:
    """An object and person below every calibrated floor (an unregistered basement): that task fails with
    its reason, the others run."""
    data = json.loads((folder / "delivery_tasks_dev.json").read_text())
    data["t2"]["target_object_name"] = data["t2"]["target_object_type"] + "_9"  # an object no other task has
    data["t2"]["target_object_pos"]["y"] = -20.0
    data["t2"]["npc_position"]["y"] = -20.0
    f = tmp_path / "tasks.json"
    f.write_text(json.dumps(data))
    assert prs_command(folder, f, tmp_path / "out") == 0
    recs = {r["task_id"]: r for r in json.loads((tmp_path / "out" / "results.json").read_text())["tasks"]}
    assert not recs["t2"]["success"] and recs["t2"]["failure_reason"]
    assert sum(r["success"] for r in recs.values()) >= 38


def test_prs_dev_requests_restructured_parse_alike(shared_data: Path) -> None:
    """Dev requests of the form *fetch the X from the Y and take it to Z* said in other sentence structures
    (the object's place in a statement of its own: *Can you bring the X to Z? It is on the Y.*, *I need the
    X in Z; you will find it in the Y.*, *The Y has a X on it: kindly transport it to Z.*): object type,
    source and destination rooms agree with the original parse on at least 90 % of them."""
    import re

    tasks, rooms, labels = _dev_requests(shared_data)
    pattern = re.compile(
        r"^(?:Please )?(?:fetch|grasp|retrieve|collect|grab|pick up|take) the (?P<obj>.+?) (?:from|on) the "
        r"(?P<src>.+?),? (?:and|then) (?:take|bring|deliver) it to (?P<dest>.+?)\.$",
        re.I,
    )
    same = total = 0
    for k, t in enumerate(tasks.values()):
        m = pattern.match(t["directive"][0])
        if not m:
            continue
        obj, src, dest = m.group("obj"), m.group("src"), m.group("dest").replace(" for me", "")
        first = [
            f"Can you bring the {obj} to {dest}? It is on the {src}.",
            f"I need the {obj} in {dest}; you will find it in the {src}.",
            f"The {src} has a {obj} on it: kindly transport it to {dest}.",
        ][k % 3]
        total += 1
        same += _parse_alike("".join(t["directive"]), first + t["directive"][1], t, rooms, labels)
    assert total >= 200 and same >= 0.9 * total, f"{same} / {total}"
