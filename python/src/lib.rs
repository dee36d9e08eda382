//! The `shaping._shaping` extension module: shaping's compiler, engine and
//! simulator for Python. The `shaping` package (`python/python/shaping/`) re-exports
//! it; its docstrings and type stubs are there.
//!
//! Everything goes through the engine (`shaping_engine`): `load` to read a
//! file, `shaping_engine::Engine` to run it, `descriptors` to evaluate genomes, so the
//! results and the messages are the command line's.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt, PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use shaping_engine::descriptors::{self, Described};
use shaping_engine::diag::ErrorFormat;
use shaping_engine::run::{self as engine_run, Event, Observer, RunOptions};
use shaping_engine::Engine;
use shaping_engine::{load, rundir, sweep, ErrorKind};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::{Program as Compiled, StageRun};

create_exception!(
    _shaping,
    ShapingError,
    PyException,
    "An error of shaping (a file with errors, a run that cannot resume, ...): its text is the command line's message, `kind` says which kind of error it is."
);

create_exception!(
    _shaping,
    CompileError,
    ShapingError,
    "A file with errors: `diagnostics` has them (a list of Diagnostic)."
);
create_exception!(
    _shaping,
    CorruptError,
    ShapingError,
    "A saved file is damaged: it does not parse, its checksum does not match, or it disagrees with the file it came from."
);
create_exception!(
    _shaping,
    StaleError,
    ShapingError,
    "A saved result belongs to another program, seed or setting than this run's."
);
create_exception!(_shaping, LockedError, ShapingError, "The run directory is in use by another process.");
create_exception!(
    _shaping,
    EvaluationError,
    ShapingError,
    "Evaluation failed (a robot link, a rank of a cluster)."
);

/// `shaping.NotFoundError`: a file or directory that does not exist, both
/// a `FileNotFoundError` and a `ShapingError` (made once, at import).
static NOT_FOUND: pyo3::sync::PyOnceLock<Py<pyo3::types::PyType>> = pyo3::sync::PyOnceLock::new();

fn not_found_type(py: Python<'_>) -> PyResult<&Bound<'_, pyo3::types::PyType>> {
    let t = NOT_FOUND.get_or_try_init(py, || -> PyResult<_> {
        let builtins = py.import("builtins")?;
        let bases = pyo3::types::PyTuple::new(
            py,
            [builtins.getattr("FileNotFoundError")?, py.get_type::<ShapingError>().into_any()],
        )?;
        let dict = pyo3::types::PyDict::new(py);
        dict.set_item("__module__", "shaping")?;
        dict.set_item(
            "__doc__",
            "A file or directory that does not exist: a FileNotFoundError and a ShapingError.",
        )?;
        // Its text stays the command line's message: an OSError with a
        // `filename` would print `[Errno 2] ...: 'PATH'` instead.
        let text = py.eval(c"lambda self: str(self.args[0]) if self.args else ''", None, None)?;
        dict.set_item("__str__", text)?;
        let made = builtins.getattr("type")?.call1(("NotFoundError", bases, dict))?;
        Ok(made.cast_into::<pyo3::types::PyType>()?.unbind())
    })?;
    Ok(t.bind(py))
}

fn kind_name(kind: ErrorKind) -> &'static str {
    match kind {
        ErrorKind::Diagnostics => "diagnostics",
        ErrorKind::Io => "io",
        ErrorKind::NotFound => "not_found",
        ErrorKind::Corrupt => "corrupt",
        ErrorKind::Stale => "stale",
        ErrorKind::Interrupted => "interrupted",
        ErrorKind::Memory => "memory",
        ErrorKind::Invalid => "invalid",
        ErrorKind::Locked => "locked",
        ErrorKind::Evaluation => "evaluation",
        ErrorKind::Internal => "internal",
        _ => "other",
    }
}

/// The engine error's data on its exception: `path` (the file or
/// directory), `operation`, `problem` (of a damaged or stale file),
/// `holder` (of a lock), `setting` and `value` (of a setting or an
/// argument), each `None` where the error has none; a `NotFoundError`'s
/// `filename` and `errno` as a `FileNotFoundError`'s.
fn set_data(py: Python<'_>, err: &PyErr, e: &shaping_engine::Error) -> PyResult<()> {
    let value = err.value(py);
    let path = e.path().map(|p| p.display().to_string());
    value.setattr("path", path.clone())?;
    value.setattr("operation", e.operation())?;
    value.setattr("problem", e.problem())?;
    value.setattr("holder", e.holder())?;
    value.setattr("setting", e.setting().map(|(key, _)| key))?;
    value.setattr("value", e.setting().and_then(|(_, v)| v))?;
    if e.kind() == ErrorKind::NotFound {
        value.setattr("filename", path)?;
        value.setattr("errno", py.import("errno")?.getattr("ENOENT")?)?;
    }
    Ok(())
}

/// The `ShapingError` (the subclass of its kind) with the engine error's
/// message, kind and data ([`set_data`]); a file that does not exist
/// raises `NotFoundError`.
fn shaping_error(py: Python<'_>, e: &shaping_engine::Error) -> PyErr {
    let message = e.message().to_string();
    let err = match e.kind() {
        ErrorKind::Diagnostics => CompileError::new_err(message),
        ErrorKind::Corrupt => CorruptError::new_err(message),
        ErrorKind::Stale => StaleError::new_err(message),
        ErrorKind::Locked => LockedError::new_err(message),
        ErrorKind::Evaluation => EvaluationError::new_err(message),
        ErrorKind::NotFound => match not_found_type(py) {
            Ok(t) => PyErr::from_type(t.clone(), (message,)),
            Err(e) => e,
        },
        _ => ShapingError::new_err(message),
    };
    let _ = err.value(py).setattr("kind", kind_name(e.kind()));
    if let Err(failed) = set_data(py, &err, e) {
        return failed;
    }
    err
}

/// The error a run, an experiment or a setting raises: `ValueError` for a
/// setting or an argument that cannot be used (`ErrorKind::Invalid`: an
/// unknown `set` key, a bad value, `seeds=0`; with the error's data,
/// [`set_data`]), else `ShapingError`.
fn engine_error(py: Python<'_>, e: &shaping_engine::Error) -> PyErr {
    match e.kind() {
        ErrorKind::Invalid => {
            let err = value_error(e.message());
            set_data(py, &err, e).err().unwrap_or(err)
        }
        _ => shaping_error(py, e),
    }
}

fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// An integer argument `name` from 0 to `max`, or a ValueError naming it
/// (a negative, a too large or a non-integer value, e.g. `1.5`).
fn count_arg(value: &Bound<'_, PyAny>, name: &str, max: u64) -> PyResult<u64> {
    let bad = || {
        let shown = value.repr().map(|r| r.to_string()).unwrap_or_else(|_| "?".into());
        value_error(format!("error: {name} must be an integer from 0 to {max}, not {shown}"))
    };
    if value.is_instance_of::<pyo3::types::PyBool>() {
        return Err(bad());
    }
    match value.extract::<u64>() {
        Ok(v) if v <= max => Ok(v),
        _ => Err(bad()),
    }
}

// The most worker threads a call takes (the command line's `--jobs` limit).
use shaping_engine::run::MAX_JOBS;

/// `jobs`: None (one thread per core) or 1 to [`MAX_JOBS`].
fn jobs_arg(jobs: Option<&Bound<'_, PyAny>>) -> PyResult<Option<usize>> {
    let Some(jobs) = jobs.filter(|j| !j.is_none()) else { return Ok(None) };
    match count_arg(jobs, "jobs", MAX_JOBS as u64) {
        Ok(0) | Err(_) => Err(value_error(format!(
            "error: jobs must be an integer from 1 to {MAX_JOBS} (None: one thread per core), not {}",
            jobs.repr().map(|r| r.to_string()).unwrap_or_else(|_| "?".into())
        ))),
        Ok(n) => Ok(Some(n as usize)),
    }
}

/// A rayon pool of `jobs` threads (None: one per core), rebuilt in a
/// process forked from the one that built it: a pool's threads are not in
/// a forked child (`multiprocessing`'s default start on Linux), where the
/// pool would wait for them forever.
struct Pool {
    jobs: Option<usize>,
    built: Mutex<Option<(u32, Arc<rayon::ThreadPool>)>>,
}

impl Pool {
    fn new(jobs: Option<usize>) -> PyResult<Pool> {
        let pool = Pool { jobs, built: Mutex::new(None) };
        pool.get()?;
        Ok(pool)
    }

    /// Runs `f` on the pool; on the calling thread when the pool has one
    /// thread or the work is one piece (`one`), where handing it to a pool
    /// thread would cost two context switches a call (tens of us: more
    /// than a step of 100 robots).
    fn run<T: Send>(&self, one: bool, f: impl FnOnce() -> T + Send) -> PyResult<T> {
        if one || self.jobs == Some(1) {
            return Ok(f());
        }
        Ok(self.get()?.install(f))
    }

    /// The pool of this process.
    fn get(&self) -> PyResult<Arc<rayon::ThreadPool>> {
        let pid = std::process::id();
        let mut built = self.built.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((owner, pool)) = built.as_ref() {
            if *owner == pid {
                return Ok(pool.clone());
            }
        }
        // Forked: the parent's pool has no threads here; it is left alone
        // (dropping it would signal threads that do not exist).
        if let Some(parent) = built.take() {
            std::mem::forget(parent);
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.jobs.unwrap_or(0))
            .build()
            .map_err(|e| ShapingError::new_err(format!("error: cannot start worker threads: {e}")))?;
        let pool = Arc::new(pool);
        *built = Some((pid, pool.clone()));
        Ok(pool)
    }
}

/// Refuses, before allocating, a call that would need `need` bytes where
/// fewer are available (the machine's, the control group's or the address
/// space's, as `run` checks): a MemoryError with the estimate and what to do.
fn check_room(need: u64, what: &str, instead: &str) -> PyResult<()> {
    load::check_room(need, what, instead).map_err(|e| PyMemoryError::new_err(e.message().to_string()))
}

/// The most robot-actions [`interruptible`] runs on the caller's thread
/// (about 30 ms of `examples/khepera.bat`'s navigation on one core).
const INLINE_ACTIONS: u64 = 100_000;

/// Runs `work` on another thread with the GIL released, checking Python's
/// signals every 50 ms meanwhile: on Ctrl-C (or any signal whose handler
/// raises) it sets the flag `work` is given, waits for `work` to return
/// (it checks the flag between episodes) and raises the handler's
/// exception (KeyboardInterrupt), keeping nothing of the work. Work of at
/// most [`INLINE_ACTIONS`] robot-actions (`actions`) runs on the caller's
/// thread instead: a thread costs more than such work, which ends within
/// a few tens of milliseconds anyway.
fn interruptible<T: Send>(
    py: Python<'_>,
    actions: u64,
    work: impl FnOnce(&AtomicBool) -> T + Send,
) -> PyResult<T> {
    let stop = AtomicBool::new(false);
    if actions <= INLINE_ACTIONS {
        return Ok(py.detach(|| work(&stop)));
    }
    let done = AtomicBool::new(false);
    /// Says the work is over, even if it panicked.
    struct Done<'a>(&'a AtomicBool, std::thread::Thread);
    impl Drop for Done<'_> {
        fn drop(&mut self) {
            self.0.store(true, Ordering::Release);
            self.1.unpark();
        }
    }
    let me = std::thread::current();
    std::thread::scope(|scope| {
        let (stop, done) = (&stop, &done);
        let worker = scope.spawn(move || {
            let _done = Done(done, me);
            work(stop)
        });
        let panicked =
            || PyRuntimeError::new_err("error: the evaluation failed (a bug of shaping: please report it)");
        while !done.load(Ordering::Acquire) {
            py.detach(|| {
                if !done.load(Ordering::Acquire) {
                    std::thread::park_timeout(Duration::from_millis(50));
                }
            });
            if done.load(Ordering::Acquire) {
                break;
            }
            if let Err(e) = py.check_signals() {
                stop.store(true, Ordering::Relaxed);
                let _ = py.detach(|| worker.join());
                return Err(e);
            }
        }
        py.detach(|| worker.join()).map_err(|_| panicked())
    })
}

fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    py.import("warnings")?
        .call_method1("warn", (message, py.get_type::<pyo3::exceptions::PyUserWarning>(), 2))?;
    Ok(())
}

fn json_to_py<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (value.to_string(),))
}

// ------------------------------------------------------------------ check

/// One diagnostic of a file: what `shaping check` prints.
#[pyclass(module = "shaping", frozen, get_all)]
#[derive(Clone)]
struct Diagnostic {
    /// The message.
    message: String,
    /// "error", "warning" or "advice".
    severity: String,
    /// The diagnostic's code (`shaping::...`), if any.
    code: Option<String>,
    /// Line (1-based) of its first label, if it points into the file.
    line: Option<usize>,
    /// Column (1-based, in characters) of its first label.
    column: Option<usize>,
    /// What to do about it, if the compiler says.
    help: Option<String>,
    /// The file.
    file: String,
}

#[pymethods]
impl Diagnostic {
    fn __repr__(&self) -> String {
        let at = match (self.line, self.column) {
            (Some(l), Some(c)) => format!(":{l}:{c}"),
            _ => String::new(),
        };
        format!("<Diagnostic {}{at}: {}: {}>", self.file, self.severity, self.message)
    }

    fn __str__(&self) -> String {
        let at = match (self.line, self.column) {
            (Some(l), Some(c)) => format!(":{l}:{c}"),
            _ => String::new(),
        };
        let help = self.help.as_ref().map(|h| format!(" (help: {h})")).unwrap_or_default();
        format!("{}{at}: {}: {}{help}", self.file, self.severity, self.message)
    }
}

/// Python's diagnostics of the engine's: a file's errors and warnings (the
/// `related` of its diagnostics), or the one diagnostic when it has none
/// (a file that is not UTF-8).
fn diagnostics_from(d: &shaping_engine::diag::Diagnosed, file: &str) -> Vec<Diagnostic> {
    let items: Vec<&shaping_engine::diag::Diagnosed> =
        if d.related.is_empty() { vec![d] } else { d.related.iter().collect() };
    items
        .into_iter()
        .map(|d| Diagnostic {
            message: d.message.clone(),
            severity: d.severity.into(),
            code: d.code.clone(),
            line: d.line,
            column: d.column,
            help: d.help.clone(),
            file: file.to_string(),
        })
        .collect()
}

/// The diagnostics of `path`, or the engine's error for a file that cannot
/// be read.
fn diagnostics_of(path: &Path) -> Result<Vec<Diagnostic>, shaping_engine::Error> {
    let file = path.display().to_string();
    match load::load_program(path, ErrorFormat::Plain) {
        Ok((_, None)) => Ok(Vec::new()),
        Ok((_, Some(w))) => Ok(diagnostics_from(&w.data, &file)),
        Err(e) => match e.diagnosed() {
            Some(d) => Ok(diagnostics_from(d, &file)),
            // A built program (`.json`) that cannot be used: its message.
            None if !matches!(e.kind(), ErrorKind::Io | ErrorKind::NotFound) => Ok(vec![Diagnostic {
                message: e.message().to_string(),
                severity: "error".into(),
                code: None,
                line: None,
                column: None,
                help: None,
                file,
            }]),
            None => Err(e),
        },
    }
}

/// Every diagnostic of the `.bat` file `path` (errors and warnings), as
/// `shaping check` reports them, with 1-based lines and columns; an empty
/// list for a good file. A file that cannot be read raises ShapingError.
#[pyfunction]
fn check(py: Python<'_>, path: PathBuf) -> PyResult<Vec<Diagnostic>> {
    py.detach(|| diagnostics_of(&path)).map_err(|e| shaping_error(py, &e))
}

// ------------------------------------------------------------------ compile

/// A compiled architecture file: its stages and their genomes.
#[pyclass(module = "shaping", frozen)]
struct Program {
    program: Arc<Compiled>,
    path: PathBuf,
}

fn stage_index(program: &Compiled, stage: &str) -> PyResult<usize> {
    load::stage_index(program, Some(stage)).map_err(|e| value_error(e.message()))
}

/// Reads and compiles `path` (a `.bat` file or a `shaping build` JSON).
fn load(py: Python<'_>, path: &Path) -> PyResult<Compiled> {
    let loaded = py.detach(|| load::load_program(path, ErrorFormat::Plain));
    match loaded {
        Ok((program, warnings)) => {
            if let Some(w) = warnings {
                warn(py, w.text.trim_end())?;
            }
            Ok(program)
        }
        Err(e) => Err(compile_error(py, &e, &path.display().to_string())),
    }
}

/// The `CompileError` of diagnostics about `file`, with its `diagnostics`.
fn compile_error(py: Python<'_>, e: &shaping_engine::Error, file: &str) -> PyErr {
    let err = shaping_error(py, e);
    if let Some(d) = e.diagnosed() {
        let _ = err.value(py).setattr("diagnostics", diagnostics_from(d, file));
    }
    err
}

#[pymethods]
impl Program {
    /// The program's name.
    #[getter]
    fn name(&self) -> String {
        self.program.name.clone()
    }

    /// The file it was compiled from.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// The names of the stages, in order.
    #[getter]
    fn stages(&self) -> Vec<String> {
        self.program.stages.iter().map(|s| s.name.clone()).collect()
    }

    /// The number of bits of `stage`'s genome (frozen genes of earlier stages included).
    fn genome_bits(&self, stage: &str) -> PyResult<u32> {
        Ok(self.program.stages[stage_index(&self.program, stage)?].layout.bits)
    }

    /// What kind of stage `stage` is: "evolve", "train" or "test".
    fn kind(&self, stage: &str) -> PyResult<&'static str> {
        Ok(match self.program.stages[stage_index(&self.program, stage)?].run {
            StageRun::Evolve(_) => "evolve",
            StageRun::Train { .. } => "train",
            StageRun::Test { .. } => "test",
        })
    }

    /// The genes of `stage`'s genome, one dict per gene: the rows of
    /// `shaping layout --format json` (`gene`, `offset`, `bits`, `stage`
    /// and `module` by name, `team_role` in a team with roles, `what`,
    /// `part`, `kind`, `input`, `lo`, `hi`, `frozen`, ...).
    fn layout<'py>(&self, py: Python<'py>, stage: &str) -> PyResult<Bound<'py, PyAny>> {
        let rows = shaping_compiler::layout_rows(&self.program, stage_index(&self.program, stage)?);
        let genes = serde_json::to_value(&rows)
            .map_err(|e| ShapingError::new_err(format!("error: cannot serialise the layout: {e}")))?;
        json_to_py(py, &genes)
    }

    /// The roles of `stage`'s heterogeneous team, in order, one dict per
    /// role: `name`, `robots` (robot 0 plays the first role), `modules`,
    /// the indices of its modules (a gene of `layout` whose `team_role` is
    /// the role's name is the role's), and `own_fitness`, whether the role
    /// declares the fitness of its robots. Empty for a team of clones or
    /// one robot.
    fn roles<'py>(&self, py: Python<'py>, stage: &str) -> PyResult<Bound<'py, PyAny>> {
        let st = &self.program.stages[stage_index(&self.program, stage)?];
        let roles: Vec<serde_json::Value> = st
            .roles
            .iter()
            .enumerate()
            .map(|(r, role)| {
                let modules: Vec<usize> = st.role_modules(r).collect();
                serde_json::json!({
                    "name": role.name,
                    "robots": role.robots,
                    "modules": modules,
                    "own_fitness": role.fitness.is_some(),
                })
            })
            .collect();
        json_to_py(py, &serde_json::Value::Array(roles))
    }

    /// The text `shaping layout` prints for `stage`.
    fn layout_text(&self, stage: &str) -> PyResult<String> {
        Ok(shaping_compiler::render_layout(&self.program, stage_index(&self.program, stage)?))
    }

    /// An evaluator of the genomes of evolved stage `stage`: see `Evaluator.evaluate`.
    ///
    /// `run`: a `Run` or a run directory whose training stages' weights
    /// (`trained.json`) are used; without it, training stages are trained
    /// afresh with the program's run seed, and a warning says so. `seed`:
    /// the seed the episodes derive from (0 to 2**64 - 1). `jobs`: worker
    /// threads (1 to 1024; None: one per core). A stage that does not exist
    /// or is not evolved, or a bad `seed` or `jobs`, raises ValueError.
    #[pyo3(signature = (stage, run=None, seed=None, jobs=None))]
    fn evaluator(
        &self,
        py: Python<'_>,
        stage: &str,
        run: Option<&Bound<'_, PyAny>>,
        seed: Option<&Bound<'_, PyAny>>,
        jobs: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Evaluator> {
        let seed = match seed {
            Some(s) if !s.is_none() => count_arg(s, "seed", u64::MAX)?,
            _ => 0,
        };
        let jobs = jobs_arg(jobs)?;
        let index = stage_index(&self.program, stage)?;
        if !matches!(self.program.stages[index].run, StageRun::Evolve(_)) {
            return Err(value_error(format!(
                "error: stage `{stage}` is not evolved (it is a {} stage): an evaluator evaluates the genomes of an evolved stage",
                if matches!(self.program.stages[index].run, StageRun::Train { .. }) { "training" } else { "test" }
            )));
        }
        let run_dir = run_dir_arg(run)?;
        let mut program = (*self.program).clone();
        let uses_training = engine_run::chain(&program, index)
            .iter()
            .any(|&i| matches!(program.stages[i].run, StageRun::Train { .. }));
        let training_seed = engine_run::run_seed(&program, None);
        let collected = Collect::default();
        let bound = py.detach(|| {
            engine_run::bind_training(&mut program, run_dir.as_deref(), training_seed, &collected)
        });
        let trained = bound.map_err(|e| shaping_error(py, &e))?;
        for w in collected.warnings.into_inner().unwrap_or_default() {
            warn(py, &w)?;
        }
        if uses_training && run_dir.is_none() && !trained.is_empty() {
            warn(
                py,
                &format!(
                    "stage `{stage}` uses weights of a training stage and no run was given: the training stages were trained afresh with seed {training_seed} (pass run= a run directory to use its weights)"
                ),
            )?;
        }
        let st = &program.stages[index];
        shaping_runtime::controller::validate(st, &Genome::zeros(st.layout.bits as usize))
            .map_err(|e| ShapingError::new_err(format!("error: stage `{}` cannot run: {e}", st.name)))?;
        Ok(Evaluator { program: Arc::new(program), index, seed, jobs, pool: Pool::new(jobs)? })
    }

    /// Pickled as its program (the compiled `Program`, as `shaping build`
    /// writes it) and its path: unpickling does not read the file again.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String, PathBuf))> {
        let py = slf.py();
        let this = slf.get();
        let json = serde_json::to_string(&*this.program)
            .map_err(|e| ShapingError::new_err(format!("error: cannot serialise the program: {e}")))?;
        Ok((py.import("shaping._shaping")?.getattr("_program_from_json")?, (json, this.path.clone())))
    }

    fn __repr__(&self) -> String {
        let stages: Vec<String> =
            self.program.stages.iter().map(|s| format!("{} ({} bits)", s.name, s.layout.bits)).collect();
        format!("<Program {} from {}: {}>", self.program.name, self.path.display(), stages.join(", "))
    }
}

