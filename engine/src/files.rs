//! The file system under a run directory: whole-file writes that a crash
//! or a second writer cannot tear, the lock that keeps one writer per
//! directory, and the checksum of saved results.
//!
//! - [`write_atomic`]: a new temporary file with a unique name beside the
//!   target, opened create-new (so a symbolic link planted there is never
//!   followed), written, synced, then renamed over the target, and the
//!   directory synced; a failed write removes its temporary file. A reader
//!   sees the old file or the new one, never a part.
//! - [`DirLock`]: an OS file lock (`flock`) on `DIR/.lock`, held while a
//!   run or an experiment writes into `DIR`; a second one is refused at once,
//!   naming the process that holds it. The lock goes away with its holder,
//!   also after `kill -9`; the file stays (empty of meaning), readers never
//!   take it.
//! - [`seal`] and [`unseal`]: a saved result (`checkpoint.json`,
//!   `trained.json`) ends with a `"checksum"` field, the FNV-1a of the rest
//!   of the text; reading verifies it.
//! - [`write_sealed`] and [`read_checked`]: every file a report or a resume
//!   reads is sealed in its directory's [`SEALS`] (`.seals`: each file's
//!   FNV-1a, itself sealed), written by the one writer of the directory
//!   around the files: first the new checksums beside the old, then the
//!   files, then the new ones alone, so a kill anywhere leaves each file
//!   matching its seal. A file whose seal does not match is `Corrupt`,
//!   naming it; a file with no seal (a directory written before seals) is
//!   read, and the caller is told ([`Unsealed`]) so that it warns.
//! - [`remove_stale_temporaries`]: under a new lock, the temporary files
//!   that killed processes left behind.

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::{Read as _, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use shaping_runtime::evolve::fingerprint::fnv1a;

use crate::error::{Error, ErrorKind, Result, Subject};

/// Reads a file, mapping I/O errors to a message that names the path.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| Error::of_io("read", path, &e))
}

/// The largest input read whole: a source file, a built program, standard
/// input of `fmt` (64 MiB; real architecture files are a few kB).
pub const MAX_INPUT_BYTES: u64 = 64 << 20;

/// Reads at most [`MAX_INPUT_BYTES`] from `reader` (named `name` in the
/// error): more is refused before it is all read (`/dev/zero` ends).
pub fn read_input(mut reader: impl std::io::Read, name: &str) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    (&mut reader)
        .take(MAX_INPUT_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::of_io("read", Path::new(name), &e))?;
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        let message = format!(
            "error: `{name}` is larger than {} MiB, the most an input may hold",
            MAX_INPUT_BYTES >> 20
        );
        let subject = Subject::File { path: name.into(), operation: "read".to_string() };
        return Err(Error::new(ErrorKind::Invalid, message).about(subject));
    }
    Ok(bytes)
}

/// Reads a source file or built program: [`read_input`] of a file.
pub fn read_input_file(path: &Path) -> Result<Vec<u8>> {
    let file = File::open(path).map_err(|e| Error::of_io("read", path, &e))?;
    read_input(file, &path.display().to_string())
}

/// Creates a directory and its parents.
pub fn create_dir(path: &Path) -> Result<()> {
    std::fs::create_dir_all(path).map_err(|e| Error::of_io("create directory", path, &e))
}

/// Writes a file atomically (see the module's documentation). Under a
/// directory this process has locked ([`DirLock`]), the lock must still be
/// there: a lock file removed or replaced by hand may have let another run
/// in, and this one stops rather than mix its files with that run's.
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<()> {
    check_locks(path)?;
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let fail = |e: std::io::Error| Error::of_io("write", path, &e);
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // Unique per process and write; create-new refuses anything already
    // there (a file, a link), so try the next name rather than follow it.
    let (tmp, mut file) = loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => break (tmp, f),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && n < u64::MAX => continue,
            Err(e) => return Err(fail(e)),
        }
    };
    let written = file.write_all(contents).and_then(|()| file.sync_all()).and_then(|()| {
        drop(file);
        std::fs::rename(&tmp, path)
    });
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(fail(e));
    }
    // The rename itself is durable once the directory is synced (where a
    // directory can be opened; elsewhere the rename is atomic anyway).
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// The lock of a directory written by one run or experiment at a time.
/// Dropping it (or the process ending in any way) releases it.
#[derive(Debug)]
pub struct DirLock {
    _file: File,
    path: PathBuf,
}

