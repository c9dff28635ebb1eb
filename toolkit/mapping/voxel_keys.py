"""The key layout of the semantic voxel map: one int64 per (voxel, label), 17 bits per axis
offset by 2^16 (signed indices), 12 label bits; sorted keys put a voxel's labels and a
column's voxels next to each other. Pure functions over key arrays."""

from __future__ import annotations

import numpy as np

AXIS_BITS = 17
LABEL_BITS = 12
OFFSET = 1 << (AXIS_BITS - 1)
AXIS_MASK = (1 << AXIS_BITS) - 1
LABEL_MASK = (1 << LABEL_BITS) - 1
OVERFLOW_LABEL = LABEL_MASK
SHIFT_Z = LABEL_BITS
SHIFT_Y = LABEL_BITS + AXIS_BITS
SHIFT_X = LABEL_BITS + 2 * AXIS_BITS
VOXEL_SHIFT = LABEL_BITS  # key >> VOXEL_SHIFT = voxel key
COLUMN_SHIFT = LABEL_BITS + AXIS_BITS  # key >> COLUMN_SHIFT = (x, y) column key


def pack(ix: np.ndarray, iy: np.ndarray, iz: np.ndarray, label: np.ndarray | int) -> np.ndarray:
    """Pack signed voxel indices and a label index into int64 keys (caller checks range)."""
    return (
        ((ix + OFFSET) << SHIFT_X)
        | ((iy + OFFSET) << SHIFT_Y)
        | ((iz + OFFSET) << SHIFT_Z)
        | np.asarray(label, dtype=np.int64)
    )


def unpack(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(ix, iy, iz, label) of packed keys, indices signed."""
    ix = ((keys >> SHIFT_X) & AXIS_MASK) - OFFSET
    iy = ((keys >> SHIFT_Y) & AXIS_MASK) - OFFSET
    iz = ((keys >> SHIFT_Z) & AXIS_MASK) - OFFSET
    return ix, iy, iz, keys & LABEL_MASK


def winning_entries(keys: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Index of the winning entry of every voxel of the sorted (voxel, label) ``keys``
    (one per voxel, in order): the most votes, ties to the lower label index."""
    if len(keys) == 0:
        return np.zeros(0, dtype=np.int64)
    vk = keys >> VOXEL_SHIFT
    starts = np.flatnonzero(np.concatenate([[True], vk[1:] != vk[:-1]]))
    best = np.maximum.reduceat(counts, starts)
    group = np.repeat(np.arange(len(starts)), np.diff(np.append(starts, len(keys))))
    cand = np.flatnonzero(counts == best[group])  # sorted: lower labels first in a group
    g = group[cand]
    return cand[np.concatenate([[True], g[1:] != g[:-1]])]


def voxel_bounds(voxel_keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Key ranges [lo, hi) holding every label's entry of the sorted distinct voxels."""
    return voxel_keys << VOXEL_SHIFT, (voxel_keys + 1) << VOXEL_SHIFT
