"""Type stubs of the Rust extension ``shaping._shaping`` (re-exported by ``shaping``)."""

import os
from typing import Any, Callable, Mapping, Optional, Union, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "ShapingError",
    "CompileError",
    "CorruptError",
    "StaleError",
    "LockedError",
    "EvaluationError",
    "NotFoundError",
    "SQUARE_MM",
    "Diagnostic",
    "Program",
    "Evaluator",
    "Run",
    "Experiment",
    "Stepper",
    "VecStepper",
    "TeamStepper",
    "VecTeamStepper",
    "check",
    "compile",
    "run",
    "experiment",
    "_program_from_json",
    "_evaluator_from_json",
    "_encode_genes",
    "_decode_genes",
]

_PathLike = Union[str, os.PathLike[str]]

SQUARE_MM: float
"""The side (mm) of the squares counted by ``squares_visited``."""

class ShapingError(Exception):
    """An error of shaping: the text is the command line's message.

    ``kind`` is one of "diagnostics", "io", "not_found", "corrupt", "stale",
    "interrupted", "memory", "invalid", "locked", "evaluation", "internal"
    (a bug of shaping); a file with errors also has ``diagnostics`` (a list
    of :class:`Diagnostic`). The error's data, each None where it has none:
    ``path`` (the file or directory it is about), ``operation`` (what
    failed on it: "read", "write", ...), ``problem`` (what is wrong with a
    damaged or stale file), ``holder`` (who holds a locked directory),
    ``setting`` and ``value`` (a setting or an argument, as given).
    """

    kind: str
    diagnostics: list[Diagnostic]
    path: str | None
    operation: str | None
    problem: str | None
    holder: str | None
    setting: str | None
    value: str | None

class CompileError(ShapingError):
    """A file with errors (kind "diagnostics"): ``diagnostics`` has them."""

class CorruptError(ShapingError):
    """A saved file is damaged (kind "corrupt")."""

class StaleError(ShapingError):
    """A saved result belongs to another program, seed or setting (kind "stale")."""

class LockedError(ShapingError):
    """The run directory is in use by another process (kind "locked")."""

class EvaluationError(ShapingError):
    """Evaluation failed: a robot link, a rank of a cluster (kind "evaluation")."""

class NotFoundError(FileNotFoundError, ShapingError):
    """A file or directory that does not exist (kind "not_found"):
    ``filename`` and ``path`` name it, ``errno`` is ``errno.ENOENT``."""

@final
class Diagnostic:
    """One diagnostic of a file, as ``shaping check`` reports it."""

    message: str
    severity: str
    """"error", "warning" or "advice"."""
    code: Optional[str]
    line: Optional[int]
    """1-based line of its first label (None if it points nowhere in the file)."""
    column: Optional[int]
    """1-based column, in characters."""
    help: Optional[str]
    file: str

def check(path: _PathLike) -> list[Diagnostic]:
    """Every diagnostic (errors and warnings) of a ``.bat`` file; [] for a good file.

    A file that cannot be read raises :class:`ShapingError`.
    """

def compile(path: _PathLike) -> Program:
    """Compiles a ``.bat`` file (or loads a ``shaping build`` JSON).

    A file with errors raises :class:`ShapingError` whose text holds the
    diagnostics; warnings of a file that compiles are Python warnings.
    """