/// A lock this process holds: its directory, its file and the file's
/// identity when it was taken.
struct Held {
    dir: PathBuf,
    lock: PathBuf,
    id: Option<(u64, u64)>,
}

/// The locks this process holds, for [`check_locks`].
static HELD: Mutex<Vec<Held>> = Mutex::new(Vec::new());

/// The device and inode of a file (`None` where there are none).
fn file_id(meta: &std::fs::Metadata) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt as _;
        Some((meta.dev(), meta.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        None
    }
}

/// Refuses a write to `path` under a directory this process locked whose
/// lock file is no longer the one it locked (removed, or replaced by
/// another run's).
fn check_locks(path: &Path) -> Result<()> {
    let held = HELD.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    for h in held.iter().filter(|h| h.id.is_some() && path.starts_with(&h.dir)) {
        let now = std::fs::symlink_metadata(&h.lock).ok().and_then(|m| file_id(&m));
        if now != h.id {
            let what = if now.is_none() { "was removed" } else { "was replaced" };
            let subject = Subject::Lock { dir: h.dir.clone(), holder: String::new() };
            return Err(Error::new(
                ErrorKind::Locked,
                format!(
                    "error: the lock `{}` {what} while this process held it, so another run may be writing into `{}`; \
                     stopped before writing `{}` (what was written before is saved): make sure no other run uses \
                     the directory, then run the same command again",
                    h.lock.display(),
                    h.dir.display(),
                    path.display()
                ),
            )
            .about(subject));
        }
    }
    Ok(())
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let mut held = HELD.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let id = self._file.metadata().ok().and_then(|m| file_id(&m));
        if let Some(at) = held.iter().position(|h| h.lock == self.path && h.id == id) {
            held.remove(at);
        }
    }
}

impl DirLock {
    /// The name of the lock file in a locked directory.
    pub const FILE: &'static str = ".lock";

    /// Locks `dir` (created if missing) for this process, or refuses at once
    /// if another process (or another lock of this one) holds it.
    pub fn acquire(dir: &Path) -> Result<DirLock> {
        create_dir(dir)?;
        let path = dir.join(Self::FILE);
        // The lock file itself is opened without following a link there.
        let mut file = open_lock_file(&path).map_err(|e| Error::of_io("open the lock", &path, &e))?;
        match file.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let holder = std::fs::read_to_string(&path).unwrap_or_default();
                let holder = holder.trim();
                // `NAME, process PID`: a holder of this process is another
                // thread's run (Python's threads, a library's two runs).
                let ours = holder
                    .rsplit_once("process ")
                    .is_some_and(|(_, pid)| pid.parse::<u32>().ok() == Some(std::process::id()));
                let who = match (holder.is_empty(), ours) {
                    (true, _) => "another process".to_string(),
                    (false, true) => format!("another run of this process ({holder})"),
                    (false, false) => format!("another process ({holder})"),
                };
                let message = format!(
                    "error: `{}` is in use by {who}; wait for it to finish (or stop it), or choose another `--out`",
                    dir.display()
                );
                let subject = Subject::Lock { dir: dir.to_path_buf(), holder: holder.to_string() };
                return Err(Error::new(ErrorKind::Locked, message).about(subject));
            }
            Err(std::fs::TryLockError::Error(e)) => {
                return Err(Error::of_io("lock", &path, &e));
            }
        }
        // Who holds it, for the refusal of the next one.
        let mut text = format!("process {}", std::process::id());
        if let Some(cmd) = std::env::args().next() {
            let name = Path::new(&cmd).file_name().map_or(cmd.clone(), |n| n.to_string_lossy().into_owned());
            text = format!("{name}, {text}");
        }
        let _ = file.set_len(0).and_then(|()| file.write_all(text.as_bytes())).and_then(|()| file.flush());
        let id = file.metadata().ok().and_then(|m| file_id(&m));
        HELD.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(Held {
            dir: dir.to_path_buf(),
            lock: path.clone(),
            id,
        });
        remove_stale_temporaries(dir);
        Ok(DirLock { _file: file, path })
    }

    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(unix)]
fn open_lock_file(path: &Path) -> std::io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt as _;
    // O_NOFOLLOW: a symbolic link planted at `.lock` is refused, not followed.
    const O_NOFOLLOW: i32 = if cfg!(target_os = "linux") { 0o400000 } else { 0x0100 };
    OpenOptions::new().read(true).write(true).create(true).truncate(false).custom_flags(O_NOFOLLOW).open(path)
}

#[cfg(not(unix))]
fn open_lock_file(path: &Path) -> std::io::Result<File> {
    OpenOptions::new().read(true).write(true).create(true).truncate(false).open(path)
}