/// Compiles the `.bat` file `path` (or loads a program written by `shaping
/// build`). A file with errors raises ShapingError whose text holds the
/// diagnostics (and whose `diagnostics` lists them); the warnings of a file
/// that compiles are Python warnings.
#[pyfunction]
fn compile(py: Python<'_>, path: PathBuf) -> PyResult<Program> {
    let program = load(py, &path)?;
    Ok(Program { program: Arc::new(program), path })
}

/// A program pickled by `Program.__reduce__` (the JSON of `shaping build`).
#[pyfunction]
fn _program_from_json(py: Python<'_>, json: &str, path: PathBuf) -> PyResult<Program> {
    let program =
        load::parse_built(json.as_bytes(), &path.display().to_string()).map_err(|e| shaping_error(py, &e))?;
    Ok(Program { program: Arc::new(program), path })
}

/// An evaluator pickled by `Evaluator.__reduce__`: its program with the
/// training stages' weights bound, so nothing is trained again.
#[pyfunction]
#[pyo3(signature = (json, index, seed, jobs=None))]
fn _evaluator_from_json(
    py: Python<'_>,
    json: &str,
    index: usize,
    seed: u64,
    jobs: Option<usize>,
) -> PyResult<Evaluator> {
    let program =
        load::parse_built(json.as_bytes(), "the pickled evaluator").map_err(|e| shaping_error(py, &e))?;
    if !matches!(program.stages.get(index).map(|s| &s.run), Some(StageRun::Evolve(_))) {
        return Err(value_error(format!(
            "error: the pickled evaluator's stage {index} is not an evolved stage"
        )));
    }
    Ok(Evaluator { program: Arc::new(program), index, seed, jobs, pool: Pool::new(jobs)? })
}

/// `run`: a `Run` (its `out`) or a run directory that exists.
fn run_dir_arg(run: Option<&Bound<'_, PyAny>>) -> PyResult<Option<PathBuf>> {
    let Some(r) = run.filter(|r| !r.is_none()) else { return Ok(None) };
    let dir: PathBuf = match r.getattr("out") {
        Ok(out) => out.extract()?,
        Err(_) => r
            .extract()
            .map_err(|_| value_error("error: run must be a `Run` or the path of a run directory"))?,
    };
    if !dir.is_dir() {
        return Err(value_error(format!("error: the run directory `{}` does not exist", dir.display())));
    }
    Ok(Some(dir))
}

/// An observer that keeps the warnings.
#[derive(Default)]
struct Collect {
    warnings: Mutex<Vec<String>>,
}

impl Observer for Collect {
    fn event(&self, event: Event<'_>) {
        if let Event::Warning(w) = event {
            if let Ok(mut v) = self.warnings.lock() {
                v.push(w);
            }
        }
    }
}

// ------------------------------------------------------------------ evaluate

/// Evaluates genomes of one evolved stage as a run evaluates them.
#[pyclass(module = "shaping", frozen)]
struct Evaluator {
    program: Arc<Compiled>,
    index: usize,
    seed: u64,
    jobs: Option<usize>,
    pool: Pool,
}

/// The memory an evaluation takes per genome of `bits` bits besides its
/// bits: the genome's `Vec`, its individual's index, its result and the
/// result's row in the arrays returned.
const EVALUATED_BYTES: u64 =
    (std::mem::size_of::<Genome>() + 8 + std::mem::size_of::<Described>() + 11 * 4) as u64;

/// The rows of a 2-D array of 0/1 of `bits` columns, or a ValueError; a
/// MemoryError, before anything is allocated, for more rows than the
/// memory available holds.
fn genomes_of(genomes: &Bound<'_, PyAny>, bits: usize, what: &str) -> PyResult<Vec<Genome>> {
    let py = genomes.py();
    let array = if genomes.is_instance_of::<numpy::PyUntypedArray>() {
        genomes.clone()
    } else {
        py.import("numpy")?.call_method1("asarray", (genomes,))?
    };
    let untyped =
        array.cast::<numpy::PyUntypedArray>().map_err(|_| value_error("genomes must be a numpy array"))?;
    let shape = untyped.shape().to_vec();
    if shape.len() != 2 || shape[1] != bits {
        return Err(value_error(format!(
            "genomes must be an array of shape (n, {bits}) (one row of the stage's {bits} bits per individual), not {}",
            match shape.len() {
                1 => format!("({},)", shape[0]),
                _ => format!("({})", shape.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", ")),
            }
        )));
    }
    let need = (shape[0] as u64).saturating_mul(bits as u64 + EVALUATED_BYTES);
    check_room(need, &format!("{what} {} genomes", shape[0]), "pass them in smaller batches")?;
    macro_rules! rows {
        ($($t:ty),*) => {
            $(
                if let Ok(a) = array.extract::<PyReadonlyArray2<'_, $t>>() {
                    let view = a.as_array();
                    let mut out = Vec::with_capacity(shape[0]);
                    for (i, row) in view.rows().into_iter().enumerate() {
                        let mut g = Vec::with_capacity(bits);
                        for (j, &v) in row.iter().enumerate() {
                            #[allow(clippy::unnecessary_cast, irrefutable_let_patterns)]
                            let b = if v == (0 as $t) { 0 } else if v == (1 as $t) { 1 } else {
                                return Err(value_error(format!(
                                    "genomes must hold 0 and 1 only: row {i}, column {j} holds {v}"
                                )));
                            };
                            g.push(b);
                        }
                        out.push(Genome { bits: g });
                    }
                    return Ok(out);
                }
            )*
        };
    }
    if let Ok(a) = array.extract::<PyReadonlyArray2<'_, bool>>() {
        return Ok(a
            .as_array()
            .rows()
            .into_iter()
            .map(|r| Genome { bits: r.iter().map(|&b| u8::from(b)).collect() })
            .collect());
    }
    rows!(u8, i8, i16, u16, i32, u32, i64, u64);
    let dtype = array.getattr("dtype").and_then(|d| d.str()).map(|s| s.to_string()).unwrap_or_default();
    Err(value_error(format!(
        "genomes must be an array of integers or booleans (0 and 1), not of dtype {dtype}; e.g. `genomes.astype(numpy.uint8)` after rounding"
    )))
}

/// The most robots of a stage's team, its variants' included.
fn team_size(stage: &shaping_runtime::program::Stage) -> usize {
    let variants = stage.variants.iter().flat_map(|v| &v.list).map(|v| v.world.robots);
    variants.chain([stage.world.robots]).max().unwrap_or(1).max(1) as usize
}

/// Whether a measure reads anything of a robot's own (a sensor, an
/// actuator, `robot.x`, `distance_to(...)`) rather than only the team's
/// terms (`team.spread` ...), which every robot reads alike.
fn per_robot(e: &shaping_runtime::expr::Expr) -> bool {
    use shaping_runtime::expr::Op;
    use shaping_runtime::state::{ST_SPREAD, TEAM_SLOTS};
    e.ops.iter().any(|op| match *op {
        Op::Chan(_) | Op::Prev(_) | Op::Act(_) => true,
        Op::State(s) => !(ST_SPREAD..ST_SPREAD + TEAM_SLOTS).contains(&usize::from(s)),
        _ => false,
    })
}

/// An array of shape (n, team) of `f` of each individual's robots.
fn columns<'py, T: numpy::Element + Copy>(
    py: Python<'py>,
    results: &[Described],
    team: usize,
    f: &dyn Fn(&Described, usize) -> T,
) -> PyResult<Bound<'py, numpy::PyArray2<T>>> {
    let flat: Vec<T> = results.iter().flat_map(|d| (0..team).map(move |i| f(d, i))).collect();
    PyArray1::from_vec(py, flat).reshape([results.len(), team])
}

/// `evaluate`'s `robots`: each robot's descriptors, events and fitness,
/// arrays of shape (n, team) (a robot an individual's episodes lacked:
/// NaN, and 0 events).
fn robot_arrays<'py>(py: Python<'py>, results: &[Described], team: usize) -> PyResult<Bound<'py, PyDict>> {
    use descriptors::Robot;
    let out = PyDict::new(py);
    type Column<T> = (&'static str, fn(&Robot) -> T);
    let floats: [Column<f32>; 6] = [
        ("fitness", |r| r.fitness),
        ("x", |r| r.descriptors.x),
        ("y", |r| r.descriptors.y),
        ("heading", |r| r.descriptors.heading),
        ("path_length", |r| r.descriptors.path_length),
        ("squares_visited", |r| r.descriptors.squares_visited),
    ];
    for (name, f) in floats {
        out.set_item(name, columns(py, results, team, &|d, i| d.robots.get(i).map_or(f32::NAN, f))?)?;
    }
    let counts: [Column<u32>; 4] = [
        ("recharges", |r| r.events.recharges),
        ("grips", |r| r.events.grips),
        ("releases_outside", |r| r.events.releases_outside),
        ("collisions", |r| r.collisions),
    ];
    for (name, f) in counts {
        out.set_item(name, columns(py, results, team, &|d, i| d.robots.get(i).map_or(0, f))?)?;
    }
    Ok(out)
}

/// The measures of one `evaluate` call: the stage with the targets they
/// add, their names and their code.
struct Measures {
    stage: shaping_runtime::program::Stage,
    names: Vec<String>,
    exprs: Vec<shaping_runtime::expr::Expr>,
}

/// The most measures one call takes.
const MAX_MEASURES: usize = 256;

/// What an `Evaluator` is pickled as: its program's JSON (the training
/// stages' weights bound), its stage's index, its seed and its jobs.
type EvaluatorState = (String, usize, u64, Option<usize>);

/// The largest individual index `individuals` may hold.
const MAX_INDIVIDUAL: u64 = u32::MAX as u64;

/// `individuals`: one integer index per row (default: the rows' order).
fn individuals_of(individuals: Option<&Bound<'_, PyAny>>, rows: usize) -> PyResult<Vec<u64>> {
    let Some(individuals) = individuals.filter(|x| !x.is_none()) else {
        return Ok((0..rows as u64).collect());
    };
    let py = individuals.py();
    let np = py.import("numpy")?;
    let array = np.call_method1("asarray", (individuals,))?;
    let shape: Vec<usize> = array.getattr("shape")?.extract()?;
    if shape != [rows] {
        return Err(value_error(format!(
            "error: individuals must be an array of shape ({rows},) (one index per row of genomes), not {}",
            array.getattr("shape")?.repr()?
        )));
    }
    if rows == 0 {
        return Ok(Vec::new());
    }
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    let values: Vec<i128> = match kind.as_str() {
        "i" => {
            let a = array.call_method1("astype", ("int64",))?;
            let a = a.extract::<numpy::PyReadonlyArray1<'_, i64>>()?;
            a.as_array().iter().map(|&v| i128::from(v)).collect()
        }
        "u" => {
            let a = array.call_method1("astype", ("uint64",))?;
            let a = a.extract::<numpy::PyReadonlyArray1<'_, u64>>()?;
            a.as_array().iter().map(|&v| i128::from(v)).collect()
        }
        _ => {
            return Err(value_error(format!(
                "error: individuals must be integers (each row's index in its generation), not of dtype {}",
                array.getattr("dtype")?.str()?
            )))
        }
    };
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            u64::try_from(v).ok().filter(|&v| v <= MAX_INDIVIDUAL).ok_or_else(|| {
                value_error(format!(
                    "error: individuals must be indices from 0 to {MAX_INDIVIDUAL} (an individual's index in its generation): row {i} holds {v}"
                ))
            })
        })
        .collect()
}

