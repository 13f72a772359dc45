"""Class-agnostic instance segmentation of one RGB-D frame with no simulator input.

Steps (all on a strided pixel grid, vectorised numpy/scipy):

1. **Back-projection** of every pixel with a depth return to world points (the camera pose gives gravity:
   world +z is up), a 3x3 median of the depth first so that sensor noise does not make edges.
2. **Support plane**: the dominant horizontal surface (the height histogram of pixels whose normal points
   up), refined by a least-squares plane through its inliers. Pixels within ``plane_distance`` of it are
   the support (the table); pixels below it are dropped.
3. **Over-segmentation** of what stands above the plane: neighbouring pixels are linked unless a depth
   discontinuity (a jump that the neighbouring depth steps do not explain, so slanted surfaces stay whole),
   a chromaticity edge or a strong brightness edge separates them; connected components of the links,
   sealed so that one stray link across a boundary cannot join two objects (the pixels lining the cuts
   join a component only after the components are formed).
   A trained link model (``gsr.perception.train``) can take the place of these thresholds: an MLP over
   each link's local features (:data:`LINK_FEATURE_NAMES`) that says whether an object boundary cuts it,
   which catches the boundaries the thresholds miss (an open drawer sticking out of its cabinet: same
   colour, a step of a centimetre).
4. **Merging**: adjacent segments are merged when a merge scorer says they are one object — a learned
   model (``gsr.perception.train``) when one is loaded, else a documented rule (similar colour and no depth
   jump along most of the shared boundary).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from gsr.perception.camera import Camera

from gsr.errors import GSRError


@dataclass(frozen=True)
class SegmentParams:
    """Tunable constants of the geometric segmenter (see docs/perception.md, *Perception without oracle*)."""

    stride: int = 0  # work on every n-th pixel; 0: the stride nearest a grid_width-wide grid (640 -> 2)
    grid_width: int = 320  # the working grid's width for stride 0 (the trained models' grid: 640x480 / 2)
    plane_distance: float = 0.008  # |height above the support plane| of support pixels (m)
    horizontal: float = 0.9  # |normal z| of a pixel that may belong to a horizontal surface
    depth_edge: float = 0.008  # a depth jump beyond this + depth_edge_rel * depth is an edge (m)
    depth_edge_rel: float = 0.012
    chroma_edge: float = 0.075  # L1 change of (r, g, b) / (r + g + b) between neighbours
    intensity_edge: float = 0.9  # |log brightness ratio| between neighbours
    dark: float = 40.0  # pixels darker than this (sum of r, g, b / 3) have no reliable chromaticity
    min_pixels: int = 10  # segments with fewer strided pixels are dropped
    link_threshold: float = 0.5  # a trained link model's boundary probability from which a link is cut
    seal: int = 0  # pixels within this many grid steps of a cut link line the boundary (seal short gaps)
    max_depth: float = 10.0
    merge_threshold: float = 0.5  # merge adjacent segments whose merge score exceeds this


@dataclass
class Segments:
    """The segmentation of one frame on the strided grid, with what recognition needs."""

    stride: int
    shape: tuple[int, int]  # full-resolution (H, W)
    labels: np.ndarray  # (h, w) int32: segment index, -1 = none
    support: np.ndarray  # (h, w) bool: support-plane pixels
    plane: np.ndarray | None  # (a, b, c, d), normal up; None when no horizontal plane was found
    points: np.ndarray  # (h, w, 3) world points (NaN without depth)
    rgb: np.ndarray  # (h, w, 3) uint8
    normals: np.ndarray  # (h, w, 3) unit normals (world), NaN where unknown
    height: np.ndarray  # (h, w) height above the plane (m), NaN without depth
    camera_position: np.ndarray  # (3,) world position of the camera centre

    @property
    def count(self) -> int:
        """Number of segments."""
        return int(self.labels.max()) + 1 if self.labels.size and self.labels.max() >= 0 else 0

    def full_mask(self, index: int) -> np.ndarray:
        """The full-resolution boolean mask of one segment (nearest-neighbour upsampling)."""
        return upsample(self.labels == index, self.stride, self.shape)

    def full_support(self) -> np.ndarray:
        """The full-resolution mask of the support plane."""
        return upsample(self.support, self.stride, self.shape)


def upsample(mask: np.ndarray, stride: int, shape: tuple[int, int]) -> np.ndarray:
    """Nearest-neighbour upsampling of a strided mask to ``shape``."""
    if stride == 1:
        return mask.copy()
    big = np.repeat(np.repeat(mask, stride, axis=0), stride, axis=1)
    return big[: shape[0], : shape[1]]


def check_inputs(rgb: np.ndarray, depth: np.ndarray, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """Validate one frame's arrays against the camera; one-line errors, NaN depth becomes 'no return'."""
    if rgb is None or depth is None:
        raise GSRError("detect: rgb and depth are both required")
    rgb = np.asarray(rgb)
    depth = np.asarray(depth)
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise GSRError(f"detect: rgb must be HxWx3, got shape {rgb.shape}")
    if depth.ndim != 2:
        raise GSRError(f"detect: depth must be HxW, got shape {depth.shape}")
    if rgb.shape[:2] != depth.shape or depth.shape != (camera.height, camera.width):
        raise GSRError(
            f"detect: rgb {rgb.shape[1]}x{rgb.shape[0]}, depth {depth.shape[1]}x{depth.shape[0]} and "
            f"camera {camera.width}x{camera.height} must have the same size"
        )
    if not np.issubdtype(depth.dtype, np.floating):
        raise GSRError(f"detect: depth must be float metres, got dtype {depth.dtype}")
    if rgb.dtype != np.uint8:
        if not np.issubdtype(rgb.dtype, np.number) or not np.all(np.isfinite(rgb)):
            raise GSRError(f"detect: rgb must be uint8, got dtype {rgb.dtype}")
        rgb = np.clip(rgb, 0, 255).astype(np.uint8)
    depth = np.where(np.isfinite(depth) & (depth > 0), depth, 0.0).astype(np.float32)
    return rgb, depth