/// The process that wrote temporary file `name` ([`write_atomic`]'s
/// `.NAME.PID.N.tmp`), if it is one.
fn temporary_owner(name: &str) -> Option<u32> {
    let rest = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (rest, n) = rest.rsplit_once('.')?;
    let (target, pid) = rest.rsplit_once('.')?;
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    (!target.is_empty() && digits(n) && digits(pid)).then(|| pid.parse().ok()).flatten()
}

/// Whether process `pid` may be alive: `false` only when it is known to be
/// gone (`/proc` has no entry for it); where there is no `/proc`, every
/// process may be.
fn may_be_alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    let proc = Path::new("/proc");
    !proc.join("self").exists() || proc.join(pid.to_string()).exists()
}

/// Removes the temporary files of [`write_atomic`] that processes which
/// are gone left in `dir` and the directories below it (a kill during a
/// write leaves one; a checkpoint's may be megabytes). Called under the
/// directory's lock; a live process's file and anything that is not a
/// plain file (a link) are left alone, and nothing is followed.
pub fn remove_stale_temporaries(dir: &Path) {
    // A run's stage, an experiment's point, seed and stage, and `.writing`.
    const DEPTH: usize = 5;
    let mut stack = vec![(dir.to_path_buf(), 0)];
    while let Some((d, depth)) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for entry in entries.flatten() {
            let Ok(kind) = entry.file_type() else { continue };
            if kind.is_dir() && depth < DEPTH {
                stack.push((entry.path(), depth + 1));
            } else if kind.is_file() {
                let name = entry.file_name();
                let stale = temporary_owner(&name.to_string_lossy()).is_some_and(|pid| !may_be_alive(pid));
                if stale {
                    let _ = std::fs::remove_file(entry.path());
                }
            }
        }
    }
}

/// The name of a directory's seals ([`write_sealed`]).
pub const SEALS: &str = ".seals";

/// Told of each file read without a seal ([`read_checked`]): written
/// before runs sealed their files, so damage to it cannot be detected.
pub type Unsealed<'a> = &'a dyn Fn(&Path);

/// The warning about files read without a seal.
pub fn unsealed_warning(paths: &[PathBuf]) -> Option<String> {
    let mut paths = paths.to_vec();
    paths.sort();
    paths.dedup();
    let first = paths.first()?;
    let (which, it) = match paths.len() {
        1 => (format!("`{}` has no seal", first.display()), "it"),
        n => (format!("{n} files have no seal (`{}` and {} more)", first.display(), n - 1), "them"),
    };
    Some(format!(
        "warning: {which}: written before runs sealed their files (or the seal was removed), so damage to {it} \
         cannot be detected; running the stage again (`--fresh`) seals {it}"
    ))
}

/// What `DIR/.seals` holds: each sealed file's checksums (FNV-1a, 16 hex
/// digits), the one written last first; two only while a write is under
/// way (or was killed).
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
struct Seals {
    format: u32,
    files: BTreeMap<String, Vec<String>>,
}

const SEALS_FORMAT: u32 = 1;

fn checksum_hex(bytes: &[u8]) -> String {
    format!("{:016x}", fnv1a(bytes))
}

/// The seals of `dir`: `None` where there are none; damaged ones are
/// `Corrupt`, naming them.
fn read_seals(dir: &Path) -> Result<Option<Seals>> {
    let path = dir.join(SEALS);
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(Error::of_io("read", &path, &e)),
    };
    let corrupt = |why: &str| {
        Error::damaged(
            &path,
            why,
            format!(
                "error: the seals `{}` are corrupt ({why}): the files beside them cannot be checked; delete it to \
                 read them unchecked (with a warning), or run the stage again (`--fresh`)",
                path.display()
            ),
        )
    };
    let text = std::str::from_utf8(&bytes).map_err(|_| corrupt("not UTF-8"))?;
    let body = match unseal(text) {
        Sealed::Verified(body) => body,
        Sealed::Unsealed(_) => return Err(corrupt("they have no checksum")),
        Sealed::Damaged => return Err(corrupt("their checksum does not match their contents")),
    };
    let seals: Seals = serde_json::from_str(&body).map_err(|e| corrupt(&e.to_string()))?;
    if seals.format != SEALS_FORMAT {
        return Err(corrupt(&format!("format {}, this shaping reads format {SEALS_FORMAT}", seals.format)));
    }
    Ok(Some(seals))
}