#[pymethods]
impl Evaluator {
    /// The stage's name.
    #[getter]
    fn stage(&self) -> String {
        self.program.stages[self.index].name.clone()
    }

    /// The number of bits of a genome (the columns of `evaluate`'s array).
    #[getter]
    fn bits(&self) -> u32 {
        self.program.stages[self.index].layout.bits
    }

    /// The episodes each individual is evaluated on (the stage's `evaluations`).
    #[getter]
    fn episodes(&self) -> u32 {
        match &self.program.stages[self.index].run {
            StageRun::Evolve(e) => e.evaluations.max(1),
            _ => 1,
        }
    }

    /// The seed the episode seeds derive from.
    #[getter]
    fn seed(&self) -> u64 {
        self.seed
    }

    /// The episodes `evaluate` gives individual `individual` of generation
    /// `generation`: a list of `(seed, variant)`, the episode seed and the
    /// name of the world's variant (`None`: the stage's own world), in the
    /// order they are lived. `shaping replay FILE --stage S --genome G
    /// --seed SEED [--variant VARIANT]` lives one of them and traces it.
    /// A bad `individual` or `generation` raises ValueError.
    #[pyo3(signature = (individual=None, generation=None))]
    fn episode_seeds(
        &self,
        individual: Option<&Bound<'_, PyAny>>,
        generation: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<(u64, Option<String>)>> {
        let arg = |v: Option<&Bound<'_, PyAny>>, name, max| match v {
            Some(v) if !v.is_none() => count_arg(v, name, max),
            _ => Ok(0),
        };
        let individual = arg(individual, "individual", MAX_INDIVIDUAL)? as usize;
        let generation = arg(generation, "generation", u64::from(u32::MAX))? as u32;
        let stage = &self.program.stages[self.index];
        let name = |k: usize| stage.variants.as_ref().and_then(|v| v.list.get(k)).map(|v| v.name.clone());
        Ok(descriptors::episodes(stage, self.index, self.seed, generation, individual)
            .into_iter()
            .map(|e| (e.seed, e.variant.and_then(name)))
            .collect())
    }

    /// Evaluates each row of `genomes`, an array of shape (n, bits) of 0
    /// and 1 (an integer or bool dtype), as the stage's evolution does: its
    /// `evaluations` episodes of its `actions` actions, in its world,
    /// learning on, with the GIL released, on the evaluator's threads.
    ///
    /// Returns a dict of arrays of shape (n,): `fitness` (float32, the mean
    /// over the episodes); `recharges`, `grips`, `releases_outside`,
    /// `collisions`, `placement_failures` (uint32, summed over them); `x`,
    /// `y`, `heading` (float32, the final pose of the last episode, mm from
    /// the arena's south-west corner and radians); `path_length` (mm) and
    /// `squares_visited` (the 50 mm squares the body centre was in), means
    /// over the episodes.
    ///
    /// Row i is evaluated on the episodes a run with run seed `seed` gives
    /// individual `individuals[i]` (default: i) of generation `generation`
    /// of the stage (an optimizer passes its generation's number for fresh
    /// episodes each generation, as a run's are), so the same genome,
    /// individual, seed and generation give the same results whatever the
    /// threads and however a batch is split. A wrong shape, dtype or value
    /// raises ValueError naming the argument; a batch larger than the
    /// memory available, MemoryError. Ctrl-C stops it within about a
    /// second (KeyboardInterrupt; nothing is returned).
    #[pyo3(signature = (genomes, generation=None, individuals=None, measures=None))]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        genomes: &Bound<'py, PyAny>,
        generation: Option<&Bound<'py, PyAny>>,
        individuals: Option<&Bound<'py, PyAny>>,
        measures: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let generation = match generation {
            Some(g) if !g.is_none() => count_arg(g, "generation", u64::from(u32::MAX))? as u32,
            _ => 0,
        };
        let measured = self.measures(py, measures)?;
        let stage = measured.as_ref().map_or(&self.program.stages[self.index], |m| &m.stage);
        let (names, exprs) = measured.as_ref().map_or((&[][..], &[][..]), |m| (&m.names[..], &m.exprs[..]));
        let genomes = genomes_of(genomes, stage.layout.bits as usize, "evaluating")?;
        let individuals = individuals_of(individuals, genomes.len())?;
        let (index, seed) = (self.index, self.seed);
        let pool = self.pool.get()?;
        let actions = (genomes.len() as u64)
            .saturating_mul(descriptors::episodes(stage, index, seed, generation, 0).len() as u64)
            .saturating_mul(u64::from(descriptors::actions(stage)))
            .saturating_mul(u64::from(stage.world.robots.max(1)));
        let results = interruptible(py, actions, |stop| {
            pool.install(|| {
                genomes
                    .par_iter()
                    .zip(individuals.par_iter())
                    .map(|(g, &i)| {
                        let episodes = descriptors::episodes(stage, index, seed, generation, i as usize);
                        descriptors::evaluate_measured(stage, g, &episodes, exprs, stop)
                    })
                    .collect::<Option<Vec<Described>>>()
            })
        })?
        .ok_or_else(|| PyKeyboardInterrupt::new_err("interrupted: the evaluation was stopped"))?;
        let out = PyDict::new(py);
        let f32s = |f: &dyn Fn(&Described) -> f32| results.iter().map(f).collect::<Vec<f32>>();
        let u32s = |f: &dyn Fn(&Described) -> u32| results.iter().map(f).collect::<Vec<u32>>();
        out.set_item("fitness", PyArray1::from_vec(py, f32s(&|d| d.evaluation.fitness)))?;
        out.set_item("recharges", PyArray1::from_vec(py, u32s(&|d| d.evaluation.events.recharges)))?;
        out.set_item("grips", PyArray1::from_vec(py, u32s(&|d| d.evaluation.events.grips)))?;
        out.set_item(
            "releases_outside",
            PyArray1::from_vec(py, u32s(&|d| d.evaluation.events.releases_outside)),
        )?;
        out.set_item("collisions", PyArray1::from_vec(py, u32s(&|d| d.collisions)))?;
        out.set_item("x", PyArray1::from_vec(py, f32s(&|d| d.descriptors.x)))?;
        out.set_item("y", PyArray1::from_vec(py, f32s(&|d| d.descriptors.y)))?;
        out.set_item("heading", PyArray1::from_vec(py, f32s(&|d| d.descriptors.heading)))?;
        out.set_item("path_length", PyArray1::from_vec(py, f32s(&|d| d.descriptors.path_length)))?;
        out.set_item("squares_visited", PyArray1::from_vec(py, f32s(&|d| d.descriptors.squares_visited)))?;
        out.set_item(
            "placement_failures",
            PyArray1::from_vec(py, u32s(&|d| d.evaluation.placement_failures)),
        )?;
        let team = team_size(stage);
        if team > 1 {
            out.set_item("robots", robot_arrays(py, &results, team)?)?;
        }
        if !names.is_empty() {
            let m = PyDict::new(py);
            for (k, (name, e)) in names.iter().zip(exprs).enumerate() {
                let value = |d: &Described, i: usize| {
                    d.robots.get(i).and_then(|r| r.measures.get(k)).copied().unwrap_or(f32::NAN)
                };
                if team > 1 && per_robot(e) {
                    m.set_item(name, columns(py, &results, team, &|d, i| value(d, i))?)?;
                } else {
                    m.set_item(name, PyArray1::from_vec(py, f32s(&|d| value(d, 0))))?;
                }
            }
            out.set_item("measures", m)?;
        }
        Ok(out)
    }

    /// Pickled as its program with the training stages' weights bound, its
    /// stage, seed and jobs: the unpickled evaluator gives the same results
    /// and trains nothing.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, EvaluatorState)> {
        let py = slf.py();
        let this = slf.get();
        let json = serde_json::to_string(&*this.program)
            .map_err(|e| ShapingError::new_err(format!("error: cannot serialise the program: {e}")))?;
        Ok((
            py.import("shaping._shaping")?.getattr("_evaluator_from_json")?,
            (json, this.index, this.seed, this.jobs),
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "<Evaluator of stage `{}` ({} bits, {} episodes each, seed {})>",
            self.stage(),
            self.bits(),
            self.episodes(),
            self.seed
        )
    }
}

impl Evaluator {
    /// `measures`: None, or a dict of names to expressions, each compiled
    /// as a fitness `at end` term of the stage (the compiler's lowering); a
    /// bad expression raises CompileError naming the measure, a bad
    /// argument ValueError.
    fn measures(&self, py: Python<'_>, measures: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Measures>> {
        let Some(measures) = measures.filter(|m| !m.is_none()) else { return Ok(None) };
        let dict = measures.cast::<PyDict>().map_err(|_| {
            value_error("error: measures must be a dict of names to expressions, e.g. {\"x\": \"robot.x\"}")
        })?;
        if dict.len() > MAX_MEASURES {
            return Err(value_error(format!(
                "error: measures holds {} expressions, at most {MAX_MEASURES} are taken in one call",
                dict.len()
            )));
        }
        let mut stage = self.program.stages[self.index].clone();
        let (mut names, mut exprs) = (Vec::new(), Vec::new());
        for (k, v) in dict.iter() {
            let name: String =
                k.extract().map_err(|_| value_error("error: measures: the names must be strings"))?;
            let text: String = v.extract().map_err(|_| {
                value_error(format!(
                    "error: measure `{name}` must be an expression as a string (e.g. \"robot.x\")"
                ))
            })?;
            let file = format!("measure {name}");
            let e = shaping_compiler::measure(&mut stage, &file, &text).map_err(|d| {
                let trimmed = text.trim();
                let rendered = shaping_engine::diag::Rendered::new(&d, ErrorFormat::Plain, &file, trimmed);
                compile_error(py, &shaping_engine::Error::diagnostics(rendered), &file)
            })?;
            names.push(name);
            exprs.push(e);
        }
        Ok(Some(Measures { stage, names, exprs }))
    }
}

// ------------------------------------------------------------------ genes