def working_stride(params: SegmentParams, width: int) -> int:
    """The pixel stride of the working grid: ``params.stride``, or for 0 the one whose grid is nearest
    ``params.grid_width`` pixels wide, so that a 320x240 and a 640x480 image of the same view give the
    same grid (the trained models' features count grid pixels and compare grid neighbours)."""
    if params.stride > 0:
        return params.stride
    return max(1, round(width / max(params.grid_width, 1)))


def _median3(z: np.ndarray) -> np.ndarray:
    """3x3 median of depth, ignoring pixels without a return (they stay empty)."""
    from scipy.ndimage import median_filter

    filled = median_filter(z, size=3, mode="nearest")
    return np.where(z > 0, np.where(filled > 0, filled, z), 0.0)


def _world(z: np.ndarray, camera: Camera, stride: int) -> np.ndarray:
    u, v = camera.rays(stride)
    zz = np.where(z > 0, z, np.nan).astype(np.float64)
    cam = np.stack((u * zz, v * zz, zz), axis=-1)
    rot, t = camera.cam_to_world[:3, :3], camera.cam_to_world[:3, 3]
    return cam @ rot.T + t


def _normals(p: np.ndarray) -> np.ndarray:
    """Unit normals from central differences of the point grid (NaN at borders and holes)."""
    dx = np.full_like(p, np.nan)
    dy = np.full_like(p, np.nan)
    dx[:, 1:-1] = p[:, 2:] - p[:, :-2]
    dy[1:-1] = p[2:] - p[:-2]
    n = np.cross(dx, dy)
    norm = np.linalg.norm(n, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return n / norm


def fit_support_plane(
    points: np.ndarray, normals: np.ndarray, camera_position: np.ndarray, params: SegmentParams
) -> np.ndarray | None:
    """The dominant horizontal plane ``(a, b, c, d)`` (normal up) of a point grid, or None."""
    pts = points.reshape(-1, 3)
    nz = np.abs(normals[..., 2]).reshape(-1)
    ok = np.isfinite(pts[:, 2]) & (np.nan_to_num(nz) > params.horizontal)
    z = pts[ok, 2]
    if z.size < 50:
        return None
    # weight each pixel by the world area it covers (squared range), so the plane with the largest
    # surface wins rather than the one nearest the camera (a cabinet top seen from close by)
    rng2 = np.sum((pts[ok] - camera_position) ** 2, axis=1)
    lo, hi = float(z.min()), float(z.max())
    bins = max(1, int(np.ceil((hi - lo) / 0.005)))
    hist, edges = np.histogram(z, bins=bins, range=(lo, lo + bins * 0.005), weights=rng2)
    # smooth over neighbouring bins so a slightly tilted plane is one peak
    smooth = hist + np.concatenate(([0], hist[:-1])) + np.concatenate((hist[1:], [0]))
    k = int(np.argmax(smooth))
    h0 = (edges[k] + edges[k + 1]) / 2.0
    near = ok & (np.abs(pts[:, 2] - h0) < 0.015)
    sel = pts[near]
    if len(sel) < 30:
        return None
    if len(sel) > 5000:
        sel = sel[np.random.default_rng(0).choice(len(sel), 5000, replace=False)]
    # z = a x + b y + c, robust: two rounds, dropping residuals beyond 3 plane distances
    for _ in range(2):
        a_mat = np.column_stack((sel[:, 0], sel[:, 1], np.ones(len(sel))))
        coef, *_ = np.linalg.lstsq(a_mat, sel[:, 2], rcond=None)
        res = np.abs(a_mat @ coef - sel[:, 2])
        keep = res < 3 * params.plane_distance
        if keep.sum() < 30:
            break
        sel = sel[keep]
    a, b, c = coef
    plane = np.array([-a, -b, 1.0, -c])
    plane /= np.linalg.norm(plane[:3])
    return plane


#: Features of a link between two neighbouring pixels (what the learned link model reads).
LINK_FEATURE_NAMES = (
    "step_rel",  # |depth step| / depth
    "jump_rel",  # step not explained by the neighbouring steps (a slanted plane's are equal) / depth
    "step",  # |depth step| (m)
    "normal_dot",  # |n1 . n2|
    "chroma_diff",
    "bright_diff",
    "dark",  # either pixel too dark for chromaticity
    "depth",  # m
    "up",  # mean |normal z| of the two pixels
    "noise",  # the frame's depth noise: median |second difference of depth| / depth over its links
    "jump_over_noise",  # jump_rel / (noise + NOISE_FLOOR): how unusual the step is for this sensor
)

#: Relative depth noise added to the frame's estimate before dividing by it (a noiseless rendering's
#: second differences are not exactly zero, and a 1 cm step must not look infinitely unusual).
NOISE_FLOOR = 0.0005


def plain_links(feats: np.ndarray) -> np.ndarray:
    """Links with no depth step and no colour change: kept without asking the link model (speed); the
    model is trained on the other links only, the ones it decides."""
    return (feats[:, 0] < 0.004) & (feats[:, 4] < 0.02) & (feats[:, 5] < 0.05)


#: A link scorer: link features (n, LINK_FEATURE_NAMES) -> probability that an object boundary cuts it.
LinkScorer = Callable[[np.ndarray], np.ndarray]


def _links(
    z: np.ndarray,
    rgb: np.ndarray,
    normals: np.ndarray,
    active: np.ndarray,
    params: SegmentParams,
    link_scorer: LinkScorer | None = None,
    samples: list | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Right and down neighbour links among active pixels: (kept_right, kept_down, jump_right, jump_down).

    ``kept`` means no boundary cuts the pair: decided by ``link_scorer`` (a trained model) when given,
    else by the thresholds (depth jump, chromaticity or brightness edge). ``jump`` marks a depth
    discontinuity by the thresholds (a merge feature). With ``samples``, (features, mask) per direction
    are appended for training."""
    f = rgb.astype(np.float32)
    s = f.sum(axis=-1) + 1e-3
    chroma = f / s[..., None]
    bright = np.log(s / 3.0 + 1.0)
    dark = s / 3.0 < params.dark
    noise = depth_noise(z, active)
    out = []
    for axis in (1, 0):
        d = np.diff(z, axis=axis)
        n = d.shape[axis]
        first, second = np.arange(n), np.arange(1, n + 1)
        # the neighbouring steps along the same line: a slanted plane has equal steps, a jump does not
        prev = np.take(d, np.r_[0, np.arange(n - 1)], axis=axis)
        nxt = np.take(d, np.r_[np.arange(1, n), n - 1], axis=axis)
        zmid = np.take(z, first, axis=axis)
        thr = params.depth_edge + params.depth_edge_rel * zmid
        jump = (np.abs(d) > thr) & (np.abs(d - prev) > thr) & (np.abs(d - nxt) > thr)
        jump |= np.abs(d) > 4 * thr  # a large step is a jump even on a steep slope
        dc = np.abs(np.diff(chroma, axis=axis)).sum(axis=-1)
        db = np.abs(np.diff(bright, axis=axis))
        either_dark = np.take(dark, first, axis=axis) | np.take(dark, second, axis=axis)
        both = np.take(active, first, axis=axis) & np.take(active, second, axis=axis)
        if link_scorer is None and samples is None:
            color = ((dc > params.chroma_edge) & ~either_dark) | (db > params.intensity_edge)
            out.append((both & ~jump & ~color, both & jump))
            continue
        n1, n2 = np.take(normals, first, axis=axis)[both], np.take(normals, second, axis=axis)[both]
        zb = np.maximum(zmid[both], 1e-3)
        step = np.abs(d[both])
        feats = np.column_stack(
            (
                step / zb,
                np.minimum(np.abs(d - prev)[both], np.abs(d - nxt)[both]) / zb,
                step,
                np.abs(np.nan_to_num((n1 * n2).sum(axis=1), nan=1.0)),
                dc[both],
                db[both],
                either_dark[both],
                zb,
                np.nan_to_num((np.abs(n1[:, 2]) + np.abs(n2[:, 2])) / 2.0, nan=0.5),
            )
        )
        jump_rel = feats[:, 1]
        feats = np.column_stack((feats, np.full(len(feats), noise), jump_rel / (noise + NOISE_FLOOR)))
        if samples is not None:
            samples.append((feats, both))
        if link_scorer is None:
            color = ((dc > params.chroma_edge) & ~either_dark) | (db > params.intensity_edge)
            out.append((both & ~jump & ~color, both & jump))
            continue
        kept = np.zeros_like(both)
        # links with no depth step and no colour change are kept without asking the model (speed)
        plain = plain_links(feats)
        cut = np.zeros(len(feats), bool)
        if (~plain).any():
            cut[~plain] = np.asarray(link_scorer(feats[~plain])) >= params.link_threshold
        kept[both] = ~cut
        out.append((kept, both & jump))
    (kr, jr), (kd, jd) = out
    return kr, kd, jr, jd


def depth_noise(z: np.ndarray, active: np.ndarray) -> float:
    """The frame's relative depth noise: the median of |second difference| / depth along rows and columns
    over active pixels (steps at object boundaries are few, so the median reads the surfaces)."""
    vals = []
    for axis in (1, 0):
        a = np.take(z, np.arange(z.shape[axis] - 2), axis=axis)
        b = np.take(z, np.arange(1, z.shape[axis] - 1), axis=axis)
        c = np.take(z, np.arange(2, z.shape[axis]), axis=axis)
        ok = (
            np.take(active, np.arange(z.shape[axis] - 2), axis=axis)
            & np.take(active, np.arange(1, z.shape[axis] - 1), axis=axis)
            & np.take(active, np.arange(2, z.shape[axis]), axis=axis)
        )
        vals.append((np.abs(a - 2 * b + c) / np.maximum(b, 1e-3))[ok])
    allv = np.concatenate(vals)
    return float(np.median(allv)) if allv.size else 0.0


def _components(active: np.ndarray, kr: np.ndarray, kd: np.ndarray) -> np.ndarray:
    """Connected components of the kept links; -1 for inactive pixels."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    h, w = active.shape
    idx = np.arange(h * w).reshape(h, w)
    a = np.concatenate((idx[:, :-1][kr], idx[:-1, :][kd]))
    b = np.concatenate((idx[:, 1:][kr], idx[1:, :][kd]))
    graph = coo_matrix((np.ones(a.size, np.int8), (a, b)), shape=(h * w, h * w))
    _, comp = connected_components(graph, directed=False)
    comp = comp.reshape(h, w)
    comp = np.where(active, comp, -1)
    return comp


def _boundary_pixels(active: np.ndarray, kr: np.ndarray, kd: np.ndarray) -> np.ndarray:
    """Active pixels with a cut link to an active neighbour (they line every boundary)."""
    both_r = active[:, :-1] & active[:, 1:]
    both_d = active[:-1, :] & active[1:, :]
    cut_r, cut_d = both_r & ~kr, both_d & ~kd
    edge = np.zeros_like(active)
    edge[:, :-1] |= cut_r
    edge[:, 1:] |= cut_r
    edge[:-1, :] |= cut_d
    edge[1:, :] |= cut_d
    return edge


def sealed_components(
    active: np.ndarray, kr: np.ndarray, kd: np.ndarray, rounds: int = 2, seal: int = 0
) -> np.ndarray:
    """Components that one stray kept link across a boundary cannot join.

    The pixels lining the cuts (and, with ``seal``, the pixels within ``seal`` grid steps of them, so a
    boundary with gaps of up to ``2 seal`` kept links between its cuts still separates) are left out,
    components are formed from the rest, and the lining pixels then join a neighbouring component
    through their kept links (``rounds + seal`` steps); lining pixels that reach none (thin structures
    that are all boundary) form components of their own."""
    edge = _boundary_pixels(active, kr, kd)
    if seal > 0:
        from scipy.ndimage import binary_dilation

        edge = binary_dilation(edge, np.ones((3, 3), bool), iterations=seal) & active
    rounds += seal
    inner = active & ~edge
    comp = _components(inner, kr & inner[:, :-1] & inner[:, 1:], kd & inner[:-1, :] & inner[1:, :])
    for _ in range(rounds):
        todo = edge & (comp < 0)
        if not todo.any():
            break
        new = comp.copy()
        # neighbour labels through kept links, in a fixed order (right, left, down, up)
        src = np.full_like(comp, -1)
        src[:, :-1] = np.where(kr, comp[:, 1:], -1)
        new = np.where(todo & (new < 0) & (src >= 0), src, new)
        src = np.full_like(comp, -1)
        src[:, 1:] = np.where(kr, comp[:, :-1], -1)
        new = np.where(todo & (new < 0) & (src >= 0), src, new)
        src = np.full_like(comp, -1)
        src[:-1, :] = np.where(kd, comp[1:, :], -1)
        new = np.where(todo & (new < 0) & (src >= 0), src, new)
        src = np.full_like(comp, -1)
        src[1:, :] = np.where(kd, comp[:-1, :], -1)
        new = np.where(todo & (new < 0) & (src >= 0), src, new)
        comp = new
    rest = active & (comp < 0)
    if rest.any():
        extra = _components(rest, kr & rest[:, :-1] & rest[:, 1:], kd & rest[:-1, :] & rest[1:, :])
        comp = np.where(rest, extra + comp.max() + 1, comp)
    return comp


def _relabel(labels: np.ndarray, min_pixels: int) -> np.ndarray:
    """Consecutive ids 0..n-1 for segments with at least ``min_pixels`` pixels, -1 elsewhere."""
    flat = labels.reshape(-1)
    valid = flat >= 0
    _, inv, counts = np.unique(flat[valid], return_inverse=True, return_counts=True)
    keep = counts >= min_pixels
    new_id = np.where(keep, np.cumsum(keep) - 1, -1)
    out = np.full(flat.shape, -1, dtype=np.int32)
    out[valid] = new_id[inv]
    return out.reshape(labels.shape)


#: A merge scorer: pair features (n, PAIR_FEATURES) -> probability that each pair is one object.
MergeScorer = Callable[[np.ndarray], np.ndarray]

PAIR_FEATURE_NAMES = (
    "chroma_diff",
    "bright_diff",
    "jump_share",
    "boundary_over_smaller",
    "log_size_small",
    "log_size_large",
    "height_gap",
    "normal_dot",
    "top_diff",
    "centroid_dist",
    "mean_step",
)


def pair_features(seg: Segments, jr: np.ndarray, jd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Adjacent segment pairs ``(n, 2)`` and their features ``(n, len(PAIR_FEATURE_NAMES))``."""
    lab = seg.labels
    n = seg.count
    if n < 2:
        return np.zeros((0, 2), np.int64), np.zeros((0, len(PAIR_FEATURE_NAMES)))
    a = np.concatenate((lab[:, :-1].ravel(), lab[:-1, :].ravel()))
    b = np.concatenate((lab[:, 1:].ravel(), lab[1:, :].ravel()))
    za = np.concatenate((seg.points[:, :-1, 2].ravel(), seg.points[:-1, :, 2].ravel()))
    zb = np.concatenate((seg.points[:, 1:, 2].ravel(), seg.points[1:, :, 2].ravel()))
    jump = np.concatenate((jr.ravel(), jd.ravel()))
    cross = (a >= 0) & (b >= 0) & (a != b)
    if not cross.any():
        return np.zeros((0, 2), np.int64), np.zeros((0, len(PAIR_FEATURE_NAMES)))
    lo, hi = np.minimum(a[cross], b[cross]), np.maximum(a[cross], b[cross])
    key = lo.astype(np.int64) * n + hi
    uniq, inv = np.unique(key, return_inverse=True)
    links = np.bincount(inv).astype(np.float64)
    jumps = np.bincount(inv, weights=jump[cross].astype(np.float64))
    step = np.bincount(inv, weights=np.nan_to_num(np.abs(za[cross] - zb[cross])))
    pairs = np.column_stack((uniq // n, uniq % n))
    st = segment_stats(seg)
    i, j = pairs[:, 0], pairs[:, 1]
    size = st["size"]
    small, large = np.minimum(size[i], size[j]), np.maximum(size[i], size[j])
    feats = np.column_stack(
        (
            np.abs(st["chroma"][i] - st["chroma"][j]).sum(axis=1),
            np.abs(st["bright"][i] - st["bright"][j]),
            jumps / links,
            links / np.sqrt(small),
            np.log(small),
            np.log(large),
            np.abs(st["bottom"][i] - st["bottom"][j]),
            np.abs((st["normal"][i] * st["normal"][j]).sum(axis=1)),
            np.abs(st["top"][i] - st["top"][j]),
            np.linalg.norm(st["centroid"][i] - st["centroid"][j], axis=1),
            step / links,
        )
    )
    return pairs, np.nan_to_num(feats)


def segment_stats(seg: Segments) -> dict[str, np.ndarray]:
    """Per-segment size, mean chromaticity, brightness, mean normal, bottom/top height, centroid."""
    n = seg.count
    lab = seg.labels.reshape(-1)
    m = lab >= 0
    ids = lab[m]
    size = np.bincount(ids, minlength=n).astype(np.float64)
    f = seg.rgb.reshape(-1, 3)[m].astype(np.float64)
    s = f.sum(axis=1) + 1e-3
    chroma = np.column_stack([np.bincount(ids, f[:, k] / s, n) for k in range(3)]) / size[:, None]
    bright = np.bincount(ids, np.log(s / 3.0 + 1.0), n) / size
    nrm = np.nan_to_num(seg.normals.reshape(-1, 3)[m])
    normal = np.column_stack([np.bincount(ids, nrm[:, k], n) for k in range(3)])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-9
    pts = seg.points.reshape(-1, 3)[m]
    centroid = np.column_stack([np.bincount(ids, np.nan_to_num(pts[:, k]), n) for k in range(3)])
    centroid /= size[:, None]
    hgt = np.nan_to_num(seg.height.reshape(-1)[m])
    order = np.argsort(ids, kind="stable")
    starts = np.searchsorted(ids[order], np.arange(n))
    bottom = np.minimum.reduceat(hgt[order], starts)
    top = np.maximum.reduceat(hgt[order], starts)
    return {
        "size": size,
        "chroma": chroma,
        "bright": bright,
        "normal": normal,
        "centroid": centroid,
        "bottom": bottom,
        "top": top,
    }


def rule_merge_score(feats: np.ndarray) -> np.ndarray:
    """The rule used without a trained model: one object when colour matches and depth is continuous."""
    chroma, bright, jump_share = feats[:, 0], feats[:, 1], feats[:, 2]
    same = (chroma < 0.06) & (bright < 0.5) & (jump_share < 0.5)
    return same.astype(np.float64)


def _merge(seg: Segments, pairs: np.ndarray, score: np.ndarray, threshold: float) -> None:
    """Union the pairs scored above ``threshold`` and relabel the segments consecutively."""
    n = seg.count
    parent = np.arange(n)

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for (i, j), s in zip(pairs.tolist(), score.tolist(), strict=True):
        if s > threshold:
            ri, rj = find(i), find(j)
            if ri != rj:
                parent[max(ri, rj)] = min(ri, rj)
    roots = np.array([find(i) for i in range(n)])
    _, new = np.unique(roots, return_inverse=True)
    lab = seg.labels
    seg.labels = np.where(lab >= 0, new[np.maximum(lab, 0)], -1).astype(np.int32)


def segment(
    rgb: np.ndarray,
    depth: np.ndarray,
    camera: Camera,
    params: SegmentParams | None = None,
    merge_scorer: MergeScorer | None = None,
    merge: bool = True,
    link_scorer: LinkScorer | None = None,
    link_samples: list | None = None,
) -> tuple[Segments, tuple[np.ndarray, np.ndarray]]:
    """Segment one frame; returns the segments and the over-segmentation's (pairs, features) before merging.

    ``merge_scorer`` maps pair features to merge probabilities (a trained model); None uses
    :func:`rule_merge_score`. With ``merge=False`` the over-segmentation is returned unmerged (training).
    ``link_scorer`` decides which neighbouring pixels a boundary separates (a trained model; None: the
    thresholds of ``params``); ``link_samples`` collects link features for training (see :func:`_links`).
    """
    params = params or SegmentParams()
    rgb, depth = check_inputs(rgb, depth, camera)
    s = working_stride(params, camera.width)
    z = depth[::s, ::s].astype(np.float64)
    z = np.where(z < params.max_depth, z, 0.0)
    z = _median3(z)
    small_rgb = rgb[::s, ::s]
    points = _world(z, camera, s)
    normals = _normals(points)
    plane = fit_support_plane(points, normals, camera.position, params)
    valid = z > 0
    if plane is not None:
        with np.errstate(invalid="ignore"):
            height = points @ plane[:3] + plane[3]
        height = np.where(valid, height, np.nan)
        support = valid & (np.abs(np.nan_to_num(height, nan=1e9)) <= params.plane_distance)
        active = valid & (np.nan_to_num(height, nan=-1.0) > params.plane_distance)
    else:
        height = np.where(valid, points[..., 2] - np.nanmin(np.where(valid, points[..., 2], np.inf)), np.nan)
        support = np.zeros_like(valid)
        active = valid
    kr, kd, jr, jd = _links(z, small_rgb, normals, active, params, link_scorer, link_samples)
    labels = _relabel(sealed_components(active, kr, kd, seal=params.seal), params.min_pixels)
    seg = Segments(
        stride=s,
        shape=(camera.height, camera.width),
        labels=labels,
        support=support,
        plane=plane,
        points=points,
        rgb=small_rgb,
        normals=normals,
        height=height,
        camera_position=camera.position,
    )
    pairs, feats = pair_features(seg, jr, jd)
    if merge and len(pairs):
        score = merge_scorer(feats) if merge_scorer is not None else rule_merge_score(feats)
        _merge(seg, pairs, np.asarray(score, dtype=np.float64), params.merge_threshold)
    return seg, (pairs, feats)
