//! Runs the real `cotui` binary, as the decode tests of this binary do.

use std::io::Write;
use std::process::{Command, Output, Stdio};

/// Runs `cotui ARGS` in the checkout (fixture paths are relative to it), with `stdin` fed
/// to it when given; its status and output.
pub fn cotui(args: &[&str], stdin: Option<&str>) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_cotui"));
    cmd.args(args).current_dir(env!("CARGO_MANIFEST_DIR"));
    let Some(text) = stdin else {
        return cmd.output().expect("run cotui");
    };
    let mut child = cmd
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn cotui");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(text.as_bytes())
        .expect("log written");
    child.wait_with_output().expect("wait cotui")
}
