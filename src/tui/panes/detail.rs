//! The Detail pane: the selected frame field by field and bit by bit (SDO command byte,
//! controlword/statusword bits, PDO signals), or the selected SDO transfer. Beside the main
//! pane on a wide terminal; on a narrow one `expand` on the trace toggles it below.

use super::{Selected, block, duration, kind_color};
use crate::analysis::trace::Trace;
use crate::decode::cia402::{describe_controlword, describe_statusword};
use crate::decode::{Body, Decoded};
use crate::frame::Frame;
use crate::sdo::{Outcome, SdoCommand, Side, Transaction};
use ratatui::Frame as TermFrame;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Wrap};

/// The bits of an SDO command byte, one line each.
pub fn sdo_command_bits(byte: u8, side: Side) -> Vec<String> {
    let cs = byte >> 5;
    let who = if side == Side::Client { "ccs" } else { "scs" };
    let mut v = vec![
        format!("command 0x{byte:02X} = {byte:08b}b"),
        format!("  bits 7-5 {who} = {cs}"),
    ];
    match (cs, side) {
        (1, Side::Client) | (2, Side::Server) => {
            v.push(format!("  bits 3-2 n = {} (unused bytes)", (byte >> 2) & 3));
            v.push(format!("  bit 1 e = {} (expedited)", (byte >> 1) & 1));
            v.push(format!("  bit 0 s = {} (size indicated)", byte & 1));
        }
        (0, Side::Client) | (0, Side::Server) => {
            v.push(format!("  bit 4 t = {} (toggle)", (byte >> 4) & 1));
            v.push(format!("  bits 3-1 n = {} (unused bytes)", (byte >> 1) & 7));
            v.push(format!("  bit 0 c = {} (last segment)", byte & 1));
        }
        (3, Side::Client) | (1, Side::Server) => v.push(format!("  bit 4 t = {} (toggle)", (byte >> 4) & 1)),
        _ => {}
    }
    v
}

fn frame_lines(trace: &Trace, f: &Frame, d: &Decoded, pos: usize) -> Vec<Line<'static>> {
    let mut v = vec![
        Line::styled(
            d.label.clone(),
            Style::default().fg(kind_color(d.kind)).add_modifier(Modifier::BOLD),
        ),
        Line::raw(format!(
            "frame {}  t {:.6} s  {}",
            pos + 1,
            f.ts_ns.saturating_sub(super::start_ns(trace)) as f64 / 1e9,
            trace.ifaces.name(f.iface)
        )),
        Line::raw(format!(
            "COB-ID 0x{:X}{}  {}  node {}",
            f.id,
            if f.is_ext() { " (29-bit)" } else { "" },
            d.kind.as_str(),
            d.node.map(|n| n.to_string()).unwrap_or_else(|| "-".into())
        )),
        Line::raw(match crate::output::explain::split(f) {
            Some(sp) => format!("{}: {} node {}", sp.text, sp.function, sp.node),
            None if f.is_err() => format!("error class 0x{:X}", f.id),
            None => "29-bit identifier: no CANopen split".to_string(),
        }),
        Line::raw(format!(
            "len {}{}{}{}",
            f.len,
            if f.is_rtr() { "  remote request" } else { "" },
            if f.is_fd() { "  CAN FD" } else { "" },
            if f.direction() == crate::frame::Direction::Tx {
                "  sent by us"
            } else {
                ""
            }
        )),
    ];
    let bytes: Vec<String> = f
        .payload()
        .iter()
        .enumerate()
        .map(|(i, b)| format!("[{i}] {b:02X} {b:08b}"))
        .collect();
    for chunk in bytes.chunks(2) {
        v.push(Line::raw(chunk.join("   ")));
    }
    if let Some(m) = &d.malformed {
        v.push(Line::styled(
            format!("malformed: {m}"),
            Style::default().fg(Color::LightRed),
        ));
    }
    let node = d.node.unwrap_or(0);
    let mode = trace.decoder().mode(crate::frame::NodeKey::of(f, node));
    let dict = trace.decoder().dictionary(node);
    match &d.body {
        Body::Sdo(s) => {
            if let Some(&b) = f.payload().first() {
                v.extend(sdo_command_bits(b, s.side).into_iter().map(Line::raw));
            }
            if let Some((i, sub)) = s.object {
                v.push(Line::raw(format!(
                    "object 0x{i:04X}:{sub:02X} {}",
                    s.name.clone().unwrap_or_default()
                )));
                let word =
                    |d: &[u8]| u16::from_le_bytes([d.first().copied().unwrap_or(0), d.get(1).copied().unwrap_or(0)]);
                match (s.command, i) {
                    (SdoCommand::InitiateDownload { data, .. }, 0x6040) => {
                        let cw = word(data.bytes());
                        v.push(Line::raw(format!(
                            "controlword {cw:016b}b: {}",
                            describe_controlword(cw, mode, dict.object(0x6040, 0))
                        )));
                    }
                    (SdoCommand::InitiateUploadResponse { data, .. }, 0x6041) => {
                        let sw = word(data.bytes());
                        v.push(Line::raw(format!(
                            "statusword {sw:016b}b: {}",
                            describe_statusword(sw, mode, dict.object(0x6041, 0))
                        )));
                    }
                    _ => {}
                }
            }
            if let Some(val) = &s.value {
                v.push(Line::raw(format!("value {}", val.text)));
            }
            for p in &s.problems {
                v.push(Line::styled(
                    format!("problem: {p}"),
                    Style::default().fg(Color::Yellow),
                ));
            }
        }
        Body::Pdo(p) => {
            if p.signals.is_empty() {
                v.push(Line::raw(
                    "no mapping known (bind a profile or capture the SDO mapping writes)",
                ));
            }
            if let Some(source) = &p.source {
                v.push(Line::raw(format!(
                    "mapping: {}",
                    crate::decode::pdo::source_text_since(source, super::start_ns(trace))
                )));
            }
            for s in &p.signals {
                v.push(Line::raw(format!(
                    "0x{:04X}:{:02X} {} = {}",
                    s.index, s.sub, s.name, s.text
                )));
                let raw = s.value.as_i64().unwrap_or(0) as u16;
                match (s.index, s.sub) {
                    (0x6040, 0) => v.push(Line::raw(format!(
                        "  {:016b}b {}",
                        raw,
                        describe_controlword(raw, mode, dict.object(0x6040, 0))
                    ))),
                    (0x6041, 0) => v.push(Line::raw(format!(
                        "  {:016b}b {}",
                        raw,
                        describe_statusword(raw, mode, dict.object(0x6041, 0))
                    ))),
                    _ => {}
                }
            }
        }
        Body::Emcy(e) => {
            v.push(Line::raw(format!("error code 0x{:04X} {}", e.code, e.text)));
            v.push(Line::raw(format!(
                "register 0x{:02X} [{}]",
                e.register,
                e.register_bits().join(", ")
            )));
            v.push(Line::raw(format!("manufacturer {}", crate::frame::hex::spaced(&e.mfr))));
            for (k, val) in &e.mfr_fields {
                v.push(Line::raw(format!("  {k} = {val}")));
            }
        }
        Body::Nmt(n) => v.push(Line::raw(format!(
            "command 0x{:02X} {}  target {}",
            n.cs,
            n.text(),
            n.target
        ))),
        Body::Heartbeat(h) => v.push(Line::raw(format!(
            "state {}  toggle {}",
            h.state.map(|s| s.text()).unwrap_or_else(|| "(request)".into()),
            h.toggle as u8
        ))),
        _ => {}
    }
    let objects = crate::output::explain::pdo_objects(d);
    v.extend(wire_lines(f, trace.stats.bitrate().bps, &objects));
    v
}