/// The genome whose frozen genes `genes.encode` copies: `base`'s, or those
/// of the best genome of the run `run` of the stage's nearest evolved
/// ancestor (its `best.genome`, the run's chosen best); all zeros for a
/// stage without frozen genes. Neither for a stage with frozen genes, or
/// both, is a ValueError.
fn frozen_template(
    program: &Compiled,
    index: usize,
    base: Option<&Bound<'_, PyAny>>,
    run: Option<&Bound<'_, PyAny>>,
) -> PyResult<Genome> {
    let st = &program.stages[index];
    let bits = st.layout.bits as usize;
    let frozen = st.layout.genes.iter().filter(|g| g.frozen).count();
    let base = base.filter(|b| !b.is_none());
    let run_dir = run_dir_arg(run)?;
    match (base, run_dir) {
        (Some(_), Some(_)) => Err(value_error(
            "error: pass run= (the frozen genes of its best genome) or base= (a genome), not both",
        )),
        (Some(b), None) => {
            let py = b.py();
            let array = py.import("numpy")?.call_method1("atleast_2d", (b,))?;
            let rows = genomes_of(&array, bits, "reading").map_err(|e| {
                value_error(format!("error: base must be one genome of stage `{}` ({bits} bits of 0 and 1): {}", st.name, e.value(py)))
            })?;
            match <[Genome; 1]>::try_from(rows) {
                Ok([g]) => Ok(g),
                Err(rows) => Err(value_error(format!(
                    "error: base must be one genome of stage `{}` ({bits} bits), not {} rows",
                    st.name,
                    rows.len()
                ))),
            }
        }
        (None, Some(dir)) => {
            let mut genome = Genome::zeros(bits);
            let Some(parent) = program.evolved_above(index) else {
                return Ok(genome);
            };
            let pst = &program.stages[parent];
            let py = run.expect("a run directory comes from run=").py();
            let ran = load::load_built(&rundir::program_path(&dir)).map_err(|e| shaping_error(py, &e))?;
            if ran.stage(&pst.name).map(|(_, s)| &s.layout) != Some(&pst.layout) {
                return Err(value_error(format!(
                    "error: the run `{}` has no stage `{}` with this program's genes: run= must be a run of this program",
                    dir.display(),
                    pst.name
                )));
            }
            let best = rundir::read_best(&rundir::stage_dir(&dir, &pst.name)).map_err(|e| shaping_error(py, &e))?;
            let kept = pst.layout.bits as usize;
            if best.bits.len() != kept {
                return Err(ShapingError::new_err(format!(
                    "error: the best genome of `{}` in `{}` has {} bits, its layout {kept}",
                    pst.name,
                    dir.display(),
                    best.bits.len()
                )));
            }
            genome.bits[..kept].copy_from_slice(&best.bits);
            Ok(genome)
        }
        (None, None) if frozen > 0 => Err(value_error(format!(
            "error: stage `{}` has {frozen} frozen genes (of the stages it extends): pass run= a run of them \
             (the frozen genes are those of its best genome of the stage extended) or base= a genome of the stage",
            st.name
        ))),
        (None, None) => Ok(Genome::zeros(bits)),
    }
}

/// `genes.encode`: genomes of `stage` whose evolvable genes are the levels
/// nearest to `values` (the runtime's codec, `Genome::encode`, as a run's
/// write-back encodes) and whose frozen genes come from `base` or `run`.
#[pyfunction]
#[pyo3(signature = (program, stage, values, base=None, run=None))]
fn _encode_genes<'py>(
    py: Python<'py>,
    program: &Program,
    stage: &str,
    values: &Bound<'py, PyAny>,
    base: Option<&Bound<'py, PyAny>>,
    run: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, numpy::PyArray2<u8>>> {
    let index = stage_index(&program.program, stage)?;
    let st = &program.program.stages[index];
    let genes: Vec<&shaping_runtime::program::Gene> = st.layout.genes.iter().filter(|g| !g.frozen).collect();
    let np = py.import("numpy")?;
    let x = np
        .call_method1("atleast_2d", (np.call_method1("asarray", (values,))?,))?
        .call_method1("astype", ("float64",))
        .map_err(|_| value_error("error: values must be an array of numbers"))?;
    let x = x.extract::<PyReadonlyArray2<'_, f64>>().map_err(|_| {
        value_error(format!(
            "error: values must be an array of shape (n, {}) (the evolvable genes of `{stage}`)",
            genes.len()
        ))
    })?;
    let shape = x.shape().to_vec();
    if shape[1] != genes.len() {
        return Err(value_error(format!(
            "error: values must have {} columns (the evolvable genes of `{stage}`), not {}",
            genes.len(),
            shape[1]
        )));
    }
    let bits = st.layout.bits as usize;
    let need = (shape[0] as u64).saturating_mul(bits as u64 + 8 * genes.len() as u64);
    check_room(need, &format!("encoding {} genomes", shape[0]), "pass them in smaller batches")?;
    let x = x.as_array();
    if let Some(((i, j), _)) = x.indexed_iter().find(|(_, v)| v.is_nan()) {
        return Err(value_error(format!(
            "error: values must be numbers: row {i}, column {j} (gene at bit {}) is NaN",
            genes[j].offset
        )));
    }
    let template = frozen_template(&program.program, index, base, run)?;
    let mut out = Vec::with_capacity(shape[0] * bits);
    for row in x.rows() {
        let mut genome = template.clone();
        for (g, &v) in genes.iter().zip(row.iter()) {
            genome.encode(g, v as f32);
        }
        out.extend_from_slice(&genome.bits);
    }
    PyArray1::from_vec(py, out).reshape([shape[0], bits])
}

/// `genes.decode`: the values of the evolvable genes of `genomes` (the
/// runtime's codec, `Genome::decode`, the values a controller uses).
#[pyfunction]
fn _decode_genes<'py>(
    py: Python<'py>,
    program: &Program,
    stage: &str,
    genomes: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let index = stage_index(&program.program, stage)?;
    let st = &program.program.stages[index];
    let array = py.import("numpy")?.call_method1("atleast_2d", (genomes,))?;
    let rows = genomes_of(&array, st.layout.bits as usize, "decoding")?;
    let genes: Vec<&shaping_runtime::program::Gene> = st.layout.genes.iter().filter(|g| !g.frozen).collect();
    let out: Vec<f64> = rows.iter().flat_map(|r| genes.iter().map(move |g| f64::from(r.decode(g)))).collect();
    PyArray1::from_vec(py, out).reshape([rows.len(), genes.len()])
}

// ------------------------------------------------------------------ step

fn invalid(e: &shaping_engine::Error) -> PyErr {
    value_error(e.message())
}

/// The stage `stage` of `program` for a robot driven from outside.
fn stepped_stage(program: &Program, stage: &str) -> PyResult<Arc<shaping_runtime::program::Stage>> {
    Ok(Arc::new(program.program.stages[stage_index(&program.program, stage)?].clone()))
}

/// One robot of a stage driven one action at a time (`shaping.gym.make`
/// wraps it in a Gymnasium environment).
#[pyclass(module = "shaping")]
struct Stepper {
    inner: shaping_engine::stepper::Stepper,
    obs: Vec<f32>,
}

#[pymethods]
impl Stepper {
    /// A robot of stage `stage` of `program`; `keep_path` keeps the poses
    /// of each life for `render`.
    #[new]
    #[pyo3(signature = (program, stage, keep_path=false))]
    fn new(program: &Program, stage: &str, keep_path: bool) -> PyResult<Stepper> {
        let mut inner = shaping_engine::stepper::Stepper::new(stepped_stage(program, stage)?)
            .map_err(|e| Python::attach(|py| shaping_error(py, &e)))?;
        inner.keep_path(keep_path);
        let obs = vec![0.0; inner.spaces().channels.len()];
        Ok(Stepper { inner, obs })
    }

    /// The names of the observation's elements (the declared sensors).
    #[getter]
    fn observation_names(&self) -> Vec<String> {
        self.inner.spaces().observation.clone()
    }

    /// The names of the action's elements.
    #[getter]
    fn action_names(&self) -> Vec<String> {
        self.inner.spaces().action.clone()
    }

    /// The lowest and highest value of each action element.
    #[getter]
    fn action_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        self.inner.spaces().action_bounds()
    }

    /// The length of a life, in actions.
    #[getter]
    fn life(&self) -> u32 {
        self.inner.life()
    }

    /// Starts a life in the world of episode seed `seed`; returns the first observation.
    fn reset<'py>(&mut self, py: Python<'py>, seed: u64) -> Bound<'py, PyArray1<f32>> {
        self.inner.reset(seed, &mut self.obs);
        PyArray1::from_slice(py, &self.obs)
    }

    /// Runs one action (a float32 array); returns the observation, the
    /// reward, terminated, truncated and a dict of what happened.
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        action: numpy::PyReadonlyArray1<'py, f32>,
    ) -> PyResult<(Bound<'py, PyArray1<f32>>, f32, bool, bool, Bound<'py, PyDict>)> {
        let action = action.as_slice().map_err(|e| value_error(format!("the action: {e}")))?;
        let step = self.inner.step(action, &mut self.obs).map_err(|e| invalid(&e))?;
        let info = PyDict::new(py);
        let pose = self.inner.pose();
        info.set_item("grips", step.outcome.grips)?;
        info.set_item("releases_outside", step.outcome.releases_outside)?;
        info.set_item("recharged", step.outcome.recharged)?;
        info.set_item("collided", step.outcome.collided)?;
        info.set_item("battery", self.inner.battery())?;
        info.set_item("x", pose.x)?;
        info.set_item("y", pose.y)?;
        info.set_item("heading", pose.theta)?;
        if step.terminated || step.truncated {
            let d = self.inner.descriptors();
            info.set_item("path_length", d.path_length)?;
            info.set_item("squares_visited", d.squares_visited)?;
        }
        Ok((PyArray1::from_slice(py, &self.obs), step.reward, step.terminated, step.truncated, info))
    }

    /// A picture of the world now and the path of the life so far: an
    /// array of shape (height, width, 3) of uint8.
    fn render<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
        rgb_of(py, self.inner.picture())
    }
}

/// The picture of a stepper's world as an array of shape (height, width, 3).
fn rgb_of<'py>(
    py: Python<'py>,
    picture: Option<shaping_engine::plot::TrajectoryScene>,
) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
    let picture = picture.ok_or_else(|| value_error("error: reset before rendering"))?;
    let rgb = py
        .detach(|| shaping_engine::plot::trajectory_rgb(&picture))
        .map_err(|e| ShapingError::new_err(format!("error: {e}")))?;
    let flat = PyArray1::from_vec(py, rgb.pixels);
    flat.reshape([rgb.height as usize, rgb.width as usize, 3])
}

/// A stage's team driven one action at a time, every robot in one call
/// (`shaping.gym.make_parallel` wraps it in a PettingZoo environment).
#[pyclass(module = "shaping")]
struct TeamStepper {
    inner: shaping_engine::stepper::TeamStepper,
    obs: Vec<f32>,
}

#[pymethods]
impl TeamStepper {
    /// The team of stage `stage` of `program`; `keep_path` keeps every
    /// robot's poses of each life for `render`. A stage with one robot
    /// raises ShapingError (step it with `shaping.gym.make`).
    #[new]
    #[pyo3(signature = (program, stage, keep_path=false))]
    fn new(program: &Program, stage: &str, keep_path: bool) -> PyResult<TeamStepper> {
        let mut inner = shaping_engine::stepper::TeamStepper::new(stepped_stage(program, stage)?)
            .map_err(|e| Python::attach(|py| shaping_error(py, &e)))?;
        inner.keep_path(keep_path);
        let obs = vec![0.0; inner.robots() * inner.spaces().channels.len()];
        Ok(TeamStepper { inner, obs })
    }

    /// Each robot's agent name: its role and its index in the role
    /// (`guard_0`), or `robot_i` without roles.
    #[getter]
    fn agents(&self) -> Vec<String> {
        self.inner.names().to_vec()
    }

    /// Each robot's role (its index in `Program.roles`; 0 without roles).
    #[getter]
    fn roles(&self) -> Vec<usize> {
        (0..self.inner.robots()).map(|i| self.inner.stage().role_of(i)).collect()
    }

    /// The names of the observation's elements (every robot's).
    #[getter]
    fn observation_names(&self) -> Vec<String> {
        self.inner.spaces().observation.clone()
    }

    /// The names of the action's elements (every robot's).
    #[getter]
    fn action_names(&self) -> Vec<String> {
        self.inner.spaces().action.clone()
    }