fn write_seals(dir: &Path, seals: &Seals) -> Result<()> {
    let json = serde_json::to_string_pretty(seals)
        .map_err(|e| Error::internal(format!("error: cannot serialise the seals: {e}")))?;
    write_atomic(&dir.join(SEALS), seal(&json).as_bytes())
}

/// Writes `files` (name and contents) into `dir`, each whole
/// ([`write_atomic`]), and seals them in `dir`'s [`SEALS`]: the new
/// checksums are added beside the old ones before the files are written
/// and the old ones dropped after, so that a kill at any point leaves every
/// file matching a seal. Seals that do not read are replaced (the files
/// they sealed then read as unsealed, with a warning).
pub fn write_sealed(dir: &Path, files: &[(&str, &[u8])]) -> Result<()> {
    let mut seals = read_seals(dir).ok().flatten().unwrap_or_default();
    seals.format = SEALS_FORMAT;
    let sums: Vec<String> = files.iter().map(|(_, bytes)| checksum_hex(bytes)).collect();
    let mut pending = false;
    for ((name, _), sum) in files.iter().zip(&sums) {
        let known = seals.files.entry((*name).to_string()).or_default();
        if !known.contains(sum) {
            known.insert(0, sum.clone());
            pending = true;
        }
    }
    if pending {
        write_seals(dir, &seals)?;
    }
    for (name, bytes) in files {
        write_atomic(&dir.join(name), bytes)?;
    }
    let mut settled = false;
    for ((name, _), sum) in files.iter().zip(&sums) {
        let known = seals.files.entry((*name).to_string()).or_default();
        if known.len() != 1 || known[0] != *sum {
            *known = vec![sum.clone()];
            settled = true;
        }
    }
    if settled {
        write_seals(dir, &seals)?;
    }
    Ok(())
}

/// Moves every file of `from` (written by [`write_sealed`]) into `to`, and
/// `from`'s seals into `to`'s as [`write_sealed`] does: the new checksums
/// beside the old first, the files, then the new ones alone. `from` is
/// removed.
pub fn move_sealed(from: &Path, to: &Path) -> Result<()> {
    let fail = |e: std::io::Error| {
        let message =
            format!("error: cannot move the files of `{}` into `{}`: {e}", from.display(), to.display());
        Error::new(ErrorKind::Io, message)
            .about(Subject::File { path: from.to_path_buf(), operation: "move".into() })
    };
    let new = read_seals(from)?.unwrap_or_default();
    let mut seals = read_seals(to).ok().flatten().unwrap_or_default();
    seals.format = SEALS_FORMAT;
    for (name, sums) in &new.files {
        let known = seals.files.entry(name.clone()).or_default();
        for sum in sums.iter().rev() {
            if !known.contains(sum) {
                known.insert(0, sum.clone());
            }
        }
    }
    if !new.files.is_empty() {
        write_seals(to, &seals)?;
    }
    for entry in std::fs::read_dir(from).map_err(fail)? {
        let entry = entry.map_err(fail)?;
        if entry.file_name() != SEALS {
            check_locks(&to.join(entry.file_name()))?;
            std::fs::rename(entry.path(), to.join(entry.file_name())).map_err(fail)?;
        }
    }
    for (name, sums) in new.files {
        seals.files.insert(name, sums);
    }
    if !seals.files.is_empty() {
        write_seals(to, &seals)?;
    }
    let _ = std::fs::remove_file(from.join(SEALS));
    std::fs::remove_dir(from).map_err(fail)
}

/// A file read by [`read_checked`].
#[derive(Debug)]
pub struct Checked {
    pub bytes: Vec<u8>,
    /// Its seal matched (`false`: it has none).
    pub sealed: bool,
}

/// Reads `path` (`None` when there is no such file) and checks it against
/// its seal in its directory's [`SEALS`]: a file whose seal does not match
/// is `Corrupt`, naming it, with `advice`; one without a seal is read, and
/// `unsealed` told.
pub fn read_checked(path: &Path, advice: &str, unsealed: Unsealed<'_>) -> Result<Option<Checked>> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(Error::of_io("read", path, &e)),
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let seals = read_seals(dir)?;
    let Some(sums) = seals.as_ref().and_then(|s| s.files.get(&name)) else {
        unsealed(path);
        return Ok(Some(Checked { bytes, sealed: false }));
    };
    if !sums.contains(&checksum_hex(&bytes)) {
        return Err(Error::damaged(
            path,
            "its checksum does not match its contents",
            format!(
                "error: `{}` is corrupt: its checksum does not match its contents (sealed in `{}`): it was changed \
                 after the run wrote it; {advice}",
                path.display(),
                dir.join(SEALS).display()
            ),
        ));
    }
    Ok(Some(Checked { bytes, sealed: true }))
}

