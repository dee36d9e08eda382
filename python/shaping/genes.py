"""Genomes from real values, for optimizers that search real vectors
(CMA-ES, MAP-Elites emitters, ...): each evolvable gene of a stage takes
the level of its grid nearest to its value.

A gene of ``b`` bits with range ``lo..hi`` encodes ``2**b`` levels,
``lo + (hi - lo) * g / (2**b - 1)``, ``g`` written most significant bit
first (``shaping layout`` lists the genes).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._shaping import Program

__all__ = ["bounds", "decode", "encode", "evolvable"]


def evolvable(program: Program, stage: str) -> list[dict[str, Any]]:
    """The genes of ``stage`` that it evolves (not frozen by an earlier stage)."""
    return [g for g in program.layout(stage) if not g["frozen"]]


def bounds(program: Program, stage: str) -> tuple[np.ndarray, np.ndarray]:
    """The lowest and highest value of each evolvable gene."""
    genes = evolvable(program, stage)
    return np.array([g["lo"] for g in genes]), np.array([g["hi"] for g in genes])


def encode(program: Program, stage: str, values: Any, base: Any = None) -> np.ndarray:
    """Genomes of ``stage`` (uint8, shape ``(n, bits)``) whose evolvable
    genes are the levels nearest to ``values`` (shape ``(n, genes)``,
    clipped to each gene's range); the frozen genes are ``base``'s (a
    genome of the stage, e.g. the best of the run of the earlier stages),
    or 0 without one."""
    genes = evolvable(program, stage)
    x = np.atleast_2d(np.asarray(values, dtype=np.float64))
    if x.shape[1] != len(genes):
        raise ValueError(f"values must have {len(genes)} columns (the evolvable genes of `{stage}`), not {x.shape[1]}")
    bits = program.genome_bits(stage)
    out = np.zeros((x.shape[0], bits), dtype=np.uint8)
    if base is not None:
        b = np.asarray(base, dtype=np.uint8)
        if b.shape != (bits,):
            raise ValueError(f"base must be one genome of {bits} bits, not of shape {b.shape}")
        out[:] = b
    for j, g in enumerate(genes):
        top = 2 ** g["bits"] - 1
        span = g["hi"] - g["lo"]
        level = np.rint((np.clip(x[:, j], g["lo"], g["hi"]) - g["lo"]) / span * top) if span else np.zeros(len(x))
        level = level.astype(np.int64)
        for k in range(g["bits"]):
            out[:, g["offset"] + k] = (level >> (g["bits"] - 1 - k)) & 1
    return out


def decode(program: Program, stage: str, genomes: Any) -> np.ndarray:
    """The values of the evolvable genes of ``genomes`` (shape ``(n, bits)``)."""
    genes = evolvable(program, stage)
    g2 = np.atleast_2d(np.asarray(genomes, dtype=np.int64))
    out = np.empty((g2.shape[0], len(genes)))
    for j, g in enumerate(genes):
        level = np.zeros(len(g2), dtype=np.int64)
        for k in range(g["bits"]):
            level = (level << 1) | g2[:, g["offset"] + k]
        out[:, j] = g["lo"] + (g["hi"] - g["lo"]) * level / (2 ** g["bits"] - 1)
    return out