@final
class Program:
    """A compiled architecture file."""

    @property
    def name(self) -> str: ...
    @property
    def path(self) -> str: ...
    @property
    def stages(self) -> list[str]:
        """The names of the stages, in order."""
    def genome_bits(self, stage: str) -> int:
        """The number of bits of ``stage``'s genome (the frozen genes of earlier stages included)."""
    def kind(self, stage: str) -> str:
        """"evolve", "train" or "test"."""
    def layout(self, stage: str) -> list[dict[str, Any]]:
        """The genes of ``stage``: the rows of ``shaping layout --format json``."""
    def roles(self, stage: str) -> list[dict[str, Any]]:
        """The roles of ``stage``'s heterogeneous team: ``name``, ``robots``, ``modules`` (module indices) and ``own_fitness`` (the role declares its robots' fitness); [] without roles."""
    def layout_text(self, stage: str) -> str:
        """The table ``shaping layout`` prints."""
    def evaluator(
        self,
        stage: str,
        run: Optional[Union[Run, _PathLike]] = None,
        seed: Optional[int] = None,
        jobs: Optional[int] = None,
    ) -> Evaluator:
        """An evaluator of the genomes of evolved stage ``stage``.

        The weights of training stages come from ``run`` (a :class:`Run` or
        a run directory); without it they are trained afresh, with the
        program's run seed (a warning says so). ``seed``: 0 to 2**64 - 1
        (None: 0). ``jobs``: worker threads, 1 to 1024 (None: one per
        core). Other values raise ValueError naming the argument.
        """
    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled as the compiled program and its path (no file is read again)."""

@final
class Evaluator:
    """Evaluates genomes of one evolved stage as a run evaluates them."""

    @property
    def stage(self) -> str: ...
    @property
    def bits(self) -> int: ...
    @property
    def episodes(self) -> int:
        """The episodes per individual (the stage's ``evaluations``)."""
    @property
    def seed(self) -> int: ...
    def episode_seeds(
        self, individual: Optional[int] = None, generation: Optional[int] = None
    ) -> list[tuple[int, Optional[str]]]:
        """The episodes ``evaluate`` gives individual ``individual`` of generation ``generation``.

        A list of ``(seed, variant)``: the episode seed and the name of
        the world's variant (``None``: the stage's own world), in the order
        they are lived. ``shaping replay FILE --stage S --genome G --seed
        SEED [--variant VARIANT]`` lives one of them and traces it.
        """
    def evaluate(
        self,
        genomes: npt.ArrayLike,
        generation: Optional[int] = None,
        individuals: Optional[npt.ArrayLike] = None,
        measures: Optional[Mapping[str, str]] = None,
    ) -> dict[str, Any]:
        """Evaluates each row of ``genomes`` (shape ``(n, bits)``, 0 and 1, integer or bool dtype).

        Returns arrays of shape ``(n,)``: ``fitness`` (float32, the mean
        over the individual's episodes), ``recharges``, ``grips``,
        ``releases_outside``, ``collisions``, ``placement_failures``
        (uint32, summed over its episodes), ``x``, ``y``, ``heading``
        (float32, the final pose of its last episode, mm and radians),
        ``path_length`` (mm) and ``squares_visited`` (float32, means over
        its episodes). Row ``i`` is evaluated on the episodes a run with
        run seed ``seed`` gives individual ``individuals[i]`` (default
        ``i``) of generation ``generation`` (None: 0) of the stage (pass an
        optimizer's generation for fresh episodes each generation, as a
        run's are), so the same genome, individual, seed and generation
        give the same results however a batch is split. The GIL is
        released while it runs; Ctrl-C stops it within about a second
        (KeyboardInterrupt). A wrong shape, dtype or value raises
        ValueError naming the argument; a batch larger than the memory
        available, MemoryError.

        A team (``robots N`` above 1): the arrays above are the team's
        (``fitness`` its aggregate, the events and collisions summed over
        its robots, ``x`` ... ``squares_visited`` robot 0's), and
        ``robots`` is a dict of each robot's own, arrays of shape
        ``(n, robots)``: ``fitness`` (its own fitness, the mean over the
        episodes), ``x``, ``y``, ``heading``, ``path_length``,
        ``squares_visited``, ``recharges``, ``grips``,
        ``releases_outside``, ``collisions``, combined over the episodes as
        above. One robot: no ``robots`` key.

        ``measures`` maps names to expressions a fitness ``at end`` term of
        the stage may be (its sensors and actuators, ``robot.x`` ...,
        ``team.spread`` ..., ``distance_to(NAME)``), each compiled by the
        compiler's lowering and read at the end of each robot's lives as
        that term is; ``result["measures"][name]`` is its mean over the
        episodes: shape ``(n,)`` for one robot or an expression of the
        team's terms only (every robot reads them alike), else
        ``(n, robots)``. A bad expression raises :class:`CompileError`
        whose ``diagnostics`` point into it (file ``measure NAME``).
        """
    def __reduce__(self) -> tuple[Any, ...]:
        """Pickled as its program with the training stages' weights bound: nothing is trained again."""

@final
class Run:
    """A run directory: the stages it holds and their files."""

    def __new__(cls, out: _PathLike) -> Run:
        """Opens a run directory written by ``shaping run`` or :func:`run`."""
    @property
    def out(self) -> str: ...
    @property
    def seed(self) -> Optional[int]: ...
    @property
    def stages(self) -> list[str]: ...
    @property
    def report(self) -> Optional[str]:
        """The path of ``report.html`` (None if not written)."""
    def stage_dir(self, stage: str) -> str: ...
    def generations(self, stage: str) -> dict[str, np.ndarray]:
        """The columns of the stage's ``generations.csv``: ``best``, ``mean``,
        ``worst`` and ``best_variant_NAME`` floats (NaN where a generation
        did not draw the variant), ``stage`` strings, the others integers."""
    def best_genome(self, stage: str) -> npt.NDArray[np.uint8]:
        """The stage's chosen best genome (``best.genome``), 0 and 1."""
    def population(self, stage: str) -> tuple[npt.NDArray[np.uint8], npt.NDArray[np.float32]]:
        """The last evaluated generation (the checkpoint): genomes ``(population, bits)`` and their fitness."""

def run(
    path: _PathLike,
    out: Optional[_PathLike] = None,
    seed: Optional[int] = None,
    stage: Optional[str] = None,
    set: Optional[Mapping[str, Any]] = None,
    jobs: Optional[int] = None,
    callback: Optional[Callable[[dict[str, Any]], Any]] = None,
    fresh: bool = False,
    report: bool = True,
) -> Run:
    """Runs ``path`` like ``shaping run`` into ``out`` (default ``runs/<file stem>``).

    ``set`` maps ``STAGE.SECTION.FIELD`` to one value each (``--set``).
    ``callback`` is called with one dict per event (``event``: "evolve_start",
    "generation", "evolved", "trained", "tested", "warning", ...); an
    exception in it stops the run (resumable) and is raised. Ctrl-C stops
    the run after the generation under way, leaves it resumable and raises
    KeyboardInterrupt.
    """

@final
class Experiment:
    """An experiment's directory: its runs and its summaries."""

    @property
    def out(self) -> str: ...
    @property
    def seeds(self) -> list[int]: ...
    @property
    def runs(self) -> list[Run]:
        """Every run, point after point, seed after seed."""
    @property
    def summary(self) -> dict[str, Any]:
        """``summary.json``: per point, its settings and per stage the median, range, mean and sd over the seeds."""
    @property
    def summary_text(self) -> str:
        """The summary the command line prints."""
    def medians(self) -> list[dict[str, Any]]:
        """The statistics of ``summary.json`` (``tests``): per stage, measure and
        group (the experiment, or a point of a sweep), a record with ``stage``,
        ``measure``, ``group``, ``seeds``, ``median`` and its bootstrap 95%
        interval ``low`` .. ``high``."""
    def tests(self) -> list[dict[str, Any]]:
        """The tests of ``summary.json`` between a sweep's points: per stage,
        measure and pair of points ``a`` and ``b``, a record with ``u``,
        ``p_value`` (two-sided Mann-Whitney U), ``p_holm`` (Holm's correction,
        with more than two points; else None), ``a12`` (Vargha-Delaney: the
        probability that a seed of ``a`` has the larger value), ``size``,
        ``method`` and ``no_test`` (why there is no test, else None). Empty for
        an experiment of one point."""
    @property
    def reports(self) -> list[str]: ...

def experiment(
    path: _PathLike,
    seeds: int = 5,
    first_seed: int = 1,
    out: Optional[_PathLike] = None,
    stage: Optional[str] = None,
    set: Optional[Mapping[str, Any]] = None,
    criterion: Optional[Mapping[str, float]] = None,
    jobs: Optional[int] = None,
    callback: Optional[Callable[[dict[str, Any]], Any]] = None,
    fresh: bool = False,
    report: bool = True,
) -> Experiment:
    """Runs ``path`` over ``seeds`` seeds like ``shaping experiment`` (default
    ``runs/<file stem>/experiment``) and writes the summaries.

    ``set`` maps ``STAGE.SECTION.FIELD`` to a value or a list of values (a
    sweep over the cartesian product); ``criterion`` maps a stage to a
    fitness (the generation at which the best reaches it is reported).
    The rest as :func:`run`.
    """

@final
class Stepper:
    """One robot of a stage driven one action at a time (see ``shaping.gym``)."""

    def __new__(cls, program: Program, stage: str, keep_path: bool = False) -> Stepper: ...
    @property
    def observation_names(self) -> list[str]: ...
    @property
    def action_names(self) -> list[str]: ...
    @property
    def action_bounds(self) -> tuple[list[float], list[float]]: ...
    @property
    def life(self) -> int: ...
    def reset(self, seed: int) -> npt.NDArray[np.float32]: ...
    def step(
        self, action: npt.NDArray[np.float32]
    ) -> tuple[npt.NDArray[np.float32], float, bool, bool, dict[str, Any]]: ...
    def render(self) -> npt.NDArray[np.uint8]: ...

@final
class VecStepper:
    """Many robots of a stage stepped together in Rust (see ``shaping.gym.make_vec``)."""

    def __new__(cls, program: Program, stage: str, num_envs: int, jobs: Optional[int] = None) -> VecStepper:
        """``num_envs``: a positive integer (else ValueError; more robots
        than the memory available holds: MemoryError); ``jobs``: 1 to 1024."""
    @property
    def num_envs(self) -> int: ...
    def reset(self, seed: int) -> npt.NDArray[np.float32]: ...
    def step(
        self, actions: npt.NDArray[np.float32]
    ) -> tuple[
        npt.NDArray[np.float32], npt.NDArray[np.float32], npt.NDArray[np.bool_], npt.NDArray[np.bool_]
    ]: ...

@final
class TeamStepper:
    """A stage's team driven one action at a time (see ``shaping.gym.make_parallel``)."""

    def __new__(cls, program: Program, stage: str, keep_path: bool = False) -> TeamStepper:
        """A stage with one robot raises :class:`ShapingError` (use :class:`Stepper`)."""
    @property
    def agents(self) -> list[str]:
        """Each robot's agent name: ``ROLE_K`` (its index in its role) or ``robot_I``."""
    @property
    def roles(self) -> list[int]:
        """Each robot's role, an index in ``Program.roles`` (0 without roles)."""
    @property
    def observation_names(self) -> list[str]: ...
    @property
    def action_names(self) -> list[str]: ...
    @property
    def action_bounds(self) -> tuple[list[float], list[float]]: ...
    @property
    def life(self) -> int: ...
    def reset(self, seed: int) -> npt.NDArray[np.float32]:
        """The first observations, shape ``(robots, observation)``."""
    def step(
        self, actions: npt.NDArray[np.float32]
    ) -> tuple[
        npt.NDArray[np.float32],
        npt.NDArray[np.float32],
        npt.NDArray[np.bool_],
        npt.NDArray[np.bool_],
        dict[str, Any],
    ]:
        """One action of every robot whose life goes on (row i of ``actions``, shape ``(robots, action)``)."""
    def render(self) -> npt.NDArray[np.uint8]: ...

@final
class VecTeamStepper:
    """Many worlds of a stage's team stepped together in Rust (see ``shaping.gym.make_parallel_vec``)."""

    def __new__(cls, program: Program, stage: str, num_envs: int, jobs: Optional[int] = None) -> VecTeamStepper:
        """``num_envs``: a positive integer (else ValueError); ``jobs``: 1 to 1024; a stage with one robot raises :class:`ShapingError`."""
    @property
    def num_envs(self) -> int: ...
    @property
    def agents(self) -> list[str]: ...
    def reset(self, seed: int) -> npt.NDArray[np.float32]:
        """The first observations, shape ``(num_envs, robots, observation)``."""
    def step(
        self, actions: npt.NDArray[np.float32]
    ) -> tuple[
        npt.NDArray[np.float32], npt.NDArray[np.float32], npt.NDArray[np.bool_], npt.NDArray[np.bool_]
    ]: ...

def _program_from_json(json: str, path: _PathLike) -> Program: ...
def _evaluator_from_json(json: str, index: int, seed: int, jobs: Optional[int] = None) -> Evaluator: ...
def _encode_genes(
    program: Program,
    stage: str,
    values: npt.ArrayLike,
    base: Optional[npt.ArrayLike] = None,
    run: Optional[Union[Run, _PathLike]] = None,
) -> npt.NDArray[np.uint8]: ...
def _decode_genes(program: Program, stage: str, genomes: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
