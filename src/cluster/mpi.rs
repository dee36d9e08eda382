//! The MPI side of [`super`]: rank 0's [`Coordinator`] and the other ranks'
//! [`serve`] loop. Every exchange is a request from a worker answered by one
//! reply from rank 0, so neither side ever waits on a send to a process that
//! is itself sending. Only the main thread calls MPI.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

use mpi::point_to_point::{Destination, MatchedReceiveVec, Source};
use mpi::topology::{Communicator, Rank, SimpleCommunicator};
use mpi::Threading;
use shaping_runtime::evolve::{Episode, Evaluation};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::Program;

use super::wire::{self, Reply, Request};
use crate::CliError;

const TAG_REQUEST: i32 = 1;
const TAG_REPLY: i32 = 2;
/// Pause between two looks for a message when none is there (MPI's own
/// blocking receive would spin a core).
const POLL: Duration = Duration::from_micros(100);

/// Initialises MPI and runs `body` on rank 0 with the coordinator; the other
/// ranks serve batches until rank 0 is done. `jobs` is the rayon thread count
/// of each rank (default: the node's cores shared among its ranks).
///
/// `tasks` runs a whole task (a seed of a sweep point) on a worker rank with
/// the given threads, when rank 0 hands tasks out ([`Coordinator::run_tasks`]).
pub fn with_mpi(
    jobs: Option<usize>,
    rank_timeout: u64,
    quiet: bool,
    tasks: Option<&TaskRunner<'_>>,
    body: impl FnOnce(&Coordinator) -> Result<(), CliError>,
) -> Result<(), CliError> {
    let Some((universe, _)) = mpi::initialize_with_threading(Threading::Funneled) else {
        return Err(CliError::internal("error: MPI was already initialised"));
    };
    let world = universe.world();
    let (rank, size) = (world.rank(), world.size() as usize);
    let on_node = world.split_shared(rank).size().max(1) as usize;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = jobs.unwrap_or_else(|| (cores / on_node).max(1));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| CliError::io(format!("error: rank {rank}: cannot start worker threads: {e}")))?;
    if rank != 0 {
        return serve(&world, &pool, threads, tasks);
    }
    let term = Arc::new(AtomicBool::new(false));
    signal_hook::flag::register(signal_hook::consts::SIGTERM, Arc::clone(&term))
        .map_err(|e| CliError::io(format!("error: cannot watch for SIGTERM: {e}")))?;
    let host = mpi::environment::processor_name().unwrap_or_default();
    let watch = Arc::new(Watch { host: host.clone(), ..Watch::default() });
    watch.spawn();
    let coordinator = Coordinator {
        world,
        size,
        pool,
        threads,
        timeout: Duration::from_secs(rank_timeout.max(1)),
        term,
        host,
        watch,
        state: RefCell::new(State::default()),
    };
    let result = body(&coordinator);
    coordinator.finish();
    if !quiet {
        coordinator.report(threads);
    }
    result
}

/// Runs one task (a point of a sweep and a seed) with this many threads.
pub type TaskRunner<'a> = dyn Fn((u32, u64), usize) -> Result<(), CliError> + Sync + 'a;

/// Rank 0's side: spreads the episodes of a generation, or whole tasks, over
/// the ranks.
pub struct Coordinator {
    world: SimpleCommunicator,
    size: usize,
    pool: rayon::ThreadPool,
    /// Threads of each rank's pool (and of a task run on rank 0).
    threads: usize,
    timeout: Duration,
    term: Arc<AtomicBool>,
    host: String,
    /// Names a dead rank of this node from a thread of its own.
    watch: Arc<Watch>,
    state: RefCell<State>,
}

/// A watcher on rank 0: when a worker rank of this node dies, mpirun ends
/// the job and may kill rank 0 before its main thread, busy between two
/// looks (the generation's selection, the checkpoint), names the rank. The
/// watcher looks every [`WATCH`] and says it at once; the main thread then
/// only ends the run ([`Coordinator::check_term`]). It never calls MPI.
#[derive(Default)]
struct Watch {
    host: String,
    seen: Mutex<Seen>,
    /// The message was printed (by the watcher or the main thread).
    reported: AtomicBool,
    /// The run is ending normally: workers leave, stop looking.
    stop: AtomicBool,
}

