//! `--bitrate` of every command that takes it: 0, negative and absurd rates are usage errors.

use std::process::Command;

#[test]
fn bitrate_zero_or_absurd_is_a_usage_error_in_every_command() {
    let commands: [&[&str]; 4] = [&["open", "x.log"], &["replay", "x.log"], &["live", "vcan0"], &["demo"]];
    for cmd in commands {
        for rate in ["0", "-1", "5M", "abc"] {
            let out = Command::new(env!("CARGO_BIN_EXE_cotui"))
                .args(cmd)
                .arg(format!("--bitrate={rate}"))
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{cmd:?} --bitrate {rate}: {err}");
            assert!(err.contains("is not a CAN bit rate"), "{cmd:?} --bitrate {rate}: {err}");
        }
    }
}
