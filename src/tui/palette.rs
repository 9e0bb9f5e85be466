//! What a commander line in the palette will do before it is sent: the exact frames, as
//! the protocol layer builds them (the SDO client's first frame, the NMT frame, the CiA 402
//! controlwords, the LSS requests), and whether it needs confirming (broadcast NMT, resets,
//! node 0, LSS services that change state).

use crate::analysis::producers;
use crate::analysis::trace::Trace;
use crate::command::spec::{Known, Preview, Spec};
use crate::command::{Command, CommandError, parse_command};
use crate::decode::cia402::DriveState;
use crate::od::bind::Bindings;

/// The first words of commander lines, from the command declaration.
pub fn commander_words() -> &'static [&'static str] {
    static WORDS: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
    WORDS.get_or_init(crate::command::syntax::commander_words)
}

/// A parsed commander line with its preview.
#[derive(Clone, Debug, PartialEq)]
pub struct Planned {
    /// The line as typed.
    pub line: String,
    /// The command.
    pub command: Command,
    /// The frames it sends, candump style, or a description when they depend on answers.
    pub preview: String,
    /// Why it must be confirmed, if it must.
    pub confirm: Option<String>,
}

/// Plans a commander line; `bindings` give object names and types, `state` a node's known
/// CiA 402 state for drive previews.
pub fn plan(
    line: &str,
    bindings: &Bindings,
    state: impl Fn(u8) -> Option<DriveState>,
) -> Result<Planned, CommandError> {
    let command = parse_command(line)?;
    if let Some(refused) = command.palette_refusal() {
        return Err(refused);
    }
    let known = Known {
        bindings,
        drive_state: &state,
    };
    let Preview { frames, confirm } = command.preview(&known)?;
    Ok(Planned {
        line: line.trim().to_string(),
        command,
        preview: frames,
        confirm,
    })
}