/// What the watcher knows: the workers, what is being evaluated and the
/// checkpoint to resume from.
#[derive(Default)]
struct Seen {
    workers: Vec<(Rank, u32, String)>,
    context: String,
    checkpoint: PathBuf,
}

/// Pause between two looks of the watcher.
const WATCH: Duration = Duration::from_millis(10);

impl Watch {
    fn spawn(self: &Arc<Self>) {
        let me = Arc::clone(self);
        std::thread::spawn(move || {
            while !me.stop.load(Ordering::SeqCst) {
                if let Some(message) = me.dead_message() {
                    // One write of the whole message, so that an abort by the
                    // main thread cannot cut it.
                    if !me.reported.swap(true, Ordering::SeqCst) {
                        eprint!("{message}");
                    }
                    return;
                }
                std::thread::sleep(WATCH);
            }
        });
    }

    fn seen(&self) -> std::sync::MutexGuard<'_, Seen> {
        self.seen.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The error message naming the workers of this node that are gone, if any.
    fn dead_message(&self) -> Option<String> {
        let seen = self.seen();
        let mut dead: Vec<&(Rank, u32, String)> =
            seen.workers.iter().filter(|(_, pid, host)| *host == self.host && !alive(*pid)).collect();
        if dead.is_empty() {
            return None;
        }
        dead.sort_unstable_by_key(|w| w.0);
        let names: Vec<String> =
            dead.iter().map(|(rank, pid, host)| format!("rank {rank} (pid {pid} on {host})")).collect();
        let what = format!("{} died during {}, and mpirun ended the run", names.join(", "), seen.context);
        Some(error_message(&what, &seen.checkpoint))
    }
}

/// `error: WHAT`, and how to resume from `checkpoint` when there is one.
fn error_message(what: &str, checkpoint: &Path) -> String {
    let resume = if checkpoint.as_os_str().is_empty() {
        String::new()
    } else {
        format!(
            "; the checkpoint `{}` is valid: run the same command again (without `--fresh`), with any number of ranks, to resume",
            checkpoint.display()
        )
    };
    format!("\nerror: {what}{resume}\n")
}

#[derive(Default)]
struct State {
    workers: HashMap<Rank, Worker>,
    /// Workers waiting for a reply with nothing to do.
    idle: Vec<Rank>,
    /// Version of the program last loaded (0: none yet) and its JSON.
    version: u32,
    program: Vec<u8>,
    next_batch: u64,
    /// What is being evaluated and the checkpoint to resume from, for messages.
    context: String,
    checkpoint: PathBuf,
    stats: Stats,
}

/// What [`Coordinator::hand_out`] hands out: `count` items, run by a
/// thread of rank 0 with `local` or by another rank; `prepare` may first
/// send a worker something else (then it takes no item yet), `give` is the
/// message giving item `k`, `take` reads the answer to item `k` (ending the
/// run on a wrong one), `late` says what a rank did not do in time.
struct Items<'a, T> {
    count: usize,
    local: &'a (dyn Fn(usize) -> Result<T, String> + Sync),
    prepare: &'a dyn Fn(&mut State, Rank) -> bool,
    give: &'a dyn Fn(usize) -> Vec<u8>,
    take: &'a dyn Fn(&State, Rank, usize, Request) -> T,
    late: &'a dyn Fn(&State, usize) -> String,
}

impl<T> Clone for Items<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Items<'_, T> {}

struct Worker {
    pid: u32,
    host: String,
    version: u32,
}

#[derive(Default)]
struct Stats {
    /// Whole tasks run, and those run on other ranks.
    tasks: u64,
    remote_tasks: u64,
    rounds: u64,
    episodes: u64,
    remote_episodes: u64,
    messages: u64,
    bytes: u64,
    /// Time rank 0 spent in sends and in receives of messages that were there.
    in_mpi: Duration,
    /// Wall time of the rounds.
    wall: Duration,
}

