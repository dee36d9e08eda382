//! Running `shaping run` and `shaping experiment` on several processes with
//! MPI (`mpirun -n N shaping run FILE`, built with `--features mpi`).
//!
//! Rank 0 runs everything a single process runs (the GA, checkpoints,
//! statistics, pictures, the progress bar) and hands the episodes of each
//! generation out in batches; the other ranks only evaluate. A rank asks for
//! its next batch when it sends the results of the last one, so a slow rank
//! simply takes fewer batches. Rank 0 evaluates too, on a second thread,
//! while its main thread answers the others. Results are put back in episode
//! order, and an episode's result depends only on its genome and seed, so
//! the files are bit-identical for any number of ranks.
//!
//! An experiment with at least as many tasks (a seed of a sweep point) as
//! ranks runs whole tasks instead: rank 0 hands one out per request, each
//! rank runs the seed as a single process would and writes its files, and
//! reports it done. The messages are in [`wire`]; the MPI side is in
//! `mpi.rs` (only with the feature).

#[cfg(feature = "mpi")]
mod mpi;
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
pub mod wire;

use shaping_runtime::evolve::{Episode, Evaluation};
use shaping_runtime::genome::Genome;

#[cfg(feature = "mpi")]
pub use self::mpi::{with_mpi, Coordinator};

/// Default seconds rank 0 waits for a rank's answer to a batch.
pub const DEFAULT_RANK_TIMEOUT: u64 = 300;

/// Variables an MPI launcher sets, with the number of processes.
const SIZE_VARS: [&str; 4] = ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "MV2_COMM_WORLD_SIZE", "PMIX_RANK"];

/// The MPI launcher this process was started by, if any: the variable that
/// says so and the number of processes (unknown for PMIx, which only gives
/// the rank).
pub fn launcher() -> Option<(&'static str, Option<u64>)> {
    SIZE_VARS.iter().find_map(|&var| {
        let value = std::env::var(var).ok()?;
        let size = if var == "PMIX_RANK" { None } else { value.trim().parse().ok() };
        Some((var, size))
    })
}

/// Runs episodes of an evolved stage on this process's rayon pool, in order:
/// what every rank does with a batch.
#[cfg(feature = "mpi")]
pub fn evaluate_local(
    stage: &shaping_runtime::program::Stage,
    actions: u32,
    jobs: &[(&Genome, Episode)],
) -> Vec<Evaluation> {
    let eval = shaping_runtime::evolve::evaluator(
        stage,
        shaping_runtime::evolve::EvalOptions { actions, learning: true },
    );
    shaping_runtime::evolve::evaluate_many(&eval, jobs)
}

/// Rank 0's coordinator evaluates a generation's episodes over the ranks.
impl shaping_engine::run::Evaluate for Coordinator {
    fn evaluate(
        &self,
        program: &shaping_runtime::program::Program,
        index: usize,
        actions: u32,
        jobs: &[(&Genome, Episode)],
    ) -> Vec<Evaluation> {
        Coordinator::evaluate(self, program, index, actions, jobs)
    }

    fn context(&self, what: String, checkpoint: &std::path::Path) {
        self.set_context(what, checkpoint);
    }
}

/// Without the `mpi` feature there is no coordinator: `Option<&Coordinator>`
/// is always `None`.
#[cfg(not(feature = "mpi"))]
pub enum Coordinator {}

#[cfg(not(feature = "mpi"))]
impl Coordinator {
    pub fn evaluate(
        &self,
        _: &shaping_runtime::program::Program,
        _: usize,
        _: u32,
        _: &[(&Genome, Episode)],
    ) -> Vec<Evaluation> {
        match *self {}
    }
    pub fn set_context(&self, _: String, _: &std::path::Path) {
        match *self {}
    }
    pub fn distributes(&self, _: usize) -> bool {
        match *self {}
    }
    pub fn run_tasks(
        &self,
        _: &[(u32, u64)],
        _: &(dyn Fn((u32, u64), usize) -> Result<(), crate::CliError> + Sync + '_),
        _: &(dyn Fn((u32, u64)) -> String + Sync),
    ) -> Result<(), crate::CliError> {
        match *self {}
    }
}
