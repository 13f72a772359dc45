"""Running the PRS delivery benchmark offline: every task of a file, results and a PRS submission.

``run_prs(data, tasks_file, workers)`` loads the station (calibrated from the folder's dev file), the
tasks and their object inventory, builds the sensor's object captions (below), runs the agent on each
task in a fresh ``PrsEnv`` and scores the episode with PRS's rules.

Object captions stand in for what PRS's camera + a vision-language model would tell apart (``sky blue``
vs ``white`` bagged cake): for each object, the words people used for it in the *caption tasks* (by
default the data folder's ``delivery_tasks_dev.json``) besides its type words. On the dev tasks this is
optimistic (the captions come from the same sentences); ``--captions none`` turns them off and
``--captions FILE`` builds them from another task file (e.g. one half of dev to score the other).
"""

from __future__ import annotations

import os
import time
import zlib
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from gsr.benchmarks.delivery.building.prs import load_station
from gsr.benchmarks.delivery.building.prs_calibrate import Observation, calibrate_station
from gsr.benchmarks.delivery.building.prs_station import Station
from gsr.benchmarks.delivery.prs_agent import PrsAgent
from gsr.benchmarks.delivery.prs_env import PrsEnv
from gsr.benchmarks.delivery.prs_metrics import aggregate, score_entry
from gsr.benchmarks.delivery.prs_parse import STOP, RequestParseError, RoomMatcher, label_words, parse_request
from gsr.benchmarks.delivery.prs_tasks import PlacedObject, PrsTask, inventory, load_tasks

from gsr.errors import GSRError


def build_captions(station: Station, tasks: list[PrsTask], labels: list[str]) -> dict[str, frozenset[str]]:
    """Object name -> the non-type words requests used for it (the sensor's captions)."""
    rooms = RoomMatcher(station)
    words: dict[str, Counter] = {}
    seen: Counter = Counter()
    for t in tasks:
        try:
            parsed = parse_request(t.request.instruction, rooms, labels)
        except RequestParseError:
            continue
        type_words = set(label_words(t.truth.target_object_type))
        attrs = [w for w in parsed.object_tokens if w not in type_words and w not in STOP]
        words.setdefault(t.truth.target_object_name, Counter()).update(set(attrs))
        seen[t.truth.target_object_name] += 1
    # a caption keeps the words at least CAPTION_SHARE of the object's requests use: what most people
    # see in it, not every paraphrase
    return {
        name: frozenset(w for w, n in c.items() if n >= CAPTION_SHARE * seen[name])
        for name, c in words.items()
    }


#: Share of an object's requests that must use a word for it to enter the object's caption.
CAPTION_SHARE = 0.25

_STATE: dict = {}


def _init(data: str, tasks_file: str, captions: str, calibration: str = "auto") -> None:
    station = load_station(data, calibration)
    if not any(f.transform is not None for f in station.floors.values()):
        raise GSRError(
            f"{data}: no floor is calibrated (the grid <-> world transform is fitted from a task file with "
            "person positions: put PRS's delivery_tasks_dev.json in the folder)"
        )
    tasks = load_tasks(tasks_file, station)
    objects = inventory(station, tasks)
    labels = sorted({o.type for o in objects})
    caps: dict[str, frozenset[str]] = {}
    if captions != "none":
        src = Path(data) / "delivery_tasks_dev.json" if captions == "dev" else Path(captions)
        caps = build_captions(station, load_tasks(src, station), labels)
    _set_state((data, tasks_file, captions, calibration), station, tasks, objects, labels, caps)


def _set_state(
    key: tuple,
    station: Station,
    tasks: list[PrsTask],
    objects: list[PlacedObject],
    labels: list[str],
    caps: dict,
) -> None:
    _STATE.clear()
    _STATE.update(
        key=key,
        station=station,
        tasks={t.request.task_id: t for t in tasks},
        objects=objects,
        labels=labels,
        captions=caps,
        agent=PrsAgent(station, labels),
    )


def ensure_state(data: str, tasks_file: str, captions: str = "dev", calibration: str = "auto") -> dict:
    """The per-process station, tasks, inventory, captions and agent for a run (loaded once)."""
    if _STATE.get("key") != (data, tasks_file, captions, calibration):
        _init(data, tasks_file, captions, calibration)
    return _STATE


def task_ids() -> list[str]:
    """The loaded run's task ids, in file order."""
    return list(_STATE["tasks"])


def run_one(task_id: str) -> dict:
    """Run one task of the loaded run: its submission entry, record and trace."""
    return _run_one(task_id)


def _run_one(task_id: str) -> dict:
    st = _STATE
    task: PrsTask = st["tasks"][task_id]
    objects: list[PlacedObject] = st["objects"]
    env = PrsEnv(st["station"], objects, task, st["captions"])
    t0 = time.process_time()
    outcome = st["agent"].run(env)
    entry = env.result()
    score = score_entry(entry, task.truth)
    truth = env.truth_cells()
    reason = outcome.reason
    if score["success"]:
        reason = ""
    elif not reason:
        if score["grasp"] < 1:
            reason = "wrong object grasped" if score["grasp"] else "no object grasped"
        elif score["human_found"] < 1:
            reason = "handed over to the wrong person"
        else:
            reason = "time limit"
    return {
        "task_id": task_id,
        "submission": entry,
        "record": {
            "task_id": task_id,
            "success": bool(score["success"]),
            "grasp": score["grasp"],
            "object_found": bool(truth["object_seen"]),
            "human_found": score["human_found"],
            "deliver": score["deliver"],
            "sim_minutes": round(score["minutes"], 3),
            "distance_to_person_m": round(score["distance_m"], 2),
            "parsed": outcome.parsed,
            "grasped": outcome.grasped,
            "failure_reason": reason,
            "cpu_s": round(time.process_time() - t0, 4),
        },
        "trace": {
            "path": [[f, c[0], c[1]] for f, c in env.log.path],
            "object": truth["object"],
            "person": truth["person"],
            "events": env.log.events,
        },
    }


