//! What a commander line in the palette will do before it is sent: the exact frames, and
//! whether it needs confirming (broadcast NMT, resets, node 0).

use super::live::UNKNOWN_STATE;
use crate::command::run::Action;
use crate::command::{Command, DriveAction, NmtAction, RunSpec, parse_command};
use crate::decode::cia402::DriveState;
use crate::frame::hex;
use crate::od::alias::resolve_object;
use crate::od::bind::Bindings;

/// The first words of commander lines.
pub const COMMANDER_WORDS: &[&str] = &["nmt", "sdo", "drive", "run", "scan", "stop"];

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

fn candump(id: u32, data: &[u8]) -> String {
    format!("{id:03X}#{}", hex::upper(data))
}

fn sdo_initiate(node: u8, index: u16, sub: u8, data: &[u8]) -> String {
    let [lo, hi] = index.to_le_bytes();
    if data.len() <= 4 {
        let cmd = 0x23 | (((4 - data.len()) as u8) << 2);
        let mut b = vec![cmd, lo, hi, sub];
        b.extend_from_slice(data);
        b.resize(8, 0);
        candump(0x600 + node as u32, &b)
    } else {
        let size = (data.len() as u32).to_le_bytes();
        let b = [0x21, lo, hi, sub, size[0], size[1], size[2], size[3]];
        format!(
            "{} then {} segments",
            candump(0x600 + node as u32, &b),
            data.len().div_ceil(7)
        )
    }
}

/// Plans a commander line; `bindings` give object names and types, `state` a node's known
/// CiA 402 state for drive previews.
pub fn plan(line: &str, bindings: &Bindings, state: impl Fn(u8) -> Option<DriveState>) -> Result<Planned, String> {
    let command = parse_command(line)?;
    let (preview, confirm) = match &command {
        Command::Nmt { action, node, .. } => {
            let f = candump(0x000, &[action.cs(), *node]);
            let reset = matches!(action, NmtAction::ResetNode | NmtAction::ResetComm);
            let confirm = match (*node, reset) {
                (0, _) => Some(format!("broadcast NMT {} to every node", action.as_str())),
                (n, true) => Some(format!("NMT {} of node {n}", action.as_str())),
                _ => None,
            };
            (f, confirm)
        }
        Command::SdoRead { node, object, .. } => {
            let (i, s) = resolve_object(bindings.dictionary(*node), object)?;
            let [lo, hi] = i.to_le_bytes();
            (candump(0x600 + *node as u32, &[0x40, lo, hi, s, 0, 0, 0, 0]), None)
        }
        Command::SdoWrite {
            node,
            object,
            value,
            options,
        } => {
            let dict = bindings.dictionary(*node);
            let (i, s) = resolve_object(dict, object)?;
            let data =
                crate::command::exec::write_data(dict, i, s, value, options.data_type).map_err(|e| e.to_string())?;
            (sdo_initiate(*node, i, s, &data), None)
        }
        Command::Drive { node, action, .. } => {
            let st = state(*node);
            let steps = match action {
                DriveAction::Status => Vec::new(),
                DriveAction::Mode(_) => Vec::new(),
                a => crate::command::drive::plan(*a, st.unwrap_or(UNKNOWN_STATE)),
            };
            let frames: Vec<String> = steps
                .iter()
                .map(|s| sdo_initiate(*node, 0x6040, 0, &s.controlword.to_le_bytes()))
                .collect();
            let from = st
                .map(|s| s.text())
                .unwrap_or("state unknown, assumed Switch on disabled");
            let text = match action {
                DriveAction::Status => format!("reads 0x6041 of node {node}"),
                DriveAction::Mode(m) => {
                    format!(
                        "{} (0x6060 = {m}), then reads 0x6061",
                        sdo_initiate(*node, 0x6060, 0, &[*m as u8])
                    )
                }
                _ if frames.is_empty() => format!("nothing to send (node {node}: {from})"),
                _ => format!("{} (from {from})", frames.join(", ")),
            };
            (text, None)
        }
        Command::Scan { .. } => (
            "listens for heartbeats, then reads 0x1018 of each node found".into(),
            None,
        ),
        Command::Run(RunSpec {
            node, procedure: None, ..
        }) => (format!("nothing: lists the procedures of node {node}"), None),
        Command::Run(RunSpec {
            node,
            procedure: Some(name),
            args,
            dry_run,
            ..
        }) => {
            let p = crate::command::run::plan(bindings.dictionary(*node), *node, name, args)?;
            let steps: Vec<String> = p.steps.iter().map(|s| s.preview()).collect();
            let confirm = p.steps.iter().find_map(|s| match s.action {
                Action::Nmt { action, target }
                    if target == 0 || matches!(action, NmtAction::ResetNode | NmtAction::ResetComm) =>
                {
                    Some(format!("`{name}` sends {}", s.text))
                }
                _ => None,
            });
            if *dry_run {
                (format!("nothing (dry run of {})", steps.join(", ")), None)
            } else {
                (steps.join(", "), confirm)
            }
        }
        Command::Stop { nodes, .. } => (
            format!(
                "cancels running commands, then 6xx#2B40600002000000 (quick stop) and 6xx#2B40600000000000 \
                 (disable voltage) to {}",
                if nodes.is_empty() {
                    "every drive cotui commanded or sees powered".to_string()
                } else {
                    format!(
                        "nodes {}",
                        nodes.iter().map(u8::to_string).collect::<Vec<_>>().join(", ")
                    )
                }
            ),
            None,
        ),
        Command::Record { .. } => {
            return Err("record runs from the command line (`cotui record IFACE -o FILE`)".into());
        }
    };
    Ok(Planned {
        line: line.trim().to_string(),
        command,
        preview,
        confirm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b() -> Bindings {
        Bindings::new().unwrap()
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
                .contains("no parameter `rpm`")
        );
        assert!(
            plan("run 2 fly", &b, |_| None)
                .unwrap_err()
                .contains("its procedures: ")
        );
    }

    #[test]
    fn broadcasts_and_resets_need_confirming() {
        assert_eq!(
            plan("nmt start 0", &b(), |_| None).unwrap().confirm.as_deref(),
            Some("broadcast NMT start to every node")
        );
        assert!(plan("nmt reset-node 4", &b(), |_| None).unwrap().confirm.is_some());
        assert!(plan("sdo read 2 nonsense_object", &b(), |_| None).is_err());
    }
}