impl Coordinator {
    /// Names what the next evaluations are for, and the checkpoint a new run
    /// would resume from, for the failure messages.
    pub fn set_context(&self, what: String, checkpoint: &Path) {
        let mut st = self.state.borrow_mut();
        let mut seen = self.watch.seen();
        seen.context.clone_from(&what);
        seen.checkpoint = checkpoint.to_path_buf();
        st.context = what;
        st.checkpoint = checkpoint.to_path_buf();
    }

    /// A worker said hello: its pid and host, for messages and the watcher.
    fn hello(&self, st: &mut State, rank: Rank, pid: u32, host: String) {
        self.watch.seen().workers.push((rank, pid, host.clone()));
        st.workers.insert(rank, Worker { pid, host, version: 0 });
    }

    /// Runs episodes of evolved stage `index` (`actions` actions, learning on)
    /// over every rank and returns the results in order.
    pub fn evaluate(
        &self,
        program: &Program,
        index: usize,
        actions: u32,
        jobs: &[(&Genome, Episode)],
    ) -> Vec<Evaluation> {
        let started = Instant::now();
        let stage = &program.stages[index];
        let mut st = self.state.borrow_mut();
        if self.size == 1 {
            let out = self.pool.install(|| super::evaluate_local(stage, actions, jobs));
            st.stats.rounds += 1;
            st.stats.episodes += jobs.len() as u64;
            st.stats.wall += started.elapsed();
            return out;
        }
        self.load(&mut st, program);
        let bounds = wire::batches(jobs.len(), self.size);
        let base = st.next_batch;
        st.next_batch += bounds.len() as u64;
        let version = st.version;
        let pool = &self.pool;
        let local = |k: usize| {
            let (a, b) = bounds[k];
            Ok(pool.install(|| super::evaluate_local(stage, actions, &jobs[a..b])))
        };
        // A worker that has not loaded this program gets it first.
        let prepare = |st: &mut State, rank: Rank| {
            let known = st.workers.get(&rank).map_or(0, |w| w.version);
            if known == version {
                return false;
            }
            let msg = Reply::Load { version, program: st.program.clone() }.encode();
            self.send(st, rank, &msg);
            if let Some(w) = st.workers.get_mut(&rank) {
                w.version = version;
            }
            true
        };
        let give = |k: usize| {
            let (a, b) = bounds[k];
            Reply::encode_work(version, base + k as u64, index as u32, actions, &jobs[a..b])
        };
        let take = |st: &State, rank: Rank, k: usize, request: Request| {
            let (a, b) = bounds[k];
            match request {
                Request::Results { batch, evaluations }
                    if batch == base + k as u64 && evaluations.len() == b - a =>
                {
                    evaluations
                }
                Request::Results { batch, evaluations } => self.fatal(
                    st,
                    format!(
                        "rank {rank} answered batch {} with {} results for batch {batch}, {} expected",
                        base + k as u64,
                        evaluations.len(),
                        b - a
                    ),
                ),
                _ => self
                    .fatal(st, format!("rank {rank} did not answer batch {} with results", base + k as u64)),
            }
        };
        let late = |st: &State, _: usize| {
            format!("answer within {} s during {}", self.timeout.as_secs(), st.context)
        };
        let (results, remote) = self.hand_out(
            &mut st,
            &Items {
                count: bounds.len(),
                local: &local,
                prepare: &prepare,
                give: &give,
                take: &take,
                late: &late,
            },
            &mut |_, _| {},
        );
        st.stats.rounds += 1;
        st.stats.episodes += jobs.len() as u64;
        st.stats.remote_episodes +=
            results.iter().zip(&remote).filter(|(_, r)| **r).map(|(e, _)| e.len() as u64).sum::<u64>();
        st.stats.wall += started.elapsed();
        results.into_iter().flatten().collect()
    }