/// Before `sync` (a second SYNC producer) or `nmt` (a second NMT master): when another
/// producer of that COB-ID was heard in the last 2 s (not cotui's own frames), the preview
/// says so and the line must be confirmed. `t0_ns` is the trace's start (times are shown
/// from it, as the trace's). This check replaces the command line's listening before
/// sending (the trace already holds the bus's last seconds), which the command then skips.
pub fn warn_second_producer(p: &mut Planned, trace: &Trace, t0_ns: u64) {
    let (cob_id, who) = match &mut p.command {
        Command::Sync(s) => {
            s.listen.ms = 0;
            (s.cob_id, "SYNC producer")
        }
        Command::Nmt(n) => {
            n.listen.ms = 0;
            (0x000, "NMT master")
        }
        _ => return,
    };
    let Some(h) = producers::heard(trace, cob_id) else {
        return;
    };
    let warning = format!(
        "another {who} is on the bus: 0x{cob_id:03X} seen {} time{} in the last {} s, last at {:.3} s",
        h.count,
        if h.count == 1 { "" } else { "s" },
        producers::RECENT_NS / 1_000_000_000,
        h.last_ns.saturating_sub(t0_ns) as f64 / 1e9
    );
    p.preview = format!("{} — warning: {warning}", p.preview);
    p.confirm = Some(match p.confirm.take() {
        Some(why) => format!("{why}; {warning}"),
        None => warning,
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b() -> Bindings {
        Bindings::new()
    }

    /// A trace of `n` frames 10 ms apart: SYNCs (cotui's own when `own`) with heartbeats
    /// of node 2 between them.
    fn trace_with_syncs(n: u64, own: bool) -> Trace {
        use crate::frame::{Flags, Frame};
        let mut trace = Trace::new(crate::decode::Decoder::from_bindings(&b()), 500_000);
        trace.ifaces.intern("can0");
        for i in 0..n {
            let mut f = if i % 2 == 0 {
                Frame::classic(0x080, &[])
            } else {
                Frame::classic(0x702, &[5])
            };
            f.ts_ns = 1_000_000_000 + i * 10_000_000;
            f.flags.set(Flags::TX, own && f.id == 0x080);
            trace.push(&f);
        }
        trace
    }

    #[test]
    fn sync_and_nmt_previews_warn_of_another_producer_heard() {
        let planned = |line: &str, trace: &Trace| {
            let mut p = plan(line, &b(), |_| None).unwrap();
            warn_second_producer(&mut p, trace, 1_000_000_000);
            p
        };
        // 400 frames over 4 s: the last 2 s hold 100 SYNCs of another producer.
        let other = trace_with_syncs(400, false);
        let p = planned("sync --period 10", &other);
        let warning = "another SYNC producer is on the bus: 0x080 seen 100 times in the last 2 s, last at 3.980 s";
        assert!(p.preview.starts_with("080# every 10 ms"), "{}", p.preview);
        assert!(p.preview.ends_with(&format!(" — warning: {warning}")), "{}", p.preview);
        assert_eq!(p.confirm.as_deref(), Some(warning));
        // cotui's own SYNCs (TX) are no other producer; nor is an empty bus.
        for trace in [trace_with_syncs(400, true), trace_with_syncs(0, false)] {
            let p = planned("sync --period 10", &trace);
            assert!(!p.preview.contains("warning"), "{}", p.preview);
            assert_eq!(p.confirm, None);
        }
        // A SYNC on another COB-ID is not the one heard.
        assert_eq!(planned("sync --period 10 --cob-id 0x081 --force", &other).confirm, None);
        // NMT: the heartbeats are no NMT frames; another master's "start all" is.
        assert_eq!(planned("nmt start 2", &other).confirm, None);
        let mut other = other;
        let mut f = crate::frame::Frame::classic(0x000, &[0x01, 0x00]);
        f.ts_ns = 5_000_000_000;
        other.push(&f);
        let p = planned("nmt start 2", &other);
        let warning = "another NMT master is on the bus: 0x000 seen 1 time in the last 2 s, last at 4.000 s";
        assert_eq!(p.confirm.as_deref(), Some(warning));
        // The trace was the check: the commands do not listen again before sending.
        assert!(matches!(&p.command, Command::Nmt(n) if n.listen.ms == 0));
        let p = planned("sync --period 10 --listen 1s", &other);
        assert!(matches!(&p.command, Command::Sync(s) if s.listen.ms == 0));
    }

    #[test]
    fn pdo_previews_show_the_remapping_frames() {
        let p = plan("pdo 5 map tpdo1 0x6041 --type sync:4", &b(), |_| None).unwrap();
        assert_eq!(
            p.preview,
            "605#4000180100000000 (COB-ID), 605#2300180185010080, 605#2F00180204000000, 605#2F001A0000000000, \
             605#23001A0110004160, 605#2F001A0001000000, 605#2300180185010000 then reads back"
        );
        let dry = plan("pdo 5 map tpdo1 0x6041 --dry-run", &b(), |_| None).unwrap();
        assert!(
            dry.preview.starts_with("nothing (dry run of 605#4000180100000000, "),
            "{}",
            dry.preview
        );
        let read = plan("pdo 5", &b(), |_| None).unwrap();
        assert!(
            read.preview.starts_with("605#4000140000000000 then"),
            "{}",
            read.preview
        );
        let err = plan("pdo 5 map tpdo1 0x6064 0x606C 0x6041", &b(), |_| None).unwrap_err();
        assert!(err.to_string().contains("more than the 64 bits"), "{err}");
    }

    #[test]
    fn previews_show_exact_frames() {
        let p = plan("nmt start 3", &b(), |_| None).unwrap();
        assert_eq!((p.preview.as_str(), p.confirm), ("000#0103", None));
        assert_eq!(
            plan("sdo read 2 0x6041", &b(), |_| None).unwrap().preview,
            "602#4041600000000000"
        );
        assert_eq!(
            plan("sdo write 2 0x6060 3 --type i8", &b(), |_| None).unwrap().preview,
            "602#2F60600003000000"
        );
        let d = plan("drive 2 enable", &b(), |_| Some(DriveState::SwitchOnDisabled)).unwrap();
        assert_eq!(
            d.preview,
            "602#2B40600006000000, 602#2B40600007000000, 602#2B4060000F000000 (from Switch on disabled)"
        );
    }

    #[test]
    fn dcf_load_asks_first_unless_dry_run() {
        let load = plan("dcf load 5 node5.dcf --store", &b(), |_| None).unwrap();
        assert!(load.preview.contains("stores (0x1010:01)"), "{}", load.preview);
        assert_eq!(
            load.confirm.as_deref(),
            Some("dcf load writes node 5's configuration from node5.dcf")
        );
        assert_eq!(
            plan("dcf load 5 node5.dcf --dry-run", &b(), |_| None).unwrap().confirm,
            None
        );
        assert_eq!(plan("dcf diff 5 node5.dcf", &b(), |_| None).unwrap().confirm, None);
        assert!(
            plan("dcf save 5 -o n.dcf", &b(), |_| None)
                .unwrap()
                .preview
                .contains("writes n.dcf")
        );
    }

    #[test]
    fn block_and_segmented_previews_say_what_follows() {
        let preview = |line: &str| plan(line, &b(), |_| None).unwrap().preview;
        // Block download initiate (client command 6, CRC and size indicated), not the expedited write.
        assert_eq!(
            preview("sdo write 2 0x6060 3 --type i8 --block"),
            "602#C660600001000000 then 1 block segments (1 bytes) and the block end"
        );
        assert_eq!(
            preview("sdo write 2 0x1008 \"drive one\" --type string"),
            "602#2108100009000000 then 2 segments"
        );
        assert_eq!(
            preview("sdo read 2 0x1008 --block"),
            "602#A40810007F000000 then the server's block segments"
        );
        assert_eq!(
            preview("stop 2 3"),
            "cancels running commands, then 602#2B40600002000000, 602#2B40600000000000, 603#2B40600002000000, \
             603#2B40600000000000 (quick stop, then disable voltage, per node), also to every drive cotui \
             commanded or sees powered"
        );
    }

    #[test]
    fn run_previews_every_step_frame() {
        let read = |p: &std::path::Path| std::fs::read(p);
        let b = Bindings::from_args(&["2=syntron-ds".to_string()], &[], &read).unwrap();
        let p = plan("run 2 pv speed=20", &b, |_| None).unwrap();
        assert_eq!(
            p.preview,
            "602#2B02210014000000, 000#0102, 602#2F60600003000000, 602#23836000E8030000, \
             602#23846000E8030000, 602#23FF6000C8000000, 602#2B40600006000000, 602#2B40600007000000, 602#2B4060000F000000"
        );
        assert!(
            plan("run 2 pv --dry-run", &b, |_| None)
                .unwrap()
                .preview
                .starts_with("nothing (dry run of 602#2B02210014000000, 000#0102")
        );
        assert!(
            plan("run 2 pv rpm=3", &b, |_| None)
                .unwrap_err()
                .to_string()
                .contains("no parameter `rpm`")
        );
        assert!(
            plan("run 2 fly", &b, |_| None)
                .unwrap_err()
                .to_string()
                .contains("its procedures: ")
        );
    }

    #[test]
    fn cyclic_previews() {
        let preview = |line: &str| plan(line, &b(), |_| None).unwrap().preview;
        assert_eq!(preview("send 601#4041600000000000"), "601#4041600000000000 once");
        assert_eq!(
            preview("sync --period 10 --counter 4"),
            "080#01 every 10 ms until stopped, counter 1..4 (a job: `jobs` lists, `jobs stop ID` or stop-all stops)"
        );
        assert_eq!(preview("send 12345678#R --count 3"), "12345678#R 3 times back to back");
    }

    #[test]
    fn broadcasts_and_resets_need_confirming() {
        assert_eq!(
            plan("nmt start 0", &b(), |_| None).unwrap().confirm.as_deref(),
            Some("broadcast NMT start to every node")
        );
        assert!(plan("nmt reset-node 4", &b(), |_| None).unwrap().confirm.is_some());
        let p = plan("lss set-node 10", &b(), |_| None).unwrap();
        assert_eq!(p.preview, "7E5#110A000000000000");
        assert!(p.confirm.unwrap().contains("every LSS slave"));
        let p = plan("lss inquire serial", &b(), |_| None).unwrap();
        assert_eq!((p.preview.as_str(), p.confirm), ("7E5#5D00000000000000", None));
        assert!(plan("sdo read 2 nonsense_object", &b(), |_| None).is_err());
    }
}
