"""Mixed ("flying") depth pixels: returns that lie between two surfaces, on neither.

Where a foreground edge stands in front of a farther surface, a time-of-flight pixel
integrates light from both and a stereo matcher smears the edge: such a pixel reads a
depth between the two, and its point floats in the free space behind the edge. In the
voxel map one such point in the obstacle height band makes its column an obstacle, and
the free-space test cannot clear it (its neighbours in the image are the edge itself,
:mod:`sgtool.mapping.free_space`); the labels of the pixels are the edge's, so objects
grow phantom parts and rooms gain phantom walls.

A pixel is *mixed* when, along one of the four image directions (rows, columns,
diagonals), its depth lies strictly between a neighbour ``A`` on one side and a
neighbour ``B`` on the other (each one or two pixels away, so that a run of two mixed
pixels is found as well as a single one), and it continues neither surface. In inverse
depth ``q = 1/z``, which is affine along an image line over any plane, with ``A'`` the
pixel beyond ``A`` (the same for ``B``) and ``k`` the distance of ``A`` from the pixel:

    between:    q_A, q_B on either side of q_p, each more than TOL q_p from it      (M1)
    an edge:    |q_A - q_B| > JUMP q_p                                                (M2)
    on neither: |q_p - (q_A + k (q_A - q_A'))| > TOL q_p, the same for B              (M3)

and it is no part of a surface along the edge:

    alone:      along no image direction in which (M1)-(M3) do not hold is it in a line
                of three pixels (it the middle or an end) whose inverse depths step by
                at most TOL q_p, or are affine within LINE q_p                           (M4)

A pixel on a plane continues its own surface (M3), whether it stands at an occlusion edge
or the plane is seen at a grazing angle; a thin thing nearer than both sides is not
between them (M1); a strip of surface between two others, one or two pixels across (a
cloth on a shelf's edge seen from afar, a box's side face seen nearly edge-on, the rim of
a sphere) continues itself along its length (M4), its ends too, where the depths of mixed
pixels differ from pixel to pixel (they mix the two surfaces in varying parts; mixed
pixels whose depths run evenly all along an edge pass for such a strip). Pixels without
depth (0, not finite) take no part. The test is per frame and pure; the voxel map leaves
mixed pixels out (:attr:`~sgtool.mapping.voxels.VoxelConfig.mixed_pixels`).
"""

from __future__ import annotations

import numpy as np

TOL = 0.03  # (M1), (M3): a share of the pixel's inverse depth (3 cm at 1 m)
LINE = 0.01  # (M4): a share of the pixel's inverse depth (a plane's strip is affine)
JUMP = 0.1  # (M2): the two sides differ by this share of the pixel's inverse depth
DIRECTIONS = ((0, 1), (1, 0), (1, 1), (1, -1))  # (row, column) steps of the four lines
REACH = 3  # pixels the test looks along a line: a neighbour two away and the one beyond
PAIRS = ((1, 1), (1, 2), (2, 1))  # the distances of A and B from the pixel


def mixed_pixels(depth: np.ndarray, tol: float = TOL, jump: float = JUMP) -> np.ndarray:
    """Bool (h, w): the mixed pixels of ``depth`` (m; 0 or not finite = no depth), by
    (M1)-(M4) of the module doc. Only the pixels between the least and the greatest
    inverse depth within two of them, as (M1) and (M2) ask of A and B, are tested."""
    d = np.asarray(depth, dtype=np.float32)
    h, w = d.shape
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.float32(1.0) / d
    q[~(np.isfinite(q) & (d > 0))] = np.nan  # no depth: NaN, which every test leaves out
    pad = np.pad(q, REACH, constant_values=np.nan)
    t = np.float32(tol) * q
    with np.errstate(invalid="ignore"):
        lo, hi = _spread(pad, REACH - 1, h, w)
        cand = (hi - q > t) & (q - lo > t) & (hi - lo > np.float32(jump) * q)
    out = np.zeros((h, w), dtype=bool)
    if not cand.any():
        return out
    pw = w + 2 * REACH
    flat = pad.ravel()
    ys, xs = np.nonzero(cand)
    at0 = (ys + REACH) * pw + xs + REACH  # the candidates in the padded image
    near: dict[tuple[int, int], np.ndarray] = {}

    def at(dy: int, dx: int) -> np.ndarray:  # q of the pixel (dy, dx) away, per candidate
        v = near.get((dy, dx))
        if v is None:
            v = near[(dy, dx)] = flat[at0 + (dy * pw + dx)]
        return v

    qp = flat[at0]
    t = np.float32(tol) * qp
    big = np.float32(jump) * qp
    hits = []  # per image direction: (M1)-(M3) along it
    with np.errstate(invalid="ignore"):
        for sy, sx in DIRECTIONS:
            hit = np.zeros(len(at0), dtype=bool)
            for ka, kb in PAIRS:
                qa, qa2 = at(-ka * sy, -ka * sx), at(-(ka + 1) * sy, -(ka + 1) * sx)
                qb, qb2 = at(kb * sy, kb * sx), at((kb + 1) * sy, (kb + 1) * sx)
                lo1, hi1 = np.fmin(qa, qb), np.fmax(qa, qb)
                hit |= ((qp - lo1 > t) & (hi1 - qp > t) & (hi1 - lo1 > big)  # (M1), (M2)
                        & (np.abs(qp - (qa + ka * (qa - qa2))) > t)  # (M3)
                        & (np.abs(qp - (qb + kb * (qb - qb2))) > t))
            hits.append(hit)
        hit = np.logical_or.reduce(hits)
        if not hit.any():
            return out
        line = np.zeros(len(at0), dtype=bool)  # (M4): in a line of three on its surface
        u = np.float32(LINE) * qp
        for (sy, sx), across in zip(DIRECTIONS, hits, strict=True):
            f1, b1 = at(sy, sx), at(-sy, -sx)
            f2, b2 = at(2 * sy, 2 * sx), at(-2 * sy, -2 * sx)
            fwd, back = np.abs(f1 - qp) <= t, np.abs(b1 - qp) <= t  # level steps
            level = fwd & (back | (np.abs(f2 - f1) <= t)) | back & (np.abs(b2 - b1) <= t)
            even = ((np.abs(f1 + b1 - 2 * qp) <= u)  # affine: the middle of three
                    | (np.abs(qp + f2 - 2 * f1) <= u) | (np.abs(qp + b2 - 2 * b1) <= u))
            line |= ~across & (level | even)
    keep = at0[hit & ~line]
    out[keep // pw - REACH, keep % pw - REACH] = True
    return out


def _spread(pad: np.ndarray, r: int, h: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    """The least and greatest non-NaN value over each pixel's (2 r + 1)^2 square (NaN
    where all are NaN), for an (h, w) image padded by ``REACH`` >= r."""
    o = REACH - r
    rows = pad[o:o + h + 2 * r]  # the rows the squares reach
    lo = rows[:, o:o + w].copy()
    hi = lo.copy()
    for k in range(1, 2 * r + 1):
        np.fmin(lo, rows[:, o + k:o + k + w], out=lo)
        np.fmax(hi, rows[:, o + k:o + k + w], out=hi)
    lo2, hi2 = lo[:h].copy(), hi[:h].copy()
    for k in range(1, 2 * r + 1):
        np.fmin(lo2, lo[k:k + h], out=lo2)
        np.fmax(hi2, hi[k:k + h], out=hi2)
    return lo2, hi2