    /// Whether an experiment of `tasks` tasks hands whole tasks to ranks
    /// ([`wire::distribute_tasks`]).
    pub fn distributes(&self, tasks: usize) -> bool {
        wire::distribute_tasks(tasks, self.size)
    }

    /// Runs whole tasks over the ranks: each rank (rank 0 on a thread of its
    /// own) runs a task at a time and writes its files, asking for the next
    /// when it reports the last done; rank 0 only hands them out.
    pub fn run_tasks(
        &self,
        tasks: &[(u32, u64)],
        run: &TaskRunner<'_>,
        describe: &(dyn Fn((u32, u64)) -> String + Sync),
    ) -> Result<(), CliError> {
        let started = Instant::now();
        let mut st = self.state.borrow_mut();
        let threads = self.threads;
        let local = |k: usize| {
            run(tasks[k], threads).map_err(|e| {
                format!("rank 0, {}: {}", describe(tasks[k]), e.to_string().trim_start_matches("error: "))
            })
        };
        let give = |k: usize| {
            let (point, seed) = tasks[k];
            Reply::Task { point, seed }.encode()
        };
        let take = |st: &State, rank: Rank, k: usize, request: Request| match request {
            Request::Done { point, seed } if tasks[k] == (point, seed) => {}
            _ => self.fatal(st, format!("rank {rank} did not report {} done", describe(tasks[k]))),
        };
        let late = |_: &State, k: usize| {
            format!(
                "report {} within {} s (`--rank-timeout` bounds a whole seed)",
                describe(tasks[k]),
                self.timeout.as_secs()
            )
        };
        let count = tasks.len();
        let mut done = 0;
        let mut progress = |k: usize, rank: Rank| {
            done += 1;
            eprintln!("{} done on rank {rank} ({done}/{count})", describe(tasks[k]));
        };
        let (_, remote) = self.hand_out(
            &mut st,
            &Items { count, local: &local, prepare: &|_, _| false, give: &give, take: &take, late: &late },
            &mut progress,
        );
        st.stats.tasks += count as u64;
        st.stats.remote_tasks += remote.iter().filter(|&&r| r).count() as u64;
        st.stats.wall += started.elapsed();
        Ok(())
    }

