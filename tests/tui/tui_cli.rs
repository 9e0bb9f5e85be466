//! The interactive commands' checks that run before the terminal is taken: keymap
//! validation with located errors, user keymap overrides, missing files, no terminal.

use std::process::{Command, Output};

fn cotui(args: &[&str], config_home: &std::path::Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cotui"))
        .args(args)
        .env("XDG_CONFIG_HOME", config_home)
        .stdin(std::process::Stdio::null())
        .output()
        .unwrap()
}

fn tempdir(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("cotui-cli-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(d.join("cotui")).unwrap();
    d
}

#[test]
fn a_bad_keymap_file_is_refused_with_its_location() {
    let dir = tempdir("bad");
    let km = dir.join("k.json");
    std::fs::write(&km, "{\n  \"q\": \"quit\",\n  \"j\": \"jump_around\"\n}\n").unwrap();
    let log = dir.join("x.log");
    std::fs::write(&log, "(1.000000) can0 701#05\n").unwrap();
    let out = cotui(&["open", log.to_str().unwrap(), "--keymap", km.to_str().unwrap()], &dir);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        err.trim(),
        format!("cotui: keymap: {}:3:3: unknown action \"jump_around\"", km.display())
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_user_keymap_is_checked_against_the_base_map() {
    let dir = tempdir("user");
    let user = dir.join("cotui").join("keymap.json");
    std::fs::write(&user, "{\"g\": \"top\"}").unwrap();
    let log = dir.join("x.log");
    std::fs::write(&log, "(1.000000) can0 701#05\n").unwrap();
    let out = cotui(&["open", log.to_str().unwrap(), "--keymap", "vim"], &dir);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!("{}:1:2: key \"g\" is a prefix of \"g g\"", user.display())),
        "{err}"
    );
    // With the default map the same override is fine; without a terminal cotui says so.
    let out = cotui(&["open", log.to_str().unwrap()], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("needs a terminal"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_missing_log_is_reported_before_the_screen_changes() {
    let dir = tempdir("missing");
    let out = cotui(&["replay", "/nonexistent/cotui.log", "--speed", "2"], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).starts_with("cotui: /nonexistent/cotui.log: "));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_replay_speed_out_of_range_is_a_usage_error() {
    let dir = tempdir("speed");
    let log = dir.join("x.log");
    std::fs::write(&log, "(1.000000) can0 701#05\n").unwrap();
    for (bad, shown) in [
        ("1e-300", "1e-300"),
        ("1e300", "1e300"),
        ("-1", "-1"),
        ("inf", "inf"),
        ("NaN", "NaN"),
        ("5000", "5000"),
        ("0.000123456789", "1.23456789e-4"),
    ] {
        let out = cotui(&["replay", log.to_str().unwrap(), &format!("--speed={bad}")], &dir);
        assert_eq!(out.status.code(), Some(1), "{bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            err.trim(),
            format!("cotui replay: --speed {shown} is out of range: 0 (as fast as possible) or 0.01 to 1000"),
            "{bad}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_keymap_that_cannot_quit_or_cannot_be_read_is_refused_and_located() {
    let dir = tempdir("noquit");
    let log = dir.join("x.log");
    std::fs::write(&log, "(1.000000) can0 701#05\n").unwrap();
    let open = |keymap: Option<&std::path::Path>| {
        let mut args = vec!["open", log.to_str().unwrap()];
        if let Some(k) = keymap {
            args.extend(["--keymap", k.to_str().unwrap()]);
        }
        let out = cotui(&args, &dir);
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).trim().to_string(),
        )
    };
    let empty = dir.join("empty.json");
    std::fs::write(&empty, "{}").unwrap();
    assert_eq!(
        open(Some(&empty)),
        (
            Some(1),
            format!(
                "cotui: keymap: {}:1:1: no key quits: bind one to \"quit\" (e.g. \"q\": \"quit\")",
                empty.display()
            )
        )
    );
    let latin1 = dir.join("latin1.json");
    std::fs::write(&latin1, b"{\"q\": \"quit\",\n \"\xE9\": \"help\"}").unwrap();
    assert_eq!(
        open(Some(&latin1)),
        (
            Some(1),
            format!("cotui: keymap: {}:2:3: not UTF-8 (byte 0xE9)", latin1.display())
        )
    );
    // The user's keymap.json is never ignored silently: a directory, bad bytes.
    let user = dir.join("cotui").join("keymap.json");
    std::fs::create_dir_all(&user).unwrap();
    assert_eq!(
        open(None),
        (
            Some(1),
            format!("cotui: keymap: {}: is a directory, not a keymap file", user.display())
        )
    );
    std::fs::remove_dir(&user).unwrap();
    std::fs::write(&user, b"{\"\\u0071\": \"none\",\n \"ctrl-c\": \"none\"}").unwrap();
    assert_eq!(
        open(None),
        (
            Some(1),
            format!(
                "cotui: keymap: {}:2:2: no key quits: bind one to \"quit\" (e.g. \"q\": \"quit\")",
                user.display()
            )
        )
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn hosted_servers_are_checked_before_the_terminal_is_taken() {
    let dir = tempdir("host");
    let out = cotui(&["demo", "--gateway", "127.0.0.1:5555"], &dir);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr).trim(),
        "cotui demo: --gateway 127.0.0.1:5555: give tcp:ADDR:PORT (e.g. tcp:127.0.0.1:5555) or unix:PATH"
    );
    let out = cotui(
        &[
            "demo",
            "--listen-only",
            "--gateway",
            "tcp:127.0.0.1:0",
            "--allow-writes",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--allow-writes and --listen-only contradict each other"),
        "{out:?}"
    );
    // A taken port is said at once, naming it.
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = taken.local_addr().unwrap().port().to_string();
    let out = cotui(&["live", "vcan0", "--socketcand", &port], &dir);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).starts_with(&format!(
            "cotui live: --socketcand {port}: cannot listen on 127.0.0.1:{port}: "
        )),
        "{out:?}"
    );
    // --allow-send means nothing without --socketcand.
    let out = cotui(&["demo", "--allow-send"], &dir);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("required arguments were not provided:\n  --socketcand"),
        "{out:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
