//! Where a server's audit lines go: stderr when it runs as its own command (`cotui serve`,
//! `cotui gateway`), the TUI's message log when the TUI hosts it (`cotui live --gateway`,
//! `--socketcand`).

use std::sync::Arc;

/// A cloneable sink of audit lines, each prefixed with the server that wrote it.
#[derive(Clone)]
pub struct Audit {
    prefix: &'static str,
    to: Arc<dyn Fn(String) + Send + Sync>,
    requests: bool,
}

impl Audit {
    /// Lines on stderr as `cotui PREFIX: line`; requests are not logged one by one.
    pub fn stderr(prefix: &'static str) -> Audit {
        Audit {
            prefix,
            to: Arc::new(|line| eprintln!("cotui {line}")),
            requests: false,
        }
    }

    /// Lines as `PREFIX: line` to `to`; with `requests`, every request and its answer too.
    pub fn to(prefix: &'static str, requests: bool, to: impl Fn(String) + Send + Sync + 'static) -> Audit {
        Audit {
            prefix,
            to: Arc::new(to),
            requests,
        }
    }

    /// Writes one line.
    pub fn say(&self, line: &str) {
        (self.to)(format!("{}: {line}", self.prefix));
    }

    /// True when each request and its answer is written too (the TUI's message log).
    pub fn logs_requests(&self) -> bool {
        self.requests
    }
}