    /// The lowest and highest value of each action element.
    #[getter]
    fn action_bounds(&self) -> (Vec<f32>, Vec<f32>) {
        self.inner.spaces().action_bounds()
    }

    /// The length of a life, in actions.
    #[getter]
    fn life(&self) -> u32 {
        self.inner.life()
    }

    /// Starts a life of the team in the world of episode seed `seed`;
    /// returns the observations, shape (robots, observation).
    fn reset<'py>(&mut self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, numpy::PyArray2<f32>>> {
        self.inner.reset(seed, &mut self.obs);
        self.observations(py)
    }

    /// Runs one action of the team with the GIL released: row i of
    /// `actions` (float32, shape (robots, action)) is robot i's (ignored
    /// once its life has ended). Returns the observations, the rewards,
    /// terminated and truncated (one row or element per robot; those of a
    /// robot whose life had ended are its last observation, 0, False,
    /// False) and a dict of the robots' poses and batteries. A malformed
    /// row raises ValueError naming the agent and the element.
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: numpy::PyReadonlyArray2<'py, f32>,
    ) -> PyResult<(
        Bound<'py, numpy::PyArray2<f32>>,
        Bound<'py, PyArray1<f32>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyDict>,
    )> {
        let (n, dims) = (self.inner.robots(), self.inner.spaces().controls.len());
        if actions.shape() != [n, dims] {
            return Err(value_error(format!(
                "error: the actions must be an array of shape ({n}, {dims}) (a row per robot), not {:?}",
                actions.shape()
            )));
        }
        let flat = actions.as_slice().map_err(|e| value_error(format!("the actions: {e}")))?;
        let (inner, obs) = (&mut self.inner, &mut self.obs);
        py.detach(|| inner.step(flat, obs).map(|_| ())).map_err(|e| invalid(&e))?;
        let steps = self.inner.steps();
        let info = PyDict::new(py);
        let poses: Vec<f32> = (0..n)
            .flat_map(|i| {
                let p = self.inner.pose(i);
                [p.x, p.y, p.theta]
            })
            .collect();
        info.set_item("pose", PyArray1::from_vec(py, poses).reshape([n, 3])?)?;
        info.set_item("battery", PyArray1::from_vec(py, (0..n).map(|i| self.inner.battery(i)).collect()))?;
        Ok((
            self.observations(py)?,
            PyArray1::from_vec(py, steps.iter().map(|s| s.reward).collect()),
            PyArray1::from_vec(py, steps.iter().map(|s| s.terminated).collect()),
            PyArray1::from_vec(py, steps.iter().map(|s| s.truncated).collect()),
            info,
        ))
    }

    /// A picture of the world now and every robot's path of the life so
    /// far: an array of shape (height, width, 3) of uint8.
    fn render<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray3<u8>>> {
        rgb_of(py, self.inner.picture())
    }
}

impl TeamStepper {
    fn observations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray2<f32>>> {
        let width = self.inner.spaces().channels.len();
        PyArray1::from_slice(py, &self.obs).reshape([self.inner.robots(), width])
    }
}

/// Many robots of one stage stepped together in Rust (`shaping.gym.make_vec`).
#[pyclass(module = "shaping")]
struct VecStepper {
    inner: shaping_engine::stepper::VecStepper,
    out: shaping_engine::stepper::VecStep,
    pool: Pool,
}

/// The memory one robot of a `VecStepper` takes, besides its observation
/// and action rows and its world's items: its stepper, its simulator after
/// the first reset and its rows of the results (measured as the resident
/// size of 20,000 to 100,000 robots after a reset: 3.4 KB a Khepera in
/// `examples/t-maze.bat`, 6.2 to 6.6 KB in `examples/khepera.bat`'s
/// `navigation` and `collect`; rounded up).
const VEC_ROBOT_BYTES: u64 = 8192;
/// The memory each wall, cylinder, lamp, zone or object of its world adds
/// to a robot (measured: about 12 bytes a wall, t-maze with 400 more; an
/// upper bound).
const VEC_ITEM_BYTES: u64 = 64;

/// The most robots of one `VecStepper` (far beyond what a step's latency allows).
const MAX_NUM_ENVS: u64 = 1 << 32;

/// The memory one robot of stage `index` takes in a batch of worlds
/// (`VEC_ROBOT_BYTES`, its rows and its world's items).
fn vec_robot_bytes(program: &Program, index: usize) -> u64 {
    let st = &program.program.stages[index];
    let width = shaping_engine::stepper::Spaces::of(st).channels.len() + 8;
    let w = &st.world;
    let items = w.items.walls.len() + w.items.cylinders.len() + w.items.lamps.len() + w.items.zones.len();
    let objects = w.objects.as_ref().map_or(0, |o| u64::from(o.count));
    VEC_ROBOT_BYTES + 8 * width as u64 + VEC_ITEM_BYTES * (items as u64 + objects)
}

#[pymethods]
impl VecStepper {
    /// `num_envs` robots of stage `stage` of `program`, stepped on `jobs`
    /// threads (None: one per core).
    /// A `num_envs` that is not a positive integer, or a bad `jobs`, raises
    /// ValueError; more robots than the memory available holds, MemoryError.
    #[new]
    #[pyo3(signature = (program, stage, num_envs, jobs=None))]
    fn new(
        program: &Program,
        stage: &str,
        num_envs: &Bound<'_, PyAny>,
        jobs: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<VecStepper> {
        let num_envs = match count_arg(num_envs, "num_envs", MAX_NUM_ENVS) {
            Ok(0) => Err(value_error("error: num_envs must be at least 1")),
            other => other,
        }? as usize;
        let jobs = jobs_arg(jobs)?;
        let index = stage_index(&program.program, stage)?;
        let need = (num_envs as u64).saturating_mul(vec_robot_bytes(program, index));
        check_room(need, &format!("stepping {num_envs} robots"), "pass a smaller num_envs")?;
        let pool = Pool::new(jobs)?;
        let inner = shaping_engine::stepper::VecStepper::new(stepped_stage(program, stage)?, num_envs)
            .map_err(|e| Python::attach(|py| shaping_error(py, &e)))?;
        Ok(VecStepper { inner, out: Default::default(), pool })
    }

    #[getter]
    fn num_envs(&self) -> usize {
        self.inner.len()
    }

    /// Starts a life of every robot (robot i's lives from stream i of
    /// `seed`); returns the observations, shape (num_envs, observation).
    fn reset<'py>(&mut self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, numpy::PyArray2<f32>>> {
        self.inner.reset(seed, &mut self.out);
        self.observations(py)
    }

    /// Steps every robot with its row of `actions` (float32, shape
    /// (num_envs, action)), with the GIL released; returns the
    /// observations, rewards, terminated and truncated. A robot whose life
    /// ended at the last step starts again instead (its action ignored).
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: numpy::PyReadonlyArray2<'py, f32>,
    ) -> PyResult<(
        Bound<'py, numpy::PyArray2<f32>>,
        Bound<'py, PyArray1<f32>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
    )> {
        let (n, dims) = (self.inner.len(), self.inner.spaces().controls.len());
        if actions.shape() != [n, dims] {
            return Err(value_error(format!(
                "error: the actions must be an array of shape ({n}, {dims}), not {:?}",
                actions.shape()
            )));
        }
        let flat = actions.as_slice().map_err(|e| value_error(format!("the actions: {e}")))?;
        let (pool, inner, out) = (&self.pool, &mut self.inner, &mut self.out);
        py.detach(|| pool.run(n == 1, || inner.step(flat, out)))?.map_err(|e| invalid(&e))?;
        Ok((
            self.observations(py)?,
            PyArray1::from_slice(py, &self.out.rewards),
            PyArray1::from_slice(py, &self.out.terminated),
            PyArray1::from_slice(py, &self.out.truncated),
        ))
    }
}

/// Many worlds of a stage's team stepped together in Rust
/// (`shaping.gym.make_parallel_vec`).
#[pyclass(module = "shaping")]
struct VecTeamStepper {
    inner: shaping_engine::stepper::VecTeamStepper,
    out: shaping_engine::stepper::VecStep,
    pool: Pool,
}

#[pymethods]
impl VecTeamStepper {
    /// `num_envs` worlds of the team of stage `stage` of `program`,
    /// stepped on `jobs` threads (None: one per core). A `num_envs` that is
    /// not a positive integer, or a bad `jobs`, raises ValueError; more
    /// robots than the memory available holds, MemoryError; a stage with
    /// one robot, ShapingError.
    #[new]
    #[pyo3(signature = (program, stage, num_envs, jobs=None))]
    fn new(
        program: &Program,
        stage: &str,
        num_envs: &Bound<'_, PyAny>,
        jobs: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<VecTeamStepper> {
        let num_envs = match count_arg(num_envs, "num_envs", MAX_NUM_ENVS) {
            Ok(0) => Err(value_error("error: num_envs must be at least 1")),
            other => other,
        }? as usize;
        let jobs = jobs_arg(jobs)?;
        let index = stage_index(&program.program, stage)?;
        let robots = u64::from(program.program.stages[index].world.robots.max(1));
        let need = (num_envs as u64).saturating_mul(robots).saturating_mul(vec_robot_bytes(program, index));
        check_room(
            need,
            &format!("stepping {num_envs} teams of {robots} robots"),
            "pass a smaller num_envs",
        )?;
        let pool = Pool::new(jobs)?;
        let inner = shaping_engine::stepper::VecTeamStepper::new(stepped_stage(program, stage)?, num_envs)
            .map_err(|e| Python::attach(|py| shaping_error(py, &e)))?;
        Ok(VecTeamStepper { inner, out: Default::default(), pool })
    }

    /// The number of worlds.
    #[getter]
    fn num_envs(&self) -> usize {
        self.inner.len()
    }

    /// Each robot's agent name in a world.
    #[getter]
    fn agents(&self) -> Vec<String> {
        self.inner.names().to_vec()
    }

    /// Starts a life of every world (world w's lives from stream w of
    /// `seed`); returns the observations, shape (num_envs, robots, observation).
    fn reset<'py>(&mut self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
        self.inner.reset(seed, &mut self.out);
        self.observations(py)
    }

    /// Steps every world with its robots' rows of `actions` (float32,
    /// shape (num_envs, robots, action)), with the GIL released; returns
    /// the observations, and the rewards, terminated and truncated of shape
    /// (num_envs, robots). A world whose team's life ended at the last step
    /// starts again instead (its actions ignored, rewards 0).
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: numpy::PyReadonlyArray3<'py, f32>,
    ) -> PyResult<(
        Bound<'py, numpy::PyArray3<f32>>,
        Bound<'py, numpy::PyArray2<f32>>,
        Bound<'py, numpy::PyArray2<bool>>,
        Bound<'py, numpy::PyArray2<bool>>,
    )> {
        let (n, robots, dims) = (self.inner.len(), self.inner.robots(), self.inner.spaces().controls.len());
        if actions.shape() != [n, robots, dims] {
            return Err(value_error(format!(
                "error: the actions must be an array of shape ({n}, {robots}, {dims}), not {:?}",
                actions.shape()
            )));
        }
        let flat = actions.as_slice().map_err(|e| value_error(format!("the actions: {e}")))?;
        let (pool, inner, out) = (&self.pool, &mut self.inner, &mut self.out);
        py.detach(|| pool.run(n == 1, || inner.step(flat, out)))?.map_err(|e| invalid(&e))?;
        Ok((
            self.observations(py)?,
            PyArray1::from_slice(py, &self.out.rewards).reshape([n, robots])?,
            PyArray1::from_slice(py, &self.out.terminated).reshape([n, robots])?,
            PyArray1::from_slice(py, &self.out.truncated).reshape([n, robots])?,
        ))
    }
}