const CHECKSUM_FIELD: &str = ",\n  \"checksum\": \"";

/// `json` (a pretty-printed JSON object) with a last field `"checksum"`:
/// the FNV-1a of `json` itself, 16 hex digits.
pub fn seal(json: &str) -> String {
    let body = json.trim_end();
    let Some(open) = body.strip_suffix("\n}") else { return json.to_string() };
    format!("{open}{CHECKSUM_FIELD}{:016x}\"\n}}", fnv1a(body.as_bytes()))
}

/// What [`unseal`] found.
#[derive(Debug, PartialEq, Eq)]
pub enum Sealed<'a> {
    /// The checksum matches: the text without it.
    Verified(String),
    /// No checksum (written before checksums existed): the text as it is.
    Unsealed(&'a str),
    /// A checksum that does not match the text.
    Damaged,
}

/// Checks the checksum [`seal`] added to `text`.
pub fn unseal(text: &str) -> Sealed<'_> {
    let body = text.trim_end();
    let Some(at) = body.rfind(CHECKSUM_FIELD) else { return Sealed::Unsealed(text) };
    let rest = &body[at + CHECKSUM_FIELD.len()..];
    let Some(hex) = rest.strip_suffix("\"\n}") else { return Sealed::Unsealed(text) };
    let Ok(sum) = u64::from_str_radix(hex, 16) else { return Sealed::Damaged };
    if hex.len() != 16 {
        return Sealed::Damaged;
    }
    let original = format!("{}\n}}", &body[..at]);
    if fnv1a(original.as_bytes()) == sum {
        Sealed::Verified(original)
    } else {
        Sealed::Damaged
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sealed_text_unseals_to_itself_and_any_changed_digit_is_damage() {
        let json = "{\n  \"a\": 1,\n  \"b\": [\n    0.5\n  ]\n}";
        let sealed = seal(json);
        assert!(sealed.contains("\"checksum\""), "{sealed}");
        assert_eq!(unseal(&sealed), Sealed::Verified(json.to_string()));
        assert_eq!(unseal(json), Sealed::Unsealed(json));
        let damaged = sealed.replace("0.5", "0.6");
        assert_eq!(unseal(&damaged), Sealed::Damaged);
        // The value still parses as JSON with the field.
        let v: serde_json::Value = serde_json::from_str(&sealed).unwrap();
        assert_eq!(v["a"], 1);
    }

    #[test]
    fn an_atomic_write_never_follows_a_link_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim");
        std::fs::write(&victim, "keep").unwrap();
        let target = dir.path().join("best.genome");
        // Links planted where the old fixed temporary name was, and at the
        // first unique names this process would try.
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&victim, dir.path().join("best.genome.tmp")).unwrap();
            for n in 0..100 {
                let name = format!(".best.genome.{}.{n}.tmp", std::process::id());
                std::os::unix::fs::symlink(&victim, dir.path().join(name)).unwrap();
            }
        }
        write_atomic(&target, b"0101\n").unwrap();
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "0101\n");
        assert!(!std::fs::symlink_metadata(&target).unwrap().file_type().is_symlink());
        let left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect();
        // Only the planted links are left.
        assert_eq!(left.len(), if cfg!(unix) { 101 } else { 0 }, "{left:?}");
    }

    #[test]
    fn an_endless_input_is_refused_at_the_limit() {
        let err = read_input(std::io::repeat(0), "/dev/zero").unwrap_err();
        assert_eq!(err.kind(), ErrorKind::Invalid);
        assert!(err.message().contains("larger than 64 MiB"), "{err}");
        assert_eq!(read_input(&b"stage"[..], "f").unwrap(), b"stage");
    }

    #[test]
    fn a_second_lock_of_a_directory_is_refused_naming_the_holder_and_released_on_drop() {
        let dir = tempfile::tempdir().unwrap();
        let first = DirLock::acquire(dir.path()).unwrap();
        let err = DirLock::acquire(dir.path()).unwrap_err();
        assert_eq!(err.kind(), ErrorKind::Locked);
        assert!(err.message().contains(&format!("process {}", std::process::id())), "{err}");
        assert!(err.message().contains("in use by another run of this process"), "{err}");
        drop(first);
        DirLock::acquire(dir.path()).unwrap();
    }
}
