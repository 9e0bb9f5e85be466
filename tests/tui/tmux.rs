//! The real binary in a tmux pane: start a command, send keys, read the screen, wait for
//! it to show something, and kill the session when the test ends (also when it fails).
//! Needs tmux (scripts/install-test-deps.sh installs it).

use std::process::{Command, Stdio};
use std::thread::sleep;
use std::time::{Duration, Instant};

/// How long [`Session::wait_for`] waits at most: generous, the machine may be busy and the
/// binary a debug build. The wait ends as soon as the screen shows what is waited for.
const BOUND: Duration = Duration::from_secs(60);

/// How a session is started: terminal size, delay after each key, colours in the capture.
pub struct Options {
    width: u16,
    height: u16,
    key_delay: Duration,
    colours: bool,
}

impl Default for Options {
    /// 150x40, 80 ms after each key, plain text.
    fn default() -> Self {
        Options {
            width: 150,
            height: 40,
            key_delay: Duration::from_millis(80),
            colours: false,
        }
    }
}

impl Options {
    /// The terminal size in columns and rows.
    pub fn size(mut self, width: u16, height: u16) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    /// The pause after each key sent (zero: keys go out back to back).
    pub fn key_delay(mut self, delay: Duration) -> Self {
        self.key_delay = delay;
        self
    }

    /// The screen is captured with its colours as escape sequences (`capture-pane -e`).
    pub fn colours(mut self) -> Self {
        self.colours = true;
        self
    }

    /// Starts `cmd` in a new detached session `name` (an old one of that name is killed).
    pub fn start(self, name: &str, cmd: &str) -> Session {
        kill(name);
        let (w, h) = (self.width.to_string(), self.height.to_string());
        let ok = Command::new("tmux")
            .args(["new-session", "-d", "-s", name, "-x", &w, "-y", &h, cmd])
            .status()
            .expect("tmux is installed (scripts/install-test-deps.sh)");
        assert!(ok.success(), "tmux new-session {name} failed");
        Session {
            name: name.to_string(),
            options: self,
        }
    }
}

/// A running tmux session; killed when dropped.
pub struct Session {
    name: String,
    options: Options,
}

impl Session {
    /// Starts `cmd` with the default [`Options`].
    pub fn start(name: &str, cmd: &str) -> Session {
        Options::default().start(name, cmd)
    }

    /// Sends tmux key names (`Enter`, `BSpace`, `C-f`, `q`), one after the other.
    pub fn keys(&self, keys: &[&str]) {
        for k in keys {
            self.send(&[k]);
        }
    }

    /// Sends `keys` in one `send-keys`, so they reach the program in one read (as a fast
    /// typist's keys do): what it does with the first cannot delay the second.
    pub fn keys_together(&self, keys: &[&str]) {
        self.send(keys);
    }

    /// Sends `text` as typed, key names not interpreted (`send-keys -l`).
    pub fn type_text(&self, text: &str) {
        self.send(&["-l", text]);
    }

    fn send(&self, args: &[&str]) {
        let ok = Command::new("tmux")
            .args(["send-keys", "-t", &self.name])
            .args(args)
            .status()
            .unwrap();
        assert!(ok.success(), "tmux send-keys {args:?} failed");
        if !self.options.key_delay.is_zero() {
            sleep(self.options.key_delay);
        }
    }

    /// The screen as it is now (with escape sequences if started with `colours`).
    pub fn screen(&self) -> String {
        let mut args = vec!["capture-pane", "-p"];
        if self.options.colours {
            args.push("-e");
        }
        args.extend(["-t", &self.name]);
        let out = Command::new("tmux").args(&args).output().unwrap();
        String::from_utf8_lossy(&out.stdout).into_owned()
    }

    /// A tmux format of the pane, e.g. `#{alternate_on}` (1 while the alternate screen is
    /// on) or `#{mouse_any_flag}` (1 while the program asked for mouse events).
    pub fn format(&self, format: &str) -> String {
        let out = Command::new("tmux")
            .args(["display-message", "-p", "-t", &self.name, format])
            .output()
            .unwrap();
        String::from_utf8_lossy(&out.stdout).trim().to_string()
    }

    /// Waits until the screen satisfies `f` (60 s at most); returns the screen. Fails the
    /// test with the last screen on timeout.
    pub fn wait_for(&self, what: &str, f: impl Fn(&str) -> bool) -> String {
        self.wait_within(what, BOUND, f)
    }

    /// [`Session::wait_for`] with its own bound, for steps known to take long (loading a
    /// million-frame log).
    pub fn wait_within(&self, what: &str, bound: Duration, f: impl Fn(&str) -> bool) -> String {
        let start = Instant::now();
        loop {
            let s = self.screen();
            if f(&s) {
                return s;
            }
            assert!(
                start.elapsed() < bound,
                "timed out after {bound:?} waiting for {what}:\n{s}"
            );
            sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        kill(&self.name);
    }
}

/// Kills session `name` if there is one (quietly: there often is none).
fn kill(name: &str) {
    let _ = Command::new("tmux")
        .args(["kill-session", "-t", name])
        .stderr(Stdio::null())
        .status();
}