impl VecTeamStepper {
    fn observations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
        let width = self.inner.spaces().channels.len();
        PyArray1::from_slice(py, &self.out.observations).reshape([
            self.inner.len(),
            self.inner.robots(),
            width,
        ])
    }
}

impl VecStepper {
    fn observations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray2<f32>>> {
        let width = self.inner.spaces().channels.len();
        PyArray1::from_slice(py, &self.out.observations).reshape([self.inner.len(), width])
    }
}

// ------------------------------------------------------------------ run

/// A run directory: the stages it holds and their files.
#[pyclass(module = "shaping", frozen)]
struct Run {
    out: PathBuf,
    seed: Option<u64>,
    stages: Vec<String>,
    report: Option<PathBuf>,
}

#[pymethods]
impl Run {
    /// Opens the run directory `out` (written by `shaping run` or `shaping.run`).
    #[new]
    fn new(py: Python<'_>, out: PathBuf) -> PyResult<Run> {
        let program = load::load_built(&rundir::program_path(&out)).map_err(|e| shaping_error(py, &e))?;
        let stages = program
            .stages
            .iter()
            .filter(|s| rundir::stage_dir(&out, &s.name).is_dir())
            .map(|s| s.name.clone())
            .collect();
        let report = rundir::report_path(&out);
        let report = report.is_file().then_some(report);
        Ok(Run { out, seed: None, stages, report })
    }

    /// The run directory.
    #[getter]
    fn out(&self) -> PathBuf {
        self.out.clone()
    }

    /// The run seed (None for a directory opened with `Run(out)`).
    #[getter]
    fn seed(&self) -> Option<u64> {
        self.seed
    }

    /// The stages run, in order.
    #[getter]
    fn stages(&self) -> Vec<String> {
        self.stages.clone()
    }

    /// The path of `report.html` (None if not written).
    #[getter]
    fn report(&self) -> Option<PathBuf> {
        self.report.clone()
    }

    /// The directory of `stage`.
    fn stage_dir(&self, stage: &str) -> PyResult<PathBuf> {
        let dir = rundir::stage_dir(&self.out, stage);
        if !dir.is_dir() {
            return Err(value_error(format!(
                "error: the run `{}` has no stage `{stage}` (it has {})",
                self.out.display(),
                self.stages.iter().map(|s| format!("`{s}`")).collect::<Vec<_>>().join(", ")
            )));
        }
        Ok(dir)
    }

    /// The columns of `generations.csv` of evolved stage `stage`, each a
    /// numpy array: `stage` strings, `best`, `mean`, `worst` and (a stage
    /// with variants) `best_variant_NAME` floats (NaN where the generation
    /// did not draw the variant), the others integers.
    fn generations<'py>(&self, py: Python<'py>, stage: &str) -> PyResult<Bound<'py, PyDict>> {
        let dir = self.stage_dir(stage)?;
        let g =
            rundir::read_generations(&dir, &|_| {}).map_err(|e| shaping_error(py, &e))?.ok_or_else(|| {
                let path = rundir::generations_path(&dir);
                ShapingError::new_err(format!(
                    "error: cannot read `{}`: there is no such file",
                    path.display()
                ))
            })?;
        let rows = &g.rows;
        let out = PyDict::new(py);
        let stages: Vec<&str> = rows.iter().map(|r| r.stage.as_str()).collect();
        out.set_item("stage", py.import("numpy")?.call_method1("array", (stages,))?)?;
        let ints = |f: fn(&rundir::GenRow) -> Option<u64>| -> Option<Vec<i64>> {
            rows.iter().map(|r| f(r).map(|n| n as i64)).collect()
        };
        let floats = |f: fn(&rundir::GenRow) -> Option<f32>| -> Option<Vec<f64>> {
            rows.iter().map(|r| f(r).map(f64::from)).collect()
        };
        // The columns in the file's order; those a file written before
        // them lacks are left out.
        let columns = [
            ("generation", ints(|r| Some(u64::from(r.generation))), None),
            ("stage_generation", ints(|r| Some(u64::from(r.stage_generation))), None),
            ("best", None, floats(|r| Some(r.best))),
            ("mean", None, floats(|r| Some(r.mean))),
            ("worst", None, floats(|r| r.worst)),
            ("best_index", ints(|r| r.best_index), None),
            ("best_recharges", ints(|r| r.best_recharges), None),
            ("best_grips", ints(|r| r.best_grips), None),
            ("best_releases_outside", ints(|r| r.best_releases_outside), None),
        ];
        for (name, int, float) in columns {
            if let Some(v) = int {
                out.set_item(name, PyArray1::from_vec(py, v))?;
            } else if let Some(v) = float {
                out.set_item(name, PyArray1::from_vec(py, v))?;
            }
        }
        // The best's fitness in each variant: NaN where its generation did
        // not draw the variant.
        for (k, variant) in g.variants.iter().enumerate() {
            let v: Vec<f64> = rows
                .iter()
                .map(|r| r.best_variants.get(k).copied().flatten().map_or(f64::NAN, f64::from))
                .collect();
            out.set_item(format!("best_variant_{variant}"), PyArray1::from_vec(py, v))?;
        }
        Ok(out)
    }

    /// The chosen best genome of evolved stage `stage` (`best.genome`), a numpy array of 0/1.
    fn best_genome<'py>(&self, py: Python<'py>, stage: &str) -> PyResult<Bound<'py, PyArray1<u8>>> {
        let dir = self.stage_dir(stage)?;
        let genome = rundir::read_best(&dir).map_err(|e| shaping_error(py, &e))?;
        Ok(PyArray1::from_vec(py, genome.bits))
    }

    /// The last evaluated generation of evolved stage `stage` (its
    /// checkpoint): the genomes, an array of shape (population, bits) of
    /// 0/1, and their fitness (float32), as the run evaluated them.
    #[allow(clippy::type_complexity)]
    fn population<'py>(
        &self,
        py: Python<'py>,
        stage: &str,
    ) -> PyResult<(Bound<'py, numpy::PyArray2<u8>>, Bound<'py, PyArray1<f32>>)> {
        let dir = self.stage_dir(stage)?;
        let cp = rundir::read_checkpoint(&dir).map_err(|e| shaping_error(py, &e))?.ok_or_else(|| {
            ShapingError::new_err(format!(
                "error: there is no checkpoint `{}`: stage `{stage}` is not evolved or not run",
                rundir::checkpoint_path(&dir).display()
            ))
        })?;
        let rows: Vec<Vec<u8>> = cp.population.iter().map(|g| g.bits.clone()).collect();
        let genomes = if rows.is_empty() {
            numpy::PyArray2::zeros(py, [0, 0], false)
        } else {
            numpy::PyArray2::from_vec2(py, &rows)
                .map_err(|e| ShapingError::new_err(format!("error: the checkpoint of `{stage}`: {e}")))?
        };
        Ok((genomes, PyArray1::from_vec(py, cp.fitness)))
    }

    fn __repr__(&self) -> String {
        format!("<Run {}: {}>", self.out.display(), self.stages.join(", "))
    }
}

/// Tells the callback of `shaping.run` the run's events (with the GIL), and
/// keeps the warnings and the callback's first exception.
struct PyObserver {
    callback: Option<Py<PyAny>>,
    warnings: Mutex<Vec<String>>,
    error: Mutex<Option<PyErr>>,
    stop: Arc<AtomicBool>,
}

impl Observer for PyObserver {
    fn event(&self, event: Event<'_>) {
        if let Event::Warning(w) = &event {
            if let Ok(mut v) = self.warnings.lock() {
                v.push(w.clone());
            }
        }
        let Some(callback) = &self.callback else { return };
        if self.error.lock().map(|e| e.is_some()).unwrap_or(true) {
            return;
        }
        let Ok(value) = serde_json::to_value(&event) else { return };
        Python::attach(|py| {
            let result = json_to_py(py, &value).and_then(|v| callback.call1(py, (v,)));
            if let Err(e) = result {
                if let Ok(mut slot) = self.error.lock() {
                    slot.get_or_insert(e);
                }
                self.stop.store(true, Ordering::Relaxed);
            }
        });
    }
}

