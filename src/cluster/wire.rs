//! The messages between rank 0 and the other ranks, as bytes: a kind byte,
//! then little-endian integers and length-prefixed byte strings. Fitness
//! travels as its bit pattern, so a result is the same on every rank.

use shaping_runtime::evolve::{Episode, Evaluation, Events};
use shaping_runtime::genome::Genome;

/// From a worker rank to rank 0: each is also a request for the next reply.
#[derive(Debug, PartialEq)]
pub enum Request {
    /// First message of a worker: who it is (for error messages).
    Hello { pid: u32, host: String },
    /// Ready for work (after loading a program).
    Ready,
    /// The results of a batch, in the batch's order.
    Results { batch: u64, evaluations: Vec<Evaluation> },
    /// The worker cannot go on.
    Failed { message: String },
    /// A task (a whole seed of a sweep point) is done: its files are written.
    Done { point: u32, seed: u64 },
}

/// From rank 0 to a worker, always in answer to a [`Request`].
#[derive(Debug, PartialEq)]
pub enum Reply {
    /// The program (JSON) that later batches refer to by `version`.
    Load { version: u32, program: Vec<u8> },
    /// Episodes of stage `stage`, each `(episode seed, genome)`, with
    /// `actions` actions and local learning on.
    Work { version: u32, batch: u64, stage: u32, actions: u32, jobs: Vec<(Episode, Genome)> },
    /// The run is over: leave.
    Stop,
    /// Run a whole seed of a sweep point and write its files.
    Task { point: u32, seed: u64 },
}

#[derive(Default)]
struct Writer(Vec<u8>);

impl Writer {
    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn bytes(&mut self, v: &[u8]) {
        self.u32(v.len() as u32);
        self.0.extend_from_slice(v);
    }
    /// An episode: its seed, then its variant (`u32::MAX`: none).
    fn episode(&mut self, e: Episode) {
        self.u64(e.seed);
        self.u32(e.variant.map_or(u32::MAX, |v| v as u32));
    }
}

struct Reader<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len());
        let end =
            end.ok_or_else(|| format!("message truncated at byte {} of {}", self.pos, self.data.len()))?;
        let s = &self.data[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    fn u64(&mut self) -> Result<u64, String> {
        let b = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(u64::from_le_bytes(a))
    }
    fn bytes(&mut self) -> Result<&'a [u8], String> {
        let n = self.u32()? as usize;
        self.take(n)
    }
    fn episode(&mut self) -> Result<Episode, String> {
        let seed = self.u64()?;
        let variant = Some(self.u32()?).filter(|&v| v != u32::MAX).map(|v| v as usize);
        Ok(Episode { seed, variant })
    }
    fn string(&mut self) -> Result<String, String> {
        Ok(String::from_utf8_lossy(self.bytes()?).into_owned())
    }
    fn end(&self) -> Result<(), String> {
        if self.pos == self.data.len() {
            Ok(())
        } else {
            Err(format!("{} bytes left over at the end of a message", self.data.len() - self.pos))
        }
    }
}

impl Request {
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Writer::default();
        match self {
            Request::Hello { pid, host } => {
                w.u8(0);
                w.u32(*pid);
                w.bytes(host.as_bytes());
            }
            Request::Ready => w.u8(1),
            Request::Results { batch, evaluations } => {
                w.u8(2);
                w.u64(*batch);
                w.u32(evaluations.len() as u32);
                for ev in evaluations {
                    w.u32(ev.fitness.to_bits());
                    w.u32(ev.events.grips);
                    w.u32(ev.events.releases_outside);
                    w.u32(ev.events.recharges);
                    w.u32(ev.placement_failures);
                    match &ev.learned {
                        Some(g) => {
                            w.u8(1);
                            w.bytes(&g.bits);
                        }
                        None => w.u8(0),
                    }
                }
            }
            Request::Failed { message } => {
                w.u8(3);
                w.bytes(message.as_bytes());
            }
            Request::Done { point, seed } => {
                w.u8(4);
                w.u32(*point);
                w.u64(*seed);
            }
        }
        w.0
    }

    pub fn decode(data: &[u8]) -> Result<Request, String> {
        let mut r = Reader { data, pos: 0 };
        let request = match r.u8()? {
            0 => Request::Hello { pid: r.u32()?, host: r.string()? },
            1 => Request::Ready,
            2 => {
                let batch = r.u64()?;
                let n = r.u32()? as usize;
                let mut evaluations = Vec::with_capacity(n.min(data.len()));
                for _ in 0..n {
                    let fitness = f32::from_bits(r.u32()?);
                    let events = Events { grips: r.u32()?, releases_outside: r.u32()?, recharges: r.u32()? };
                    let placement_failures = r.u32()?;
                    let learned = match r.u8()? {
                        0 => None,
                        1 => Some(Genome { bits: r.bytes()?.to_vec() }),
                        k => return Err(format!("unknown learned-genome flag {k}")),
                    };
                    evaluations.push(Evaluation { fitness, learned, events, placement_failures });
                }
                Request::Results { batch, evaluations }
            }
            3 => Request::Failed { message: r.string()? },
            4 => Request::Done { point: r.u32()?, seed: r.u64()? },
            k => return Err(format!("unknown request kind {k}")),
        };
        r.end()?;
        Ok(request)
    }
}

