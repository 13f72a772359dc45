"""Perception input: one RGB-D frame with instance masks and labels, the detector plug-in, file loading.

Masks are an ``HxW`` integer image: each pixel holds an instance id, negative means "no instance".
Labels map an instance id to what it is (a node id, a category, a colour, a parent for articulated
parts) or mark it as a functional keypoint of another node (``{"keypoint_of": ..., "name": "handle"}``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np
from gsr.perception.camera import Camera, load_camera

from gsr.errors import GSRError
from gsr.scene_graph import NODE_NAME

_LABEL_FIELDS = frozenset(
    {"id", "category", "color", "parent", "attributes", "keypoint_of", "name", "ignore"}
)


@dataclass(frozen=True)
class InstanceLabel:
    """What one mask id denotes: a node (id, category, colour, parent) or a keypoint of a node."""

    id: str | None = None
    category: str = "thing"
    color: str | None = None
    parent: str | None = None
    attributes: dict[str, Any] = field(default_factory=dict)
    keypoint_of: str | None = None
    name: str | None = None
    ignore: bool = False


def label_from_dict(data: Any, where: str) -> InstanceLabel:
    """Validate one label object; errors name ``where`` and the field."""
    if not isinstance(data, dict):
        raise GSRError(f"{where}: label must be a JSON object")
    unknown = set(data) - _LABEL_FIELDS
    if unknown:
        raise GSRError(f"{where}: unknown label field(s) {', '.join(sorted(unknown))}")
    for key in ("id", "category", "color", "parent", "keypoint_of", "name"):
        v = data.get(key)
        if v is not None and not isinstance(v, str):
            raise GSRError(f"{where}: field {key!r} must be a string, got {v!r}")
    for key in ("id", "category", "parent", "keypoint_of"):
        v = data.get(key)
        if v is not None and not NODE_NAME.match(v.lower()):
            raise GSRError(f"{where}: field {key!r}: {v!r} is not a valid node name")
    if "keypoint_of" in data and "name" not in data:
        raise GSRError(f"{where}: a keypoint label needs 'name' (e.g. 'handle')")
    attrs = data.get("attributes", {})
    if not isinstance(attrs, dict):
        raise GSRError(f"{where}: field 'attributes' must be an object")
    return InstanceLabel(
        id=data.get("id", "").lower() or None,
        category=str(data.get("category", "thing")).lower(),
        color=data.get("color"),
        parent=(data.get("parent") or "").lower() or None,
        attributes=dict(attrs),
        keypoint_of=(data.get("keypoint_of") or "").lower() or None,
        name=data.get("name"),
        ignore=bool(data.get("ignore", False)),
    )


def labels_from_dict(data: Any, source: str = "<labels>") -> dict[int, InstanceLabel]:
    """Validate a labels JSON object ``{"<mask id>": {label}, ...}``."""
    if not isinstance(data, dict):
        raise GSRError(f"{source}: labels must be a JSON object mapping mask ids to labels")
    out: dict[int, InstanceLabel] = {}
    for key, value in data.items():
        try:
            mask_id = int(key)
        except ValueError:
            raise GSRError(f"{source}: key {key!r} is not an integer mask id") from None
        out[mask_id] = label_from_dict(value, f"{source}: label {key}")
    return out


@dataclass(frozen=True)
class Frame:
    """One camera's observation: RGB, metric depth, instance masks, labels and the camera."""

    rgb: np.ndarray  # HxWx3 uint8
    depth: np.ndarray  # HxW float, metres, 0 or non-finite = no return
    masks: np.ndarray  # HxW int, negative = no instance
    camera: Camera
    labels: dict[int, InstanceLabel] = field(default_factory=dict)

    def __post_init__(self) -> None:
        h, w = self.camera.height, self.camera.width
        checks = (
            ("rgb", self.rgb, (h, w, 3)),
            ("depth", self.depth, (h, w)),
            ("masks", self.masks, (h, w)),
        )
        for name, arr, shape in checks:
            if arr.shape != shape:
                raise GSRError(
                    f"{name}: shape {arr.shape} does not match the camera ({w}x{h}); expected {shape}"
                )
        if not np.issubdtype(self.masks.dtype, np.integer):
            raise GSRError(f"masks: expected an integer array, got dtype {self.masks.dtype}")
        if not np.issubdtype(self.depth.dtype, np.floating):
            raise GSRError(f"depth: expected a float array in metres, got dtype {self.depth.dtype}")


@runtime_checkable
class Detector(Protocol):
    """Any instance detector: RGB-D in, an instance-id image and labels for those ids out."""

    def detect(self, rgb: np.ndarray, depth: np.ndarray) -> tuple[np.ndarray, dict[int, InstanceLabel]]:
        """Instance masks (HxW int, negative = none) and labels by mask id."""
        ...