    /// Hands `items` out, one per request, to the other ranks and to a
    /// thread of rank 0, until every item is done; returns the results in
    /// item order and, per item, whether another rank did it. `done_at`
    /// hears of every item done and where.
    fn hand_out<T: Send>(
        &self,
        st: &mut State,
        items: &Items<'_, T>,
        done_at: &mut dyn FnMut(usize, Rank),
    ) -> (Vec<T>, Vec<bool>) {
        let Items { count, local, prepare, give, take, late } = *items;
        let next = AtomicUsize::new(0);
        let mut results: Vec<Option<T>> = (0..count).map(|_| None).collect();
        let mut remote = vec![false; count];
        let mut done = 0;
        let mut outstanding: HashMap<Rank, (usize, Instant)> = HashMap::new();
        std::thread::scope(|s| {
            let (tx, rx) = mpsc::channel();
            let next = &next;
            s.spawn(move || loop {
                let k = next.fetch_add(1, Ordering::SeqCst);
                if k >= count {
                    break;
                }
                let out = local(k);
                let failed = out.is_err();
                if tx.send((k, out)).is_err() || failed {
                    break;
                }
            });
            let mut local_gone = false;
            // Hands the next item (or what must come first) to a waiting worker.
            let hand = |st: &mut State, rank: Rank, outstanding: &mut HashMap<Rank, (usize, Instant)>| {
                if prepare(st, rank) {
                    return;
                }
                let k = next.fetch_add(1, Ordering::SeqCst);
                if k < count {
                    self.send(st, rank, &give(k));
                    outstanding.insert(rank, (k, Instant::now()));
                } else if !st.idle.contains(&rank) {
                    st.idle.push(rank);
                }
            };
            let waiting = std::mem::take(&mut st.idle);
            for rank in waiting {
                hand(st, rank, &mut outstanding);
            }
            while done < count {
                let mut busy = false;
                while let Some((rank, request)) = self.poll(st) {
                    busy = true;
                    match request {
                        Request::Hello { pid, host } => self.hello(st, rank, pid, host),
                        Request::Ready => {}
                        Request::Failed { message } => self.fatal(st, format!("rank {rank}: {message}")),
                        answer => {
                            let Some((k, _)) = outstanding.remove(&rank) else {
                                self.fatal(st, format!("rank {rank} sent an answer it was not asked for"));
                            };
                            results[k] = Some(take(st, rank, k, answer));
                            remote[k] = true;
                            done += 1;
                            done_at(k, rank);
                        }
                    }
                    hand(st, rank, &mut outstanding);
                }
                loop {
                    match rx.try_recv() {
                        Ok((k, Ok(out))) => {
                            results[k] = Some(out);
                            done += 1;
                            busy = true;
                            done_at(k, 0);
                        }
                        Ok((_, Err(message))) => self.fatal(st, message),
                        Err(mpsc::TryRecvError::Empty) => break,
                        Err(mpsc::TryRecvError::Disconnected) => {
                            local_gone = true;
                            break;
                        }
                    }
                }
                if local_gone
                    && done < count
                    && outstanding.is_empty()
                    && next.load(Ordering::SeqCst) >= count
                {
                    self.fatal(st, "an evaluation on rank 0 failed".into());
                }
                self.check_late(st, &outstanding, late);
                self.check_term(st, &outstanding);
                if !busy {
                    std::thread::sleep(POLL);
                }
            }
        });
        (results.into_iter().flatten().collect(), remote)
    }

    /// Ends the run when a rank has held its item longer than the timeout
    /// (`late` says what it did not do).
    fn check_late(
        &self,
        st: &mut State,
        outstanding: &HashMap<Rank, (usize, Instant)>,
        late: &dyn Fn(&State, usize) -> String,
    ) {
        if let Some((&rank, &(k, _))) = outstanding.iter().find(|(_, (_, t))| t.elapsed() > self.timeout) {
            let msg = format!(
                "{} did not {}: it died or hangs (`--rank-timeout` sets the limit)",
                self.who(st, rank),
                late(st, k)
            );
            self.fatal(st, msg);
        }
    }

    /// Makes `program` the one batches refer to (a new version when it changed).
    fn load(&self, st: &mut State, program: &Program) {
        let json = serde_json::to_vec(program).unwrap_or_default();
        if st.version == 0 || json != st.program {
            st.version += 1;
            st.program = json;
        }
    }

    /// Sends without blocking on a rank that hangs (a large message waits
    /// for the receiver): gives up after the timeout.
    fn send(&self, st: &mut State, rank: Rank, msg: &[u8]) {
        let t = Instant::now();
        mpi::request::scope(|scope| {
            let mut request = self.world.process_at_rank(rank).immediate_send_with_tag(scope, msg, TAG_REPLY);
            loop {
                match request.test() {
                    Ok(_) => return,
                    Err(pending) => request = pending,
                }
                self.check_term(st, &HashMap::from([(rank, (0, t))]));
                if t.elapsed() > self.timeout {
                    // MPI_Abort ends the process with the request pending.
                    let msg = format!(
                        "{} did not take a message within {} s during {}: it died or hangs (`--rank-timeout` sets the limit)",
                        self.who(st, rank),
                        self.timeout.as_secs(),
                        st.context
                    );
                    self.fatal(st, msg);
                }
                std::thread::sleep(POLL);
            }
        });
        st.stats.in_mpi += t.elapsed();
        st.stats.messages += 1;
        st.stats.bytes += msg.len() as u64;
    }

