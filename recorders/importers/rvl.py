"""RVL depth decompression (Wilson, "Fast Lossless Depth Image Compression", ISS 2017), as
``compressed_depth_image_transport`` writes it (format ``"16UC1; compressedDepth rvl"``).

The stream is little-endian 32-bit words of 4-bit nibbles, most significant nibble first.
A nibble carries 3 bits of a value (least significant group first) and a continuation bit
(0x8). The values come as runs: the number of zero pixels, the number of non-zero pixels,
then one zig-zag coded delta per non-zero pixel (from the previous non-zero pixel, 16-bit
wrap-around), until every pixel is decoded.

:func:`decode_rvl` is a pure numpy function: the nibbles and values are unpacked with array
operations, only the runs (far fewer than the pixels) are walked in Python.
"""

from __future__ import annotations

import numpy as np

from sgtool.errors import SgtoolError


def _values(data: bytes) -> np.ndarray:
    """All variable-length values of the stream, in order (int64)."""
    n_words = len(data) // 4
    words = np.frombuffer(data[: n_words * 4], dtype="<u4")
    shifts = np.arange(28, -4, -4, dtype=np.uint32)
    nib = ((words[:, None] >> shifts[None, :]) & 0xF).astype(np.int64).ravel()
    last = (nib & 0x8) == 0  # a value ends at a nibble without the continuation bit
    ends = np.flatnonzero(last)
    if len(ends) == 0:
        return np.zeros(0, np.int64)
    nib = nib[: ends[-1] + 1]
    group = np.concatenate([[0], np.cumsum(last[: ends[-1]])])  # value index of each nibble
    starts = np.concatenate([[0], ends[:-1] + 1])
    pos = np.arange(len(nib)) - starts[group]  # position of the nibble within its value
    if pos.max(initial=0) > 10:
        raise ValueError("a value longer than 33 bits")
    return np.bincount(group, weights=(nib & 0x7) << (3 * pos), minlength=len(ends)).astype(
        np.int64)


def decode_rvl(data: bytes, width: int, height: int) -> np.ndarray:
    """The (height, width) uint16 image of an RVL stream; :class:`SgtoolError` when the
    stream is shorter than the image or its runs overrun it."""
    n = int(width) * int(height)
    try:
        vals = _values(bytes(data))
    except ValueError as e:
        raise SgtoolError(f"RVL depth: corrupt stream ({e})") from e
    out_pos: list[np.ndarray] = []
    deltas: list[np.ndarray] = []
    i = done = 0
    while done < n:
        if i + 1 >= len(vals):
            raise SgtoolError(f"RVL depth: the stream ends after {done} of {n} pixels")
        zeros, nonzeros = int(vals[i]), int(vals[i + 1])
        i += 2
        if done + zeros + nonzeros > n or i + nonzeros > len(vals):
            raise SgtoolError(f"RVL depth: a run overruns the {width}x{height} image")
        done += zeros
        out_pos.append(np.arange(done, done + nonzeros))
        deltas.append(vals[i: i + nonzeros])
        i += nonzeros
        done += nonzeros
    out = np.zeros(n, np.uint16)
    if out_pos:
        pos = np.concatenate(out_pos)
        z = np.concatenate(deltas)
        delta = (z >> 1) ^ -(z & 1)  # zig-zag
        out[pos] = (np.cumsum(delta) & 0xFFFF).astype(np.uint16)
    return out.reshape(int(height), int(width))
