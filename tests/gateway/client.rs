//! A small CiA 309-3 client: writes request lines, reads answer lines (`[seq] ...`), keeps
//! the notification lines in between.

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::Duration;

/// The longest wait for one answer (a bound for a hung gateway, not a pace).
pub const WAIT: Duration = Duration::from_secs(60);

/// A line reader on its own thread.
pub fn lines_of(r: impl std::io::Read + Send + 'static) -> Receiver<String> {
    let (tx, rx) = channel();
    std::thread::spawn(move || {
        let mut r = BufReader::new(r);
        loop {
            let mut line = String::new();
            match r.read_line(&mut line) {
                Ok(0) | Err(_) => break,
                Ok(_) => {
                    if tx.send(line).is_err() {
                        break;
                    }
                }
            }
        }
    });
    rx
}

/// One connection: where requests go, where answers come from.
pub struct Client<W: Write> {
    /// Where requests go.
    pub to: W,
    from: Receiver<String>,
    /// The notification lines read so far.
    pub notices: Vec<String>,
}

impl<W: Write> Client<W> {
    pub fn new(to: W, from: Receiver<String>) -> Client<W> {
        Client {
            to,
            from,
            notices: Vec::new(),
        }
    }

    /// Sends raw bytes (a line end included when wanted).
    pub fn send(&mut self, bytes: &[u8]) {
        self.to.write_all(bytes).unwrap();
        self.to.flush().unwrap();
    }

    /// The next answer line that starts with `[seq]` (without its CR LF).
    pub fn answer_of(&mut self, seq: u32) -> String {
        let want = format!("[{seq}]");
        loop {
            let line = self.next_line();
            if line.starts_with(&want) {
                return line;
            }
            self.notices.push(line);
        }
    }

    /// Sends `line` and gives the answer to its sequence number (the line's first word).
    pub fn ask(&mut self, line: &str) -> String {
        self.send(format!("{line}\r\n").as_bytes());
        let seq: u32 = line.trim_start_matches('[').split(']').next().unwrap().parse().unwrap();
        self.answer_of(seq)
    }

    /// Waits until a notification line contains `text`; gives it.
    pub fn notice(&mut self, text: &str) -> String {
        if let Some(n) = self.notices.iter().find(|n| n.contains(text)) {
            return n.clone();
        }
        loop {
            let line = self.next_line();
            self.notices.push(line.clone());
            if line.contains(text) {
                return line;
            }
        }
    }

    /// The next line, its CR LF cut.
    pub fn next_line(&mut self) -> String {
        self.next_raw().trim_end_matches(['\r', '\n']).to_string()
    }

    /// The next line with its end (CR LF closes an answer; LF alone separates the lines of a text).
    pub fn next_raw(&mut self) -> String {
        self.from.recv_timeout(WAIT).unwrap_or_else(|_| {
            panic!(
                "no line from the gateway in {WAIT:?}; notices so far: {:?}",
                self.notices
            )
        })
    }

    /// The lines of a multi-line answer (`help`, `log`): up to the one closed by CR LF.
    pub fn text(&mut self) -> Vec<String> {
        let mut lines = Vec::new();
        loop {
            let raw = self.next_raw();
            lines.push(raw.trim_end_matches(['\r', '\n']).to_string());
            if raw.ends_with("\r\n") {
                return lines;
            }
        }
    }
}

/// `cotui gateway demo --stdio ARGS...` and its client.
pub struct Gateway {
    pub child: Child,
    pub client: Client<ChildStdin>,
}

impl Gateway {
    pub fn start(args: &[&str]) -> Gateway {
        let mut child = Command::new(env!("CARGO_BIN_EXE_cotui"))
            .args(["gateway", "demo", "--stdio"])
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        let to = child.stdin.take().unwrap();
        let from = lines_of(child.stdout.take().unwrap());
        Gateway {
            child,
            client: Client::new(to, from),
        }
    }
}

impl Drop for Gateway {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