impl Reply {
    pub fn encode(&self) -> Vec<u8> {
        let mut w = Writer::default();
        match self {
            Reply::Load { version, program } => {
                w.u8(0);
                w.u32(*version);
                w.bytes(program);
            }
            Reply::Work { version, batch, stage, actions, jobs } => {
                w.u8(1);
                w.u32(*version);
                w.u64(*batch);
                w.u32(*stage);
                w.u32(*actions);
                w.u32(jobs.len() as u32);
                for (episode, genome) in jobs {
                    w.episode(*episode);
                    w.bytes(&genome.bits);
                }
            }
            Reply::Stop => w.u8(2),
            Reply::Task { point, seed } => {
                w.u8(3);
                w.u32(*point);
                w.u64(*seed);
            }
        }
        w.0
    }

    /// Encodes a [`Reply::Work`] from borrowed genomes (rank 0 does not copy them).
    pub fn encode_work(
        version: u32,
        batch: u64,
        stage: u32,
        actions: u32,
        jobs: &[(&Genome, Episode)],
    ) -> Vec<u8> {
        let mut w = Writer::default();
        w.u8(1);
        w.u32(version);
        w.u64(batch);
        w.u32(stage);
        w.u32(actions);
        w.u32(jobs.len() as u32);
        for (genome, episode) in jobs {
            w.episode(*episode);
            w.bytes(&genome.bits);
        }
        w.0
    }

    pub fn decode(data: &[u8]) -> Result<Reply, String> {
        let mut r = Reader { data, pos: 0 };
        let reply = match r.u8()? {
            0 => Reply::Load { version: r.u32()?, program: r.bytes()?.to_vec() },
            1 => {
                let (version, batch, stage, actions) = (r.u32()?, r.u64()?, r.u32()?, r.u32()?);
                let n = r.u32()? as usize;
                let mut jobs = Vec::with_capacity(n.min(data.len()));
                for _ in 0..n {
                    let episode = r.episode()?;
                    jobs.push((episode, Genome { bits: r.bytes()?.to_vec() }));
                }
                Reply::Work { version, batch, stage, actions, jobs }
            }
            2 => Reply::Stop,
            3 => Reply::Task { point: r.u32()?, seed: r.u64()? },
            k => return Err(format!("unknown reply kind {k}")),
        };
        r.end()?;
        Ok(reply)
    }
}

/// How an experiment uses the ranks, by the work there is: whole tasks
/// (seeds of sweep points) to ranks when there are at least as many tasks as
/// ranks, so the ranks work independently and only report back; else the
/// tasks one after the other, each generation's episodes in batches over
/// every rank (a single large run).
pub fn distribute_tasks(tasks: usize, ranks: usize) -> bool {
    ranks > 1 && tasks >= ranks
}