/// `set`: a dict of `STAGE.SECTION.FIELD` to one value each.
fn assignments(set: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<sweep::Assignment>> {
    sweep_sets(set)?
        .into_iter()
        .map(|parsed| {
            <[String; 1]>::try_from(parsed.values).map(|[value]| (parsed.target.clone(), value)).map_err(
                |values| {
                    value_error(format!(
                        "error: `--set {}={}`: `run` takes one value (`experiment` sweeps several)",
                        parsed.target,
                        values.join(",")
                    ))
                },
            )
        })
        .collect()
}

/// Runs the file `path` like `shaping run` into `out` (default
/// `runs/<file stem>`), resuming what is saved there, and returns its `Run`.
///
/// `seed`: the run seed (default: the first evolved stage's); `stage`: run
/// only it and the stages it needs; `set`: a dict of `STAGE.SECTION.FIELD`
/// to one value each (`--set`); `jobs`: worker threads; `fresh`: start
/// every stage again; `report`: write `report.html`. `callback` is called
/// (with the GIL) with one dict per event (`event`: "evolve_start",
/// "resumed", "generation", "evolve_end", "evolved", "trained", "tested",
/// "warning"); an exception it raises stops the run after the generation
/// under way and is raised. Ctrl-C does the same and raises
/// KeyboardInterrupt; the run is resumable. Errors of the run raise
/// ShapingError with the command line's message; malformed arguments raise
/// ValueError.
#[pyfunction]
#[pyo3(signature = (path, out=None, seed=None, stage=None, set=None, jobs=None, callback=None, fresh=false, report=true))]
#[allow(clippy::too_many_arguments)]
fn run(
    py: Python<'_>,
    path: PathBuf,
    out: Option<PathBuf>,
    seed: Option<&Bound<'_, PyAny>>,
    stage: Option<String>,
    set: Option<&Bound<'_, PyDict>>,
    jobs: Option<&Bound<'_, PyAny>>,
    callback: Option<Py<PyAny>>,
    fresh: bool,
    report: bool,
) -> PyResult<Run> {
    let seed = seed.filter(|s| !s.is_none()).map(|s| count_arg(s, "seed", u64::MAX)).transpose()?;
    let jobs = jobs_arg(jobs)?;
    check_callback(py, &callback)?;
    let sets = assignments(set)?;
    let program = load(py, &path)?;
    if let Some(s) = &stage {
        stage_index(&program, s)?;
    }
    let out = out.unwrap_or_else(|| engine_run::default_out(&path));
    let options = RunOptions { stage, seed, out, jobs, fresh, no_report: !report, sets };
    let outcome = observed(py, callback, |observer, stop| {
        Engine { observer, evaluator: None, interrupt: Some(stop) }.run_file(program, &path, &options)
    })?;
    Ok(Run::of(outcome))
}

impl Run {
    fn of(outcome: engine_run::RunOutcome) -> Run {
        Run {
            stages: outcome.stages.iter().map(|s| s.stage().to_string()).collect(),
            out: outcome.out,
            seed: Some(outcome.seed),
            report: outcome.report,
        }
    }
}

/// Runs `body` with the GIL released, its events told to `callback`, Ctrl-C
/// setting its stop flag (it stops after the generation under way,
/// resumable; Python's own handler still runs); then warns of its
/// warnings, and raises the callback's first exception, KeyboardInterrupt
/// for an interruption, or the error.
fn observed<T: Send>(
    py: Python<'_>,
    callback: Option<Py<PyAny>>,
    body: impl FnOnce(&PyObserver, &AtomicBool) -> Result<T, shaping_engine::Error> + Send,
) -> PyResult<T> {
    let stop = Arc::new(AtomicBool::new(false));
    let observer = PyObserver {
        callback,
        warnings: Mutex::new(Vec::new()),
        error: Mutex::new(None),
        stop: stop.clone(),
    };
    let hook = signal_hook::flag::register(signal_hook::consts::SIGINT, stop.clone()).ok();
    let result = py.detach(|| body(&observer, &stop));
    if let Some(id) = hook {
        signal_hook::low_level::unregister(id);
    }
    for w in observer.warnings.lock().map(|v| v.clone()).unwrap_or_default() {
        warn(py, &w)?;
    }
    if let Some(e) = observer.error.lock().ok().and_then(|mut e| e.take()) {
        return Err(e);
    }
    match result {
        Ok(v) => Ok(v),
        Err(e) if e.kind() == ErrorKind::Interrupted => {
            // Python's handler saw the signal too: its KeyboardInterrupt, with the run's message.
            let _ = py.check_signals();
            Err(PyKeyboardInterrupt::new_err(e.message().to_string()))
        }
        Err(e) => Err(engine_error(py, &e)),
    }
}

fn check_callback(py: Python<'_>, callback: &Option<Py<PyAny>>) -> PyResult<()> {
    match callback {
        Some(c) if !c.bind(py).is_callable() => {
            Err(value_error("callback must be callable (it is called with one dict per event)"))
        }
        _ => Ok(()),
    }
}

// ------------------------------------------------------------------ experiment

/// An experiment's directory: its runs and its summaries.
#[pyclass(module = "shaping", frozen)]
struct Experiment {
    out: PathBuf,
    seeds: Vec<u64>,
    runs: Vec<Py<Run>>,
    summary_text: String,
    reports: Vec<PathBuf>,
}

#[pymethods]
impl Experiment {
    /// The experiment's directory.
    #[getter]
    fn out(&self) -> PathBuf {
        self.out.clone()
    }

    /// The seeds run.
    #[getter]
    fn seeds(&self) -> Vec<u64> {
        self.seeds.clone()
    }

    /// Every run, point after point (one point without `set` lists), seed after seed.
    #[getter]
    fn runs(&self, py: Python<'_>) -> Vec<Py<Run>> {
        self.runs.iter().map(|r| r.clone_ref(py)).collect()
    }

    /// The summary the command line prints (`summary.md` of the point, or the sweep's table).
    #[getter]
    fn summary_text(&self) -> String {
        self.summary_text.clone()
    }

    /// `summary.json`: per point, its settings and per stage the median,
    /// range, mean and standard deviation over the seeds.
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let summary = self.read_summary(py)?;
        let text = serde_json::to_value(&summary).map(|v| v.to_string()).unwrap_or_default();
        py.import("json")?.call_method1("loads", (text,))
    }

    /// The statistics of `summary.json` (its `tests`), per stage and
    /// measure: each group's median over the seeds with its bootstrap 95%
    /// interval. A group is the experiment, or a point of a sweep.
    fn medians<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let t = self.tests_of_summary(py)?;
        let out = PyList::empty(py);
        for m in &t.measures {
            for (g, figures) in t.groups.iter().zip(&m.groups) {
                let d = PyDict::new(py);
                d.set_item("stage", &m.stage)?;
                d.set_item("measure", &m.measure)?;
                d.set_item("group", g)?;
                d.set_item("seeds", figures.seeds)?;
                d.set_item("median", figures.median)?;
                d.set_item("low", figures.interval.map(|i| i.low))?;
                d.set_item("high", figures.interval.map(|i| i.high))?;
                out.append(d)?;
            }
        }
        Ok(out)
    }

    /// The tests of `summary.json` between the points of a sweep, per stage,
    /// measure and pair: Mann-Whitney's U and `p_value`, `p_holm` (Holm's
    /// correction over the measure's pairs with more than two points, else
    /// None), Vargha-Delaney's `a12` (the probability that a seed of `a`
    /// has the larger value), its `size` and the test's `method`; without a
    /// test (a side with fewer than 2 seeds) these are None and `no_test`
    /// says why. Empty for an experiment of one point.
    fn tests<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let t = self.tests_of_summary(py)?;
        let out = PyList::empty(py);
        let name = |i: usize| t.groups.get(i.wrapping_sub(1)).cloned().unwrap_or_default();
        for m in &t.measures {
            for p in &m.pairs {
                let d = PyDict::new(py);
                d.set_item("stage", &m.stage)?;
                d.set_item("measure", &m.measure)?;
                d.set_item("a", name(p.a))?;
                d.set_item("b", name(p.b))?;
                d.set_item("u", p.u)?;
                d.set_item("p_value", p.p_value)?;
                d.set_item("p_holm", p.p_holm)?;
                d.set_item("a12", p.a12)?;
                d.set_item("size", p.size.map(|s| s.words()))?;
                d.set_item("method", p.method.map(|m| m.words()))?;
                d.set_item("no_test", p.no_test.as_deref())?;
                out.append(d)?;
            }
        }
        Ok(out)
    }

    /// The reports written (`report.html` of each point, and of the sweep).
    #[getter]
    fn reports(&self) -> Vec<PathBuf> {
        self.reports.clone()
    }

    fn __repr__(&self) -> String {
        format!("<Experiment {}: {} runs, seeds {:?}>", self.out.display(), self.runs.len(), self.seeds)
    }
}

impl Experiment {
    /// `summary.json`, as the experiment wrote it (through the run
    /// directory's one reader).
    fn read_summary(&self, py: Python<'_>) -> PyResult<rundir::ExperimentSummary> {
        rundir::read_experiment_summary(&self.out, &|_| {}).map_err(|e| shaping_error(py, &e))?.ok_or_else(
            || {
                let path = rundir::summary_path(&self.out);
                ShapingError::new_err(format!(
                    "error: cannot read `{}`: there is no such file",
                    path.display()
                ))
            },
        )
    }

    /// The `tests` of `summary.json`, as the experiment wrote them.
    fn tests_of_summary(&self, py: Python<'_>) -> PyResult<rundir::Tests> {
        Ok(self.read_summary(py)?.tests)
    }
}

/// `set` of an experiment: a dict of `STAGE.SECTION.FIELD` to a value or a
/// list of values (a sweep over them).
fn sweep_sets(set: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<sweep::Set>> {
    let Some(set) = set else { return Ok(Vec::new()) };
    let mut out = Vec::new();
    for (k, v) in set.iter() {
        let key: String =
            k.extract().map_err(|_| value_error("set: the keys are STAGE.SECTION.FIELD strings"))?;
        let one = |v: &Bound<'_, PyAny>| -> PyResult<String> {
            Ok(if let Ok(b) = v.extract::<bool>() { b.to_string() } else { v.str()?.to_string() })
        };
        let values: Vec<String> =
            if v.is_instance_of::<PyList>() || v.is_instance_of::<pyo3::types::PyTuple>() {
                v.try_iter()?.map(|x| one(&x?)).collect::<PyResult<_>>()?
            } else {
                vec![one(&v)?]
            };
        out.push(
            sweep::parse_set(&format!("{key}={}", values.join(",")))
                .map_err(|e| value_error(format!("error: {e}")))?,
        );
    }
    Ok(out)
}

/// Runs the file `path` over `seeds` consecutive seeds from `first_seed`,
/// like `shaping experiment`, into `out` (default
/// `runs/<file stem>/experiment`), and writes the summaries and reports.
///
/// `set`: a dict of `STAGE.SECTION.FIELD` to a value or a list of values:
/// a sweep over the cartesian product of the lists, every point over the
/// seeds. `criterion`: a dict of stage to fitness, to report the generation
/// at which the best reaches it. `stage`, `jobs`, `fresh`, `report`,
/// `callback`, Ctrl-C and the errors: as `run`.
#[pyfunction]
#[pyo3(signature = (path, seeds=5, first_seed=1, out=None, stage=None, set=None, criterion=None, jobs=None, callback=None, fresh=false, report=true))]
#[allow(clippy::too_many_arguments)]
fn experiment(
    py: Python<'_>,
    path: PathBuf,
    seeds: u64,
    first_seed: u64,
    out: Option<PathBuf>,
    stage: Option<String>,
    set: Option<&Bound<'_, PyDict>>,
    criterion: Option<&Bound<'_, PyDict>>,
    jobs: Option<&Bound<'_, PyAny>>,
    callback: Option<Py<PyAny>>,
    fresh: bool,
    report: bool,
) -> PyResult<Experiment> {
    let jobs = jobs_arg(jobs)?;
    check_callback(py, &callback)?;
    let sets = sweep_sets(set)?;
    let mut criteria = Vec::new();
    if let Some(c) = criterion {
        for (k, v) in c.iter() {
            let stage: String =
                k.extract().map_err(|_| value_error("criterion: the keys are stage names"))?;
            let value: f64 =
                v.extract().map_err(|_| value_error("criterion: the values are fitness values"))?;
            criteria.push(format!("{stage}={value}"));
        }
    }
    let program = load(py, &path)?;
    let options = shaping_engine::experiment::ExperimentOptions {
        file: path,
        seeds,
        first_seed,
        out,
        jobs,
        criterion: criteria,
        sets,
        stage,
        fresh,
        no_report: !report,
    };
    let (outcomes, finished) = observed(py, callback, |observer, stop| {
        Engine { observer, evaluator: None, interrupt: Some(stop) }.experiment(program, options)
    })?;
    let mut runs = Vec::new();
    let mut seen = Vec::new();
    for o in outcomes {
        if !seen.contains(&o.seed) {
            seen.push(o.seed);
        }
        runs.push(Py::new(py, Run::of(o))?);
    }
    Ok(Experiment {
        out: finished.out,
        seeds: seen,
        runs,
        summary_text: finished.summary,
        reports: finished.reports,
    })
}

#[pymodule]
fn _shaping(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("ShapingError", m.py().get_type::<ShapingError>())?;
    m.add("CompileError", m.py().get_type::<CompileError>())?;
    m.add("CorruptError", m.py().get_type::<CorruptError>())?;
    m.add("StaleError", m.py().get_type::<StaleError>())?;
    m.add("LockedError", m.py().get_type::<LockedError>())?;
    m.add("EvaluationError", m.py().get_type::<EvaluationError>())?;
    m.add("NotFoundError", not_found_type(m.py())?)?;
    m.add("SQUARE_MM", descriptors::SQUARE_MM)?;
    m.add_class::<Diagnostic>()?;
    m.add_class::<Program>()?;
    m.add_class::<Evaluator>()?;
    m.add_class::<Run>()?;
    m.add_class::<Experiment>()?;
    m.add_class::<Stepper>()?;
    m.add_class::<VecStepper>()?;
    m.add_class::<TeamStepper>()?;
    m.add_class::<VecTeamStepper>()?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(compile, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(experiment, m)?)?;
    m.add_function(wrap_pyfunction!(_program_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(_evaluator_from_json, m)?)?;
    m.add_function(wrap_pyfunction!(_encode_genes, m)?)?;
    m.add_function(wrap_pyfunction!(_decode_genes, m)?)?;
    Ok(())
}
