"""Published numbers quoted from the SCOUT paper, to print next to ours.

Source: I. Mahdi, M. Cassinelli, F. Despinoy, T. Welschehold, A. Valada, "Relational
Semantic Reasoning on 3D Scene Graphs for Open World Interactive Object Search" (SCOUT),
sec. VI-E, Table VII ("Evaluation results on SymSearch and OmniGibson"), SymSearch columns
(mean ± std over 5 seeds), and sec. VI-G, Table IX ("Performance breakdown to seen vs.
unseen queries"), SymSearch row (SCOUT only). The numbers are copied as printed; the
paper's agents run on SymSearch's InteriorGS scenes with an LLM-distilled prior, ours on
the houses of this benchmark, so the quoted rows show the regime, not a target to match.
"""

from __future__ import annotations

from dataclasses import dataclass

SOURCE = "SCOUT (Mahdi et al.), sec. VI-E, Table VII, SymSearch columns"
SOURCE_IX = "SCOUT (Mahdi et al.), sec. VI-G, Table IX, SymSearch row"


@dataclass(frozen=True)
class QuotedRow:
    """One agent's SymSearch row of SCOUT Table VII: (mean, std) per metric."""

    agent: str  # as printed in the paper
    planner: str | None  # our planner of the same design, None when we have none
    sr: tuple[float, float]
    spl: tuple[float, float]
    steps: tuple[float, float]
    inference_s: tuple[float, float]


TABLE_VII_SYMSEARCH: tuple[QuotedRow, ...] = (
    QuotedRow("Random Agent", "random", (0.381, 0.043), (0.074, 0.012), (45, 2), (0.00, 0.00)),
    QuotedRow("CLIP Similarity (w/o RI)", None, (0.564, 0.010), (0.172, 0.018), (37, 1),
              (0.58, 0.01)),
    QuotedRow("CLIP Similarity", None, (0.650, 0.006), (0.177, 0.019), (33, 1), (0.75, 0.01)),
    QuotedRow("SBERT Similarity (w/o RI)", "sbert-noroom", (0.632, 0.029), (0.180, 0.017),
              (36, 1), (0.08, 0.00)),
    QuotedRow("SBERT Similarity", "sbert", (0.689, 0.007), (0.192, 0.014), (32, 0),
              (1.00, 0.01)),
    QuotedRow("MoMa-LLM", "moma-llm", (0.827, 0.012), (0.255, 0.020), (21, 1),
              (294.52, 20.57)),
    QuotedRow("GODHS", None, (0.906, 0.011), (0.159, 0.016), (20, 0), (39.28, 2.17)),
    QuotedRow("SCOUT (w/o RI, Δ = 0)", None, (0.834, 0.004), (0.215, 0.013), (22, 0),
              (0.08, 0.00)),
    QuotedRow("SCOUT (w/o RI)", "scout-noroom", (0.840, 0.006), (0.264, 0.023), (23, 1),
              (0.09, 0.00)),
    QuotedRow("SCOUT (Δ = 0)", "scout-delta0", (0.871, 0.002), (0.219, 0.012), (20, 0),
              (0.09, 0.00)),
    QuotedRow("SCOUT", "scout", (0.876, 0.002), (0.282, 0.021), (20, 1), (0.08, 0.00)),
)


@dataclass(frozen=True)
class QuotedSplit:
    """SCOUT Table IX, SymSearch: SR and SPL of SCOUT on seen and on unseen queries."""

    agent: str
    planner: str
    seen_sr: float
    seen_spl: float
    unseen_sr: float
    unseen_spl: float


TABLE_IX_SYMSEARCH = QuotedSplit("SCOUT", "scout", 0.859, 0.277, 0.945, 0.300)


def quoted_for(planner: str) -> QuotedRow | None:
    """The Table VII row of the paper's agent that ``planner`` implements, if any."""
    return next((q for q in TABLE_VII_SYMSEARCH if q.planner == planner), None)
