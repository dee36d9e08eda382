"""shaping from Python.

Compile ``.bat`` architecture files, evaluate genomes of an evolved stage
with numpy (for any optimizer: CMA-ES, MAP-Elites, ...), and run programs
and experiments like ``shaping run`` and ``shaping experiment``, and drive a
stage's robot from a reinforcement-learning library (``shaping.gym``, with
``gymnasium`` installed), at the speed of the Rust core.

>>> import shaping
>>> program = shaping.compile("examples/khepera.bat")
>>> program.stages
['avoidance', 'navigation', 'collect', 'bigger']
>>> ev = program.evaluator("navigation", seed=0)     # doctest: +SKIP
>>> result = ev.evaluate(genomes)                    # doctest: +SKIP
>>> result["fitness"].shape                          # doctest: +SKIP
(n,)

Errors of shaping raise :class:`ShapingError` (its text is the command
line's message, its ``kind`` says which kind of error it is), or its
subclass of that kind (:class:`CompileError`, :class:`CorruptError`,
:class:`StaleError`, :class:`LockedError`, :class:`EvaluationError`, and
:class:`NotFoundError`, also a ``FileNotFoundError``); wrong
arguments (a stage that does not exist, a genome array of the wrong shape,
dtype or values) raise :class:`ValueError`.
"""

from ._shaping import (
    SQUARE_MM,
    Diagnostic,
    Evaluator,
    Experiment,
    Program,
    Run,
    ShapingError,
    CompileError,
    CorruptError,
    StaleError,
    LockedError,
    EvaluationError,
    NotFoundError,
    check,
    compile,
    experiment,
    run,
)

from typing import TYPE_CHECKING

from . import genes

if TYPE_CHECKING:
    from . import gym as gym


def __getattr__(name: str):
    # `shaping.gym` is loaded on first use (as SciPy loads its submodules),
    # so `import shaping` needs no gymnasium and `shaping.gym.make` works
    # without `import shaping.gym`.
    if name == "gym":
        import importlib

        return importlib.import_module(".gym", __name__)
    raise AttributeError(f"module 'shaping' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), "gym"])


__all__ = [
    "genes",
    "gym",
    "SQUARE_MM",
    "Diagnostic",
    "Evaluator",
    "Experiment",
    "Program",
    "Run",
    "ShapingError",
    "CompileError",
    "CorruptError",
    "StaleError",
    "LockedError",
    "EvaluationError",
    "NotFoundError",
    "check",
    "compile",
    "experiment",
    "run",
]