/// The frame on the wire: its figures, then its bits field by field, stuff bits marked; a
/// PDO's data bits by mapped object (`objects`, see [`crate::output::explain::pdo_objects`]).
pub fn wire_lines(f: &Frame, bitrate: u64, objects: &[crate::output::explain::MappedBits]) -> Vec<Line<'static>> {
    let wire = match crate::wire::rebuild(f) {
        Ok(w) => w,
        Err(e) => return vec![Line::raw(format!("on the wire: none ({e})"))],
    };
    let mut v = vec![Line::raw(format!(
        "on the wire: {}",
        crate::output::explain::figures_text(&wire, bitrate)
    ))];
    let stuff = Style::default().fg(Color::Yellow).add_modifier(Modifier::BOLD);
    let mut line: Vec<Span<'static>> = Vec::new();
    for g in crate::output::explain::wire_groups(&wire, objects) {
        let (field, bits) = (g.field, g.bits);
        let wide = matches!(field, crate::wire::Field::Data | crate::wire::Field::Crc);
        if wide && !line.is_empty() {
            v.push(Line::from(std::mem::take(&mut line)));
        }
        line.push(Span::styled(
            format!("{} ", field.as_str()),
            Style::default().fg(Color::DarkGray),
        ));
        if let Some(o) = g.object.map(|i| &objects[i]) {
            let numbers = format!("{}..{}", o.canopen_bits[0], o.canopen_bits[1]);
            line.push(Span::styled(
                format!("{} bits {numbers} ", o.label),
                Style::default().fg(Color::Cyan),
            ));
        }
        // Stuff bits come as `[b]`: shown as the bit alone, highlighted.
        let mut rest = bits.as_str();
        while !rest.is_empty() {
            if let Some(after) = rest.strip_prefix('[') {
                line.push(Span::styled(after[..1].to_string(), stuff));
                rest = &after[2..];
            } else {
                let n = rest.find('[').unwrap_or(rest.len());
                line.push(Span::raw(rest[..n].to_string()));
                rest = &rest[n..];
            }
        }
        line.push(Span::raw("  "));
        if wide {
            v.push(Line::from(std::mem::take(&mut line)));
        }
    }
    if !line.is_empty() {
        v.push(Line::from(line));
    }
    v.push(Line::styled(
        "stuff bits highlighted; ACK slot as sent (recessive)",
        Style::default().fg(Color::DarkGray),
    ));
    v
}