def frame_from_detector(rgb: np.ndarray, depth: np.ndarray, camera: Camera, detector: Detector) -> Frame:
    """Build a frame by running a detector plug-in on RGB-D."""
    masks, labels = detector.detect(rgb, depth)
    return Frame(rgb=rgb, depth=depth, masks=np.asarray(masks), camera=camera, labels=dict(labels))


# ------------------------------------------------------------------ files


def _check_file(path: Path) -> None:
    if not path.exists():
        raise GSRError(f"{path}: no such file")
    if path.is_dir():
        raise GSRError(f"{path}: is a directory, expected a file")


def load_rgb(path: str | Path) -> np.ndarray:
    """An RGB image (PNG/JPEG via Pillow, or a .npy HxWx3 uint8 array)."""
    p = Path(path)
    _check_file(p)
    if p.suffix.lower() == ".npy":
        arr = _load_npy(p)
    else:
        from PIL import Image, UnidentifiedImageError

        try:
            with Image.open(p) as img:
                arr = np.asarray(img.convert("RGB"))
        except (UnidentifiedImageError, OSError) as exc:
            raise GSRError(f"{p}: not a readable image ({exc})") from None
    if arr.ndim != 3 or arr.shape[2] != 3:
        raise GSRError(f"{p}: expected an HxWx3 RGB image, got shape {arr.shape}")
    return arr.astype(np.uint8, copy=False)


def _load_npy(p: Path) -> np.ndarray:
    try:
        return np.load(p, allow_pickle=False)
    except (ValueError, OSError) as exc:
        raise GSRError(f"{p}: not a readable .npy array ({exc})") from None


def load_depth(path: str | Path) -> np.ndarray:
    """A metric depth image: .npy float (metres) or a 16-bit PNG in millimetres."""
    p = Path(path)
    _check_file(p)
    if p.suffix.lower() == ".npy":
        arr = _load_npy(p)
        if not np.issubdtype(arr.dtype, np.floating):
            raise GSRError(f"{p}: depth .npy must be float metres, got dtype {arr.dtype}")
    else:
        from PIL import Image, UnidentifiedImageError

        try:
            with Image.open(p) as img:
                raw = np.asarray(img)
        except (UnidentifiedImageError, OSError) as exc:
            raise GSRError(f"{p}: not a readable image ({exc})") from None
        if raw.dtype not in (np.uint16, np.int32):
            raise GSRError(f"{p}: a depth PNG must be 16-bit millimetres, got dtype {raw.dtype}")
        arr = raw.astype(np.float32) / 1000.0
    if arr.ndim != 2:
        raise GSRError(f"{p}: expected an HxW depth image, got shape {arr.shape}")
    return arr.astype(np.float32, copy=False)


def load_masks(path: str | Path) -> np.ndarray:
    """An instance-id image: .npy integer array or a 16-bit/8-bit PNG (negative ids only via .npy)."""
    p = Path(path)
    _check_file(p)
    if p.suffix.lower() == ".npy":
        arr = _load_npy(p)
    else:
        from PIL import Image, UnidentifiedImageError

        try:
            with Image.open(p) as img:
                arr = np.asarray(img)
        except (UnidentifiedImageError, OSError) as exc:
            raise GSRError(f"{p}: not a readable image ({exc})") from None
    if arr.ndim != 2 or not np.issubdtype(arr.dtype, np.integer):
        raise GSRError(f"{p}: expected an HxW integer mask image, got shape {arr.shape} dtype {arr.dtype}")
    return arr.astype(np.int32, copy=False)


def load_labels(path: str | Path) -> dict[int, InstanceLabel]:
    """A labels JSON file ``{"<mask id>": {"id", "category", "color", "parent"}, ...}``."""
    p = Path(path)
    _check_file(p)
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise GSRError(f"{p}:{exc.lineno}:{exc.colno}: invalid JSON: {exc.msg}") from None
    except UnicodeDecodeError:
        raise GSRError(f"{p}: not a UTF-8 text file") from None
    return labels_from_dict(data, str(p))


def load_frame(
    rgb: str | Path,
    depth: str | Path,
    masks: str | Path,
    camera: str | Path,
    labels: str | Path | None = None,
) -> Frame:
    """Load and cross-check the files of one frame (shapes must match the camera)."""
    cam = load_camera(camera)
    rgb_a, depth_a, masks_a = load_rgb(rgb), load_depth(depth), load_masks(masks)
    for name, path, arr in (("rgb", rgb, rgb_a), ("depth", depth, depth_a), ("masks", masks, masks_a)):
        if arr.shape[:2] != (cam.height, cam.width):
            raise GSRError(
                f"{path}: {name} is {arr.shape[1]}x{arr.shape[0]} but {camera} says {cam.width}x{cam.height}"
            )
    lab = load_labels(labels) if labels is not None else {}
    return Frame(rgb=rgb_a, depth=depth_a, masks=masks_a, camera=cam, labels=lab)