/// Splits `jobs` episodes into batches for `ranks` processes: about four per
/// rank, so that a rank that finishes early takes another while a slow one is
/// still busy. Returns the batch boundaries (start, end), in order.
pub fn batches(jobs: usize, ranks: usize) -> Vec<(usize, usize)> {
    if jobs == 0 {
        return Vec::new();
    }
    let size = jobs.div_ceil(4 * ranks.max(1)).max(1);
    (0..jobs).step_by(size).map(|s| (s, (s + size).min(jobs))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_round_trip_bit_for_bit() {
        let odd = f32::from_bits(0x7f7f_fffe);
        let cases = [
            Request::Hello { pid: 4242, host: "node-7".into() },
            Request::Ready,
            Request::Results {
                batch: u64::MAX - 3,
                evaluations: vec![
                    Evaluation {
                        fitness: -0.0,
                        learned: None,
                        events: Events::default(),
                        placement_failures: 0,
                    },
                    Evaluation {
                        fitness: odd,
                        learned: Some(Genome { bits: vec![1, 0, 1, 1] }),
                        events: Events { grips: 3, releases_outside: 2, recharges: 1 },
                        placement_failures: 5,
                    },
                ],
            },
            Request::Failed { message: "stage 9 does not exist".into() },
            Request::Done { point: 7, seed: u64::MAX },
        ];
        for case in cases {
            let back = Request::decode(&case.encode()).unwrap();
            assert_eq!(back, case);
            if let Request::Results { evaluations, .. } = &back {
                assert_eq!(evaluations[0].fitness.to_bits(), (-0.0f32).to_bits());
            }
        }
    }

    #[test]
    fn replies_round_trip_and_borrowed_work_matches() {
        let g = [Genome { bits: vec![0, 1, 1] }, Genome { bits: vec![] }];
        let work = Reply::Work {
            version: 3,
            batch: 17,
            stage: 2,
            actions: 300,
            jobs: vec![
                (Episode::plain(9), g[0].clone()),
                (Episode { seed: u64::MAX, variant: Some(63) }, g[1].clone()),
            ],
        };
        let borrowed: Vec<(&Genome, Episode)> =
            vec![(&g[0], Episode::plain(9)), (&g[1], Episode { seed: u64::MAX, variant: Some(63) })];
        assert_eq!(work.encode(), Reply::encode_work(3, 17, 2, 300, &borrowed));
        let task = Reply::Task { point: u32::MAX, seed: 12 };
        for case in [work, Reply::Load { version: 1, program: b"{}".to_vec() }, Reply::Stop, task] {
            assert_eq!(Reply::decode(&case.encode()).unwrap(), case);
        }
    }

    #[test]
    fn bad_messages_are_errors_not_panics() {
        assert!(Request::decode(&[]).unwrap_err().contains("truncated"));
        assert!(Request::decode(&[9]).unwrap_err().contains("unknown request kind 9"));
        assert!(Reply::decode(&[2, 0]).unwrap_err().contains("left over"));
        let mut work = Reply::encode_work(1, 1, 0, 10, &[(&Genome { bits: vec![1; 8] }, Episode::plain(5))]);
        work.truncate(work.len() - 2);
        assert!(Reply::decode(&work).unwrap_err().contains("truncated"));
        // A length prefix larger than the message.
        assert!(Request::decode(&[3, 255, 255, 255, 255]).unwrap_err().contains("truncated"));
    }

    #[test]
    fn whole_tasks_go_to_ranks_only_when_there_are_enough() {
        assert!(distribute_tasks(6, 2));
        assert!(distribute_tasks(400, 64));
        assert!(!distribute_tasks(1, 8), "one large run keeps the batches");
        assert!(!distribute_tasks(3, 4));
        assert!(!distribute_tasks(5, 1), "one rank has nothing to distribute");
    }

    #[test]
    fn batches_cover_every_job_once_in_order() {
        for (jobs, ranks) in [(100, 1), (100, 3), (7, 5), (1, 64), (10_000, 64), (0, 2)] {
            let b = batches(jobs, ranks);
            let mut next = 0;
            for &(s, e) in &b {
                assert_eq!(s, next);
                assert!(e > s);
                next = e;
            }
            assert_eq!(next, jobs);
            assert!(b.len() <= 4 * ranks, "{jobs} jobs on {ranks} ranks: {} batches", b.len());
        }
        assert_eq!(batches(100, 3), (0..100).step_by(9).map(|s| (s, (s + 9).min(100))).collect::<Vec<_>>());
    }
}
