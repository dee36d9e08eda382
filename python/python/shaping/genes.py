"""Genomes from real values, for optimizers that search real vectors
(CMA-ES, MAP-Elites emitters, ...): each evolvable gene of a stage takes
the level of its grid nearest to its value.

A gene of ``b`` bits with range ``lo..hi`` encodes ``2**b`` levels,
``lo + (hi - lo) * g / (2**b - 1)``, ``g`` written most significant bit
first (``shaping layout`` lists the genes). Encoding and decoding are the
runtime's (``Genome::encode`` and ``Genome::decode`` in Rust): a value
half-way between two levels takes the upper one, as a run's write-back.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._shaping import Program, _decode_genes, _encode_genes

__all__ = ["bounds", "decode", "encode", "evolvable"]


def evolvable(program: Program, stage: str) -> list[dict[str, Any]]:
    """The genes of ``stage`` that it evolves (not frozen by an earlier stage)."""
    return [g for g in program.layout(stage) if not g["frozen"]]


def bounds(program: Program, stage: str) -> tuple[np.ndarray, np.ndarray]:
    """The lowest and highest value of each evolvable gene."""
    genes = evolvable(program, stage)
    return np.array([g["lo"] for g in genes]), np.array([g["hi"] for g in genes])


def encode(
    program: Program,
    stage: str,
    values: Any,
    base: Any = None,
    run: Any = None,
) -> np.ndarray:
    """Genomes of ``stage`` (uint8, shape ``(n, bits)``) whose evolvable
    genes are the levels nearest to ``values`` (shape ``(n, genes)``,
    clipped to each gene's range; ties away from the lower level, as the
    runtime's codec rounds: one codec, in Rust).

    A stage that extends evolved stages has frozen genes: they come from
    ``run`` (a :class:`shaping.Run` or a run directory of this program: the
    chosen best genome, ``best.genome``, of the nearest evolved stage it
    extends) or from ``base`` (one genome of the stage). Without
    either, such a stage raises ValueError, as do NaN values and values of
    the wrong shape."""
    return _encode_genes(program, stage, values, base=base, run=run)


def decode(program: Program, stage: str, genomes: Any) -> np.ndarray:
    """The values of the evolvable genes of ``genomes`` (shape ``(n, bits)``),
    as the runtime decodes them (float32 values, returned as float64)."""
    return _decode_genes(program, stage, genomes)
