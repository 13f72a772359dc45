"""Controlled degradations of perfect simulator input: depth noise and eroded instance masks."""

from __future__ import annotations

import numpy as np


def add_depth_noise(depth: np.ndarray, sigma: float, rng: np.random.Generator) -> np.ndarray:
    """Depth with zero-mean Gaussian noise of ``sigma`` metres; pixels without a return stay empty."""
    if sigma < 0:
        raise ValueError(f"depth noise sigma must be >= 0, got {sigma}")
    d = np.asarray(depth, dtype=np.float32)
    if sigma == 0:
        return d.copy()
    noisy = d + rng.normal(0.0, sigma, size=d.shape).astype(np.float32)
    return np.where(d > 0, np.maximum(noisy, 1e-3), 0.0).astype(np.float32)


def erode_masks(masks: np.ndarray, pixels: int) -> np.ndarray:
    """Shrink every instance by ``pixels`` (4-neighbourhood): boundary pixels become -1 (no instance).

    Imitates a detector whose masks stop short of object edges; erosion also removes the pixels that
    straddle depth discontinuities, where real sensors and detectors are least reliable.
    """
    if pixels < 0:
        raise ValueError(f"mask erosion must be >= 0 pixels, got {pixels}")
    m = np.asarray(masks).copy()
    for _ in range(pixels):
        keep = m >= 0
        keep[1:, :] &= m[1:, :] == m[:-1, :]
        keep[:-1, :] &= m[:-1, :] == m[1:, :]
        keep[:, 1:] &= m[:, 1:] == m[:, :-1]
        keep[:, :-1] &= m[:, :-1] == m[:, 1:]
        m = np.where(keep, m, -1)
    return m