fn transaction_lines(trace: &Trace, t: &Transaction) -> Vec<Line<'static>> {
    let dict = trace.decoder().dictionary(t.node);
    let mut v = vec![
        Line::styled(t.label(dict), Style::default().add_modifier(Modifier::BOLD)),
        Line::raw(format!(
            "node {}  {} {}  {} frames  {}",
            t.node,
            t.direction.as_str(),
            t.protocol.as_str(),
            t.frames.len(),
            duration(t.duration_ns() as f64 / 1e9)
        )),
        Line::raw(format!("data {}", crate::frame::hex::spaced(&t.data))),
    ];
    if let Outcome::Aborted { code, text, by } = &t.outcome {
        v.push(Line::styled(
            format!("aborted by {} 0x{code:08X}: {text}", by.as_str()),
            Style::default().fg(Color::Red),
        ));
    }
    for p in &t.problems {
        v.push(Line::styled(
            format!("problem: {}", p.as_str()),
            Style::default().fg(Color::Yellow),
        ));
    }
    v
}

/// The Detail pane's state: the selected frame decoded, and whether it is shown on a
/// narrow terminal.
#[derive(Default)]
pub struct DetailPane {
    /// The frame shown, decoded, with its trace position.
    decoded: Option<(usize, Decoded)>,
    /// Shown below the main pane when the terminal is too narrow for the side column.
    shown: bool,
}

impl DetailPane {
    /// Decodes the frame `selected` names, unless it is the one decoded already.
    pub fn update(&mut self, trace: &Trace, selected: Option<Selected>) {
        let pos = match selected {
            Some(Selected::Frame(p)) => Some(p),
            _ => None,
        };
        if pos != self.decoded.as_ref().map(|(p, _)| *p) {
            self.decoded = pos.and_then(|p| trace.decode_positions(&[p]).pop().map(|d| (p, d)));
        }
    }

    /// True when toggled in below the main pane.
    pub fn shown(&self) -> bool {
        self.shown
    }

    /// Toggles the pane in below the main pane (a narrow terminal), or out.
    pub fn toggle(&mut self) {
        self.shown = !self.shown;
    }

    /// Takes the pane away from below the main pane.
    pub fn hide(&mut self) {
        self.shown = false;
    }

    /// Forgets the decoded frame (the trace started over).
    pub fn reset(&mut self) {
        self.decoded = None;
    }

    /// Draws the pane for `selected` ([`DetailPane::update`] must have decoded it).
    pub fn render(&self, trace: &Trace, selected: Option<Selected>, f: &mut TermFrame, area: Rect) {
        f.render_widget(block(" Detail ", false), area);
        let inner = block("", true).inner(area);
        let lines = match selected {
            Some(Selected::Transfer(i)) => match trace.transactions.get(i) {
                Some(t) => transaction_lines(trace, &t),
                None => vec![Line::raw("no transfer selected")],
            },
            Some(Selected::Frame(pos)) => match &self.decoded {
                Some((p, d)) if *p == pos => frame_lines(trace, &trace.store.frame(pos), d, pos),
                _ => vec![Line::raw("no frame selected")],
            },
            None => vec![Line::raw("no frame selected")],
        };
        f.render_widget(Paragraph::new(lines).wrap(Wrap { trim: false }), inner);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sdo_command_bits_name_every_field() {
        assert_eq!(
            sdo_command_bits(0x4B, Side::Server),
            [
                "command 0x4B = 01001011b",
                "  bits 7-5 scs = 2",
                "  bits 3-2 n = 2 (unused bytes)",
                "  bit 1 e = 1 (expedited)",
                "  bit 0 s = 1 (size indicated)"
            ]
        );
        assert_eq!(sdo_command_bits(0x60, Side::Client)[2], "  bit 4 t = 0 (toggle)");
    }

    #[test]
    fn sdo_controlword_and_statusword_values_are_broken_into_bits() {
        let mut a = crate::tui::panes::testutil::app();
        let mut t =
            crate::analysis::trace::Trace::new(crate::decode::Decoder::new(Default::default(), Vec::new()), 500_000);
        for (id, data) in [
            (0x602u32, [0x2B, 0x40, 0x60, 0x00, 0x0F, 0x00, 0, 0]),
            (0x602, [0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]),
            (0x582, [0x4B, 0x41, 0x60, 0x00, 0x37, 0x02, 0, 0]),
        ] {
            t.push(&Frame::classic(id, &data));
        }
        *a.capture_mut().trace_mut() = t;
        let lines = |a: &crate::tui::app::App, pos: usize| -> Vec<String> {
            let d = a.trace().decode_positions(&[pos]).pop().unwrap();
            frame_lines(a.trace(), &a.trace().store.frame(pos), &d, pos)
                .iter()
                .map(|l| l.spans.iter().map(|s| s.content.to_string()).collect())
                .collect()
        };
        assert!(lines(&a, 0).contains(&"controlword 0000000000001111b: Enable operation".to_string()));
        assert!(
            lines(&a, 2)
                .iter()
                .any(|l| l.starts_with("statusword 0000001000110111b: Operation enabled [")),
            "{:?}",
            lines(&a, 2)
        );
    }
}
