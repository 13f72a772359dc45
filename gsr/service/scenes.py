"""Stored scenes: an agent sends a scene graph once (POST /v1/scenes) and then checks many steps
against its id, without sending or parsing the graph again.

A scene's id is the SHA-256 of its canonical JSON, so storing the same scene twice gives the same
id and any server process can serve it: the JSON is kept in the state directory that a server's
processes share (at most ``max_scenes`` files, oldest dropped first), and each process keeps the
most recently used parsed scenes (with their states) in memory.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from collections import OrderedDict
from pathlib import Path
from typing import Any

from gsr.service.handlers import ApiError, Scene
from gsr.service.settings import ServiceSettings

_ID = re.compile(r"[0-9a-f]{32}")
INLINE_CACHE_NODES = 200  # inline scenes up to this size are remembered by content (bounds the cache)


class SceneStore:
    """Content-addressed scenes on disk with a per-process LRU of parsed ones."""

    def __init__(self, settings: ServiceSettings, directory: Path, cached: int = 256, on_lookup=None) -> None:
        self.settings = settings
        self.directory = directory
        self.directory.mkdir(parents=True, exist_ok=True)
        self.cached = cached
        self._lru: OrderedDict[str, Scene] = OrderedDict()
        self._on_lookup = on_lookup or (lambda result: None)

    def put(self, data: dict[str, Any]) -> tuple[str, Scene]:
        """Validate and store a scene graph; its id and the parsed scene."""
        scene = Scene.from_data(data, self.settings, field="body")
        text = json.dumps(data, sort_keys=True, separators=(",", ":"))
        scene_id = hashlib.sha256(text.encode()).hexdigest()[:32]
        path = self.directory / f"{scene_id}.json"
        if not path.exists():
            tmp = path.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_text(text, encoding="utf-8")
            os.replace(tmp, path)
            self._trim()
        self._remember(scene_id, scene)
        return scene_id, scene

    def inline(self, data: dict[str, Any], field: str = "scene_graph") -> Scene:
        """A scene sent inline, parsed once per distinct content: an agent that re-sends the same
        graph with every step pays for the parse and the derived state only the first time."""
        nodes = data.get("nodes")
        if not isinstance(nodes, list) or len(nodes) > INLINE_CACHE_NODES:
            return Scene.from_data(data, self.settings, field)
        key = "inline:" + hashlib.sha1(json.dumps(data, sort_keys=True).encode()).hexdigest()
        scene = self._lru.get(key)
        if scene is None:
            scene = Scene.from_data(data, self.settings, field)
            self._remember(key, scene)
        else:
            self._lru.move_to_end(key)
        return scene

    def get(self, scene_id: str) -> Scene:
        """The parsed scene ``scene_id`` (404 ``unknown_scene`` when it is not stored)."""
        scene = self._lru.get(scene_id)
        if scene is not None:
            self._lru.move_to_end(scene_id)
            self._on_lookup("memory")
            return scene
        path = self.directory / f"{scene_id}.json"
        if not _ID.fullmatch(scene_id) or not path.is_file():
            self._on_lookup("miss")
            raise ApiError(
                404, "unknown_scene", f"no stored scene {scene_id[:64]!r}; store it with POST /v1/scenes"
            )
        data = json.loads(path.read_text(encoding="utf-8"))
        scene = Scene.from_data(data, self.settings, field="scene")
        self._remember(scene_id, scene)
        self._on_lookup("disk")
        return scene

    def _remember(self, scene_id: str, scene: Scene) -> None:
        self._lru[scene_id] = scene
        self._lru.move_to_end(scene_id)
        while len(self._lru) > self.cached:
            self._lru.popitem(last=False)

    def _trim(self) -> None:
        files = list(self.directory.glob("*.json"))
        excess = len(files) - self.settings.max_scenes
        if excess <= 0:
            return
        files.sort(key=lambda p: p.stat().st_mtime if p.exists() else 0.0)
        for path in files[: excess + self.settings.max_scenes // 10]:
            path.unlink(missing_ok=True)
