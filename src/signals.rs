//! The signals that would end the process: one list, so that a run saves its
//! generation and a robot stops its motors and keeps its trace on every one
//! of them, not only on Ctrl-C.
//!
//! A signal is listed when its default action ends the process and a
//! handler can catch it. Left out: `SIGKILL` and `SIGSTOP` (no handler can
//! run), and the faults a process raises on itself (`SIGSEGV`, `SIGBUS`,
//! `SIGILL`, `SIGFPE`, `SIGABRT`, `SIGSYS`, `SIGTRAP`): after one of those
//! a handler that returns would run the faulting instruction again, so
//! they stay the crash they are. `SIGPIPE` is ignored by Rust programs.

use std::ffi::c_int;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

/// The signals caught (see the module's documentation), with the words a
/// message uses for each; the real-time signals follow them
/// ([`caught`]).
#[cfg(unix)]
const NAMED: &[(c_int, &str)] = {
    use signal_hook::consts::*;
    &[
        (SIGINT, "Ctrl-C"),
        (SIGTERM, "SIGTERM"),
        (SIGHUP, "SIGHUP: the terminal closed"),
        (SIGQUIT, "SIGQUIT"),
        (SIGUSR1, "SIGUSR1"),
        (SIGUSR2, "SIGUSR2"),
        (SIGALRM, "SIGALRM"),
        (SIGVTALRM, "SIGVTALRM"),
        (SIGPROF, "SIGPROF"),
        (SIGXCPU, "SIGXCPU: the CPU time limit"),
        (SIGXFSZ, "SIGXFSZ: the file size limit"),
        (SIGIO, "SIGIO"),
        #[cfg(any(target_os = "linux", target_os = "android"))]
        (libc::SIGPWR, "SIGPWR: a power failure"),
        #[cfg(any(target_os = "linux", target_os = "android"))]
        (libc::SIGSTKFLT, "SIGSTKFLT"),
    ]
};

#[cfg(not(unix))]
const NAMED: &[(c_int, &str)] =
    &[(signal_hook::consts::SIGINT, "Ctrl-C"), (signal_hook::consts::SIGTERM, "SIGTERM")];

/// Every signal caught: the named ones, then the real-time signals (whose
/// default action ends the process too).
pub fn caught() -> Vec<c_int> {
    let mut all: Vec<c_int> = NAMED.iter().map(|&(s, _)| s).collect();
    #[cfg(any(target_os = "linux", target_os = "android"))]
    all.extend(libc::SIGRTMIN()..=libc::SIGRTMAX());
    all
}

/// The words for signal `sig` in a message.
pub fn name(sig: c_int) -> String {
    if let Some(&(_, words)) = NAMED.iter().find(|&&(s, _)| s == sig) {
        return words.to_string();
    }
    #[cfg(any(target_os = "linux", target_os = "android"))]
    if (libc::SIGRTMIN()..=libc::SIGRTMAX()).contains(&sig) {
        return match sig - libc::SIGRTMIN() {
            0 => "SIGRTMIN".to_string(),
            k => format!("SIGRTMIN+{k}"),
        };
    }
    format!("signal {sig}")
}

/// The last caught signal that arrived (0: none yet).
fn last() -> &'static Arc<AtomicUsize> {
    static LAST: OnceLock<Arc<AtomicUsize>> = OnceLock::new();
    LAST.get_or_init(|| Arc::new(AtomicUsize::new(0)))
}

/// Sets `flag` on every caught signal (and remembers which came, for
/// [`last_name`]); with `exit_on_second`, a second one ends the process at
/// once. Registering twice adds handlers; each only sets its flag.
pub fn register(flag: &Arc<AtomicBool>, exit_on_second: bool) -> std::io::Result<()> {
    for sig in caught() {
        if exit_on_second {
            signal_hook::flag::register_conditional_shutdown(sig, 2, Arc::clone(flag))?;
        }
        signal_hook::flag::register(sig, Arc::clone(flag))?;
        signal_hook::flag::register_usize(sig, Arc::clone(last()), sig as usize)?;
    }
    Ok(())
}

/// The words for the last caught signal that arrived ("Ctrl-C" if none
/// did, as when the flag was set by hand).
pub fn last_name() -> String {
    match last().load(Ordering::Relaxed) {
        0 => "Ctrl-C".to_string(),
        sig => name(sig as c_int),
    }
}

#[cfg(all(test, any(target_os = "linux", target_os = "android")))]
mod tests {
    use super::*;

    /// The signals whose default action ends the process, from signal(7):
    /// every one is caught or is a fault listed as left out.
    #[test]
    fn every_signal_that_ends_the_process_is_caught_or_a_fault() {
        use libc::*;
        let stop_or_ignore = [SIGCHLD, SIGCONT, SIGSTOP, SIGTSTP, SIGTTIN, SIGTTOU, SIGURG, SIGWINCH];
        let faults = [SIGKILL, SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT, SIGSYS, SIGTRAP, SIGPIPE];
        let caught = caught();
        for sig in 1..=SIGRTMAX() {
            // The real-time signals below SIGRTMIN belong to the C library.
            if (32..SIGRTMIN()).contains(&sig) || stop_or_ignore.contains(&sig) {
                continue;
            }
            assert!(caught.contains(&sig) != faults.contains(&sig), "signal {sig} ({})", name(sig));
        }
        assert_eq!(name(SIGRTMIN() + 2), "SIGRTMIN+2");
        assert_eq!(name(SIGXCPU), "SIGXCPU: the CPU time limit");
    }
}