    /// The next request from any worker, if one is there.
    fn poll(&self, st: &mut State) -> Option<(Rank, Request)> {
        let t = Instant::now();
        let probed = self.world.any_process().immediate_matched_probe_with_tag(TAG_REQUEST)?;
        let (bytes, status) = probed.matched_receive_vec::<u8>();
        st.stats.in_mpi += t.elapsed();
        st.stats.messages += 1;
        st.stats.bytes += bytes.len() as u64;
        let rank = status.source_rank();
        match Request::decode(&bytes) {
            Ok(r) => Some((rank, r)),
            Err(e) => self.fatal(st, format!("cannot read a message from rank {rank}: {e}")),
        }
    }

    /// Waits until every worker is waiting for a reply and tells it to leave.
    fn finish(&self) {
        let mut st = self.state.borrow_mut();
        let started = Instant::now();
        loop {
            while let Some((rank, request)) = self.poll(&mut st) {
                match request {
                    Request::Hello { pid, host } => self.hello(&mut st, rank, pid, host),
                    Request::Failed { message } => self.fatal(&st, format!("rank {rank}: {message}")),
                    Request::Ready | Request::Results { .. } | Request::Done { .. } => {}
                }
                if !st.idle.contains(&rank) {
                    st.idle.push(rank);
                }
            }
            if st.idle.len() + 1 >= self.size {
                break;
            }
            if started.elapsed() > self.timeout {
                let missing: Vec<Rank> = (1..self.size as Rank).filter(|r| !st.idle.contains(r)).collect();
                let msg = format!(
                    "rank {} did not report within {} s at the end of the run (`--rank-timeout` sets the limit)",
                    missing.first().copied().unwrap_or(0),
                    self.timeout.as_secs()
                );
                self.fatal(&st, msg);
            }
            self.check_term(&st, &HashMap::new());
            std::thread::sleep(POLL);
        }
        self.watch.stop.store(true, Ordering::SeqCst);
        let idle = std::mem::take(&mut st.idle);
        let stop = Reply::Stop.encode();
        for rank in idle {
            self.send(&mut st, rank, &stop);
        }
    }

    fn report(&self, threads: usize) {
        let st = self.state.borrow();
        let s = &st.stats;
        let rounds = s.rounds.max(1) as f64;
        if s.tasks > 0 {
            eprintln!(
                "mpi: {} ranks x {threads} threads; {} tasks (whole seeds), {} on other ranks, in {:.2} s; {} messages, {:.1} us each",
                self.size,
                s.tasks,
                s.remote_tasks,
                s.wall.as_secs_f64(),
                s.messages,
                s.in_mpi.as_secs_f64() * 1e6 / s.messages.max(1) as f64,
            );
            return;
        }
        eprintln!(
            "mpi: {} ranks x {threads} threads; {} rounds, {} episodes ({} on other ranks), {:.0} episodes/s; {} messages, {:.2} MB, {:.1} us each; rank 0 spent {:.3} ms per round in sends and receives, {:.1} ms per round in all",
            self.size,
            s.rounds,
            s.episodes,
            s.remote_episodes,
            s.episodes as f64 / s.wall.as_secs_f64().max(1e-9),
            s.messages,
            s.bytes as f64 / 1e6,
            s.in_mpi.as_secs_f64() * 1e6 / s.messages.max(1) as f64,
            s.in_mpi.as_secs_f64() * 1e3 / rounds,
            s.wall.as_secs_f64() * 1e3 / rounds,
        );
    }

    fn who(&self, st: &State, rank: Rank) -> String {
        match st.workers.get(&rank) {
            Some(w) => format!("rank {rank} (pid {} on {})", w.pid, w.host),
            None => format!("rank {rank}"),
        }
    }