def run_prs(
    data: str | Path,
    tasks_file: str | Path,
    workers: int = 1,
    captions: str = "dev",
    calibration: str = "auto",
) -> dict:
    """Run every task; returns ``{"summary", "records", "submission", "traces"}`` (task order kept)."""
    data, tasks_file = str(data), str(tasks_file)
    _init(data, tasks_file, captions, calibration)
    ids = list(_STATE["tasks"])
    t0, c0 = time.perf_counter(), time.process_time()
    if workers > 1:
        with ProcessPoolExecutor(
            workers, initializer=_init, initargs=(data, tasks_file, captions, calibration)
        ) as pool:
            rows = list(pool.map(_run_one, ids, chunksize=8))
    else:
        rows = [_run_one(i) for i in ids]
    truths = {i: t.truth for i, t in _STATE["tasks"].items()}
    meta = {"workers": workers, "captions": captions, "calibration_tasks": calibration}
    return _document(rows, truths, t0, c0, meta, _STATE["station"])


def observations_of(station: Station, tasks: list[PrsTask]) -> list[Observation]:
    """Calibration observations of tasks: each person's position with their schedule codes at that hour."""
    out = []
    for t in tasks:
        slots = station.people[t.truth.npc_id].slots_at(t.request.time.hour)
        out.append(Observation(tuple(s.location for s in slots), *t.truth.npc_position))
    return out


#: How ``run_prs_crossfit`` folds tasks: by file position, by recipient (a held-out person's schedule
#: codes are calibrated only from other people), or by target object (a held-out object's caption never
#: comes from a request about it: the sensor sees it by type only).
SPLITS = ("position", "person", "object")


def fold_of(task: PrsTask, position: int, folds: int, split: str) -> int:
    """The fold of a task: by position, or by a stable hash of its recipient or target object."""
    if split == "position":
        return position % folds
    key = str(task.truth.npc_id) if split == "person" else task.truth.target_object_name
    return zlib.crc32(key.encode("utf-8")) % folds


def run_prs_crossfit(
    data: str | Path,
    tasks_file: str | Path,
    folds: int = 2,
    split: str = "position",
    captions: str = "dev",
) -> dict:
    """The honest dev estimate: the tasks split in ``folds`` (``SPLITS``); each fold runs on a station
    calibrated, and with object captions built, from the *other* folds only (the inventory stays every
    object of the file). ``captions`` "none": no captions at all (the sensor sees types only); a caption
    file would bypass the folds and is refused. Returns the same document as ``run_prs``."""
    if folds < 2:
        raise GSRError("--crossfit needs at least 2 folds")
    if split not in SPLITS:
        raise GSRError(f"--split must be one of {', '.join(SPLITS)}, not {split!r}")
    if captions not in ("dev", "none"):
        raise GSRError(
            "--crossfit builds captions from the other folds (--captions dev) or none (--captions none); "
            f"a caption file ({captions}) would bypass the folds"
        )
    data, tasks_file = str(data), str(tasks_file)
    t0, c0 = time.perf_counter(), time.process_time()
    tasks = load_tasks(tasks_file, load_station(data, None))
    rows = []
    fold = {t.request.task_id: fold_of(t, k, folds, split) for k, t in enumerate(tasks)}
    for f in range(folds):
        test = [t for t in tasks if fold[t.request.task_id] == f]
        train = [t for t in tasks if fold[t.request.task_id] != f]
        if not test:
            continue
        station = load_station(data, None)
        calibrate_station(station, observations_of(station, train))
        objects = inventory(station, tasks)
        labels = sorted({o.type for o in objects})
        caps = build_captions(station, train, labels) if captions == "dev" else {}
        _set_state(("crossfit", data, tasks_file, f, captions), station, test, objects, labels, caps)
        rows += [_run_one(t.request.task_id) for t in test]
    order = {t.request.task_id: k for k, t in enumerate(tasks)}
    rows.sort(key=lambda r: order[r["task_id"]])
    truths = {t.request.task_id: t.truth for t in tasks}
    folds_text = f"crossfit, {folds} folds by {split}"
    caption_text = folds_text if captions == "dev" else "none"
    meta = {"workers": 1, "captions": caption_text, "calibration_tasks": folds_text}
    return _document(rows, truths, t0, c0, meta, _STATE["station"])


def _document(rows: list[dict], truths: dict, t0: float, c0: float, meta: dict, station: Station) -> dict:
    scores = [score_entry(r["submission"], truths[r["task_id"]]) for r in rows]
    summary = aggregate(scores, len(rows))
    records = [r["record"] for r in rows]
    n = max(1, len(records))
    summary.update(
        {
            "human_found_exact": sum(r["human_found"] == 1 for r in records) / n,
            "grasp_exact": sum(r["grasp"] == 1 for r in records) / n,
            "object_found": sum(r["object_found"] for r in records) / n,
            "failure_reasons": dict(Counter(r["failure_reason"] for r in records if r["failure_reason"])),
            "wall_s": round(time.perf_counter() - t0, 2),
            "cpu_s_main": round(time.process_time() - c0, 2),
            **meta,
            "calibration": station.calibration,
            "cpu_count": os.cpu_count(),
        }
    )
    return {
        "summary": summary,
        "records": records,
        "submission": {r["task_id"]: r["submission"] for r in rows},
        "traces": {r["task_id"]: r["trace"] for r in rows},
    }
