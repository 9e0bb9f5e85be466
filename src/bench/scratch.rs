//! The bench's temporary folder for its generated logs: refused up front when the logs
//! would not fit in the free space, and removed at the end, on an error, and on SIGINT,
//! SIGTERM or SIGHUP (a thread waits for those signals, stops the child being measured,
//! removes the folder and exits 128 + the signal's number).

use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicI32, Ordering};

/// The child being measured (0: none), stopped when a signal ends the bench.
static CHILD: AtomicI32 = AtomicI32::new(0);

/// Notes the child being measured (0 when it ended).
pub fn set_child(pid: i32) {
    CHILD.store(pid, Ordering::SeqCst);
}

/// A temporary folder, removed when dropped.
pub struct Scratch {
    dir: PathBuf,
}

impl Scratch {
    /// Creates `dir` for logs of `need` bytes in all, refused (saying how much is needed and
    /// free) when they would not fit; from now on a signal removes it. Call before any
    /// other thread starts: the signals are blocked here and the threads started later
    /// inherit that.
    pub fn create(dir: PathBuf, need: u64) -> io::Result<Scratch> {
        let parent = dir.parent().unwrap_or(Path::new("/"));
        let free = free_bytes(parent)?;
        if need > free {
            return Err(io::Error::new(
                io::ErrorKind::StorageFull,
                format!(
                    "the generated logs need about {} and {} has {} free: give fewer --frames (or TMPDIR=a folder with more space)",
                    size(need),
                    parent.display(),
                    size(free)
                ),
            ));
        }
        std::fs::create_dir_all(&dir)?;
        remove_on_signal(dir.clone())?;
        Ok(Scratch { dir })
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.dir
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// `1.5 GB`, `320 MB`, `12 kB`.
fn size(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.0} MB", b / 1e6)
    } else {
        format!("{:.0} kB", (b / 1e3).ceil())
    }
}

/// Bytes free for an unprivileged user in the file system of `dir`.
fn free_bytes(dir: &Path) -> io::Result<u64> {
    use std::os::unix::ffi::OsStrExt;
    let path = std::ffi::CString::new(dir.as_os_str().as_bytes()).map_err(io::Error::other)?;
    // SAFETY: statvfs is plain data, filled by the call.
    let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
    // SAFETY: `path` is a NUL-terminated string and `st` valid memory for the call.
    if unsafe { libc::statvfs(path.as_ptr(), &mut st) } != 0 {
        return Err(io::Error::last_os_error());
    }
    Ok((st.f_bavail as u64).saturating_mul(st.f_frsize as u64))
}

/// Blocks SIGINT, SIGTERM and SIGHUP in this thread (and so in those it starts later) and
/// starts a thread that waits for them, then stops the child, removes `dir` and exits.
fn remove_on_signal(dir: PathBuf) -> io::Result<()> {
    // SAFETY: sigset_t is plain data, set up by sigemptyset/sigaddset before any use.
    let mut set: libc::sigset_t = unsafe { std::mem::zeroed() };
    // SAFETY: `set` is valid memory; the signal numbers are valid.
    let blocked = unsafe {
        libc::sigemptyset(&mut set);
        for sig in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            libc::sigaddset(&mut set, sig);
        }
        libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut())
    };
    if blocked != 0 {
        return Err(io::Error::from_raw_os_error(blocked));
    }
    std::thread::spawn(move || {
        let mut sig = 0;
        // SAFETY: `set` and `sig` are valid for the call; the signals are blocked.
        if unsafe { libc::sigwait(&set, &mut sig) } != 0 {
            return;
        }
        let child = CHILD.load(Ordering::SeqCst);
        if child > 0 {
            // SAFETY: kill has no memory effects; the pid is our child's.
            unsafe { libc::kill(child, libc::SIGKILL) };
        }
        let _ = std::fs::remove_dir_all(&dir);
        eprintln!("cotui bench: stopped; {} removed", dir.display());
        std::process::exit(128 + sig);
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::size;

    #[test]
    fn sizes_read_in_kilo_mega_and_gigabytes() {
        assert_eq!(size(1_500_000_000), "1.5 GB");
        assert_eq!(size(320_000_000), "320 MB");
        assert_eq!(size(1), "1 kB");
    }
}