    /// mpirun sends SIGTERM to the surviving ranks when one dies (or when the
    /// job is interrupted): say which rank is gone, if it ran on this node.
    fn check_term(&self, st: &State, outstanding: &HashMap<Rank, (usize, Instant)>) {
        if self.watch.reported.load(Ordering::SeqCst) {
            // The watcher named the dead rank: leave it the time to write.
            std::thread::sleep(10 * WATCH);
            self.world.abort(1)
        }
        if !self.term.load(Ordering::SeqCst) {
            return;
        }
        let mut dead: Vec<Rank> = st
            .workers
            .iter()
            .filter(|(_, w)| w.host == self.host && !alive(w.pid))
            .map(|(&r, _)| r)
            .collect();
        dead.sort_unstable();
        let what = if dead.is_empty() {
            let mut waiting: Vec<Rank> = outstanding.keys().copied().collect();
            waiting.sort_unstable();
            format!(
                "mpirun ended the run during {} (a rank died on another node, or the job was interrupted; rank 0 was waiting for ranks {waiting:?})",
                st.context
            )
        } else {
            let names: Vec<String> = dead.iter().map(|&r| self.who(st, r)).collect();
            format!("{} died during {}, and mpirun ended the run", names.join(", "), st.context)
        };
        self.fatal(st, what);
    }

    fn fatal(&self, st: &State, what: String) -> ! {
        if !self.watch.reported.swap(true, Ordering::SeqCst) {
            eprint!("{}", error_message(&what, &st.checkpoint));
        } else {
            std::thread::sleep(10 * WATCH);
        }
        self.world.abort(1)
    }
}

/// A process of this node is alive (a zombie is not).
fn alive(pid: u32) -> bool {
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        Ok(stat) => stat.rsplit_once(')').is_none_or(|(_, rest)| !rest.trim_start().starts_with('Z')),
        Err(_) => false,
    }
}

/// A worker rank: evaluates the batches rank 0 sends until told to stop.
fn serve(
    world: &SimpleCommunicator,
    pool: &rayon::ThreadPool,
    threads: usize,
    tasks: Option<&TaskRunner<'_>>,
) -> Result<(), CliError> {
    let root = world.process_at_rank(0);
    let send = |r: Request| root.send_with_tag(&r.encode()[..], TAG_REQUEST);
    let receive = || loop {
        if let Some(probed) = root.immediate_matched_probe_with_tag(TAG_REPLY) {
            return probed.matched_receive_vec::<u8>().0;
        }
        std::thread::sleep(POLL);
    };
    // After a failure rank 0 ends the job; wait for it.
    let fail = |message: String| -> ! {
        send(Request::Failed { message });
        loop {
            std::thread::sleep(Duration::from_secs(1));
        }
    };
    let host = mpi::environment::processor_name().unwrap_or_default();
    send(Request::Hello { pid: std::process::id(), host });
    let mut program: Option<(u32, Program)> = None;
    loop {
        match Reply::decode(&receive()) {
            Err(e) => fail(format!("cannot read a message from rank 0: {e}")),
            Ok(Reply::Stop) => return Ok(()),
            Ok(Reply::Task { point, seed }) => {
                let Some(run) = tasks else { fail("a task came to a rank that runs no experiment".into()) };
                match run((point, seed), threads) {
                    Ok(()) => send(Request::Done { point, seed }),
                    Err(e) => fail(e.to_string().trim_start_matches("error: ").to_string()),
                }
            }
            Ok(Reply::Load { version, program: json }) => match serde_json::from_slice::<Program>(&json) {
                Ok(p) => {
                    program = Some((version, p));
                    send(Request::Ready);
                }
                Err(e) => fail(format!("cannot read the program rank 0 sent: {e}")),
            },
            Ok(Reply::Work { version, batch, stage, actions, jobs }) => {
                let Some((loaded, p)) = &program else { fail("work came before the program".into()) };
                if *loaded != version {
                    fail(format!("work for program version {version}, version {loaded} is loaded"));
                }
                let Some(st) = p.stages.get(stage as usize) else {
                    fail(format!("work for stage {stage}, the program has {}", p.stages.len()))
                };
                let refs: Vec<(&Genome, Episode)> = jobs.iter().map(|(episode, g)| (g, *episode)).collect();
                let evaluations = pool.install(|| super::evaluate_local(st, actions, &refs));
                send(Request::Results { batch, evaluations });
            }
        }
    }
}
