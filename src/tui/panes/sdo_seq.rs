//! One SDO transfer as a sequence diagram: a client and a server column, one arrow per
//! frame in time order (→ client to server, ← server to client) with its time since the
//! transfer's first frame and a short label (command, toggle, block seqno, ackseq, CRC,
//! the abort in red where it happened), and a last row when the transfer was left
//! unanswered. Which frames are block segments is worked out once, when the diagram is
//! opened; the labels are decoded only for the rows on screen.

use super::{fit, header, selected};
use crate::analysis::trace::Trace;
use crate::sdo::codec::decode;
use crate::sdo::{Outcome, Protocol, SdoCommand, Side, Transaction, TransferDirection};
use ratatui::style::{Color, Style};
use ratatui::text::Line;

/// Width of the time column (`+1234.567 ms`).
const TIME: usize = 12;

/// One frame of the transfer: where it is in the trace, who sent it, and whether its
/// sender was inside a block sub-block (its first byte is then `last | seqno`).
#[derive(Clone, Copy, Debug)]
struct Step {
    pos: usize,
    side: Side,
    block_segment: bool,
}

/// An opened transfer: its index in the transactions and its frames as steps.
pub(crate) struct Sequence {
    /// Index of the transfer in the trace's transactions.
    pub(crate) transfer: usize,
    steps: Vec<Step>,
}

impl Sequence {
    /// The diagram of transfer `transfer` of `trace`: None when there is no such transfer.
    /// Reads every frame of the transfer once (for the block sub-block state).
    pub(crate) fn open(trace: &Trace, transfer: usize) -> Option<Sequence> {
        let t = trace.transactions.get(transfer)?;
        let data_side = match t.direction {
            TransferDirection::Download => Side::Client,
            TransferDirection::Upload => Side::Server,
        };
        // A block transfer caught mid-way starts inside a sub-block.
        let mut in_sub_block = t.protocol == Protocol::Block && t.is_partial();
        let mut data_done = false;
        let mut steps = Vec::with_capacity(t.frames.len());
        for &seq in &t.frames {
            let pos = seq.saturating_sub(1) as usize;
            if pos >= trace.len() {
                continue;
            }
            let f = trace.store.frame(pos);
            let side = if f.id == t.channel.request_cob {
                Side::Client
            } else {
                Side::Server
            };
            let block_segment = in_sub_block && side == data_side;
            match decode(side, f.payload(), block_segment) {
                SdoCommand::BlockDownloadInitiateResponse { .. } | SdoCommand::BlockUploadStart => in_sub_block = true,
                SdoCommand::BlockSegment { last: true, .. } => {
                    in_sub_block = false;
                    data_done = true;
                }
                SdoCommand::BlockDownloadAck { .. } | SdoCommand::BlockUploadAck { .. } => in_sub_block = !data_done,
                SdoCommand::Abort { .. } | SdoCommand::BlockDownloadEnd { .. } | SdoCommand::BlockUploadEnd { .. } => {
                    in_sub_block = false
                }
                _ => {}
            }
            steps.push(Step {
                pos,
                side,
                block_segment,
            });
        }
        Some(Sequence { transfer, steps })
    }

    /// Rows of the diagram: one per frame, and one more when frames were not kept or the
    /// transfer was left unanswered.
    pub(crate) fn len(&self, t: &Transaction) -> usize {
        self.steps.len() + usize::from(trailer(t, self.steps.last()).is_some())
    }

    /// The trace position of the frame of row `row` (None on the last, frameless row).
    pub(crate) fn position(&self, row: usize) -> Option<usize> {
        self.steps.get(row).map(|s| s.pos)
    }

    /// The title of the diagram's pane.
    pub(crate) fn title(t: &Transaction) -> String {
        let object = if t.is_partial() {
            "????:??".to_string()
        } else {
            format!("{:04X}:{:02X}", t.index, t.sub)
        };
        let outcome = match &t.outcome {
            Outcome::Aborted { by, .. } => format!("aborted by the {}", by.as_str()),
            o => o.as_str().to_string(),
        };
        // The protocol is unknown when the first answer never came.
        let protocol = match t.protocol {
            Protocol::Unknown => String::new(),
            p => format!("{} ", p.as_str()),
        };
        format!(
            " SDO transfer {object} node {} — {protocol}{}, {outcome} ",
            t.node,
            t.direction.as_str()
        )
    }

    /// The column header and rows `offset..offset + height - 1` of the diagram, `width`
    /// columns wide, row `chosen` drawn selected.
    pub(crate) fn lines(
        &self,
        trace: &Trace,
        t: &Transaction,
        width: usize,
        height: usize,
        offset: usize,
        chosen: usize,
    ) -> Vec<Line<'static>> {
        let lane = width.saturating_sub(TIME + 1);
        let client = format!("client (0x{:03X})", t.channel.request_cob);
        let server = format!("server (0x{:03X})", t.channel.response_cob);
        let gap = lane.saturating_sub(client.chars().count() + server.chars().count());
        let head = format!("{:>TIME$} {client}{}{server}", "time", " ".repeat(gap));
        let mut lines = vec![Line::styled(fit(&head, width), header())];
        let rows = height.saturating_sub(1);
        for (i, step) in self.steps.iter().enumerate().skip(offset).take(rows) {
            let f = trace.store.frame(step.pos);
            let cmd = decode(step.side, f.payload(), step.block_segment);
            let at = f.ts_ns.saturating_sub(t.start_ns) as f64 / 1e6;
            let time = format!("+{at:.3} ms");
            let text = format!("{time:>TIME$} {}", arrow(step.side, &label(&cmd), lane));
            let style = match cmd {
                SdoCommand::Abort { .. } => Style::default().fg(Color::Red),
                _ => Style::default(),
            };
            lines.push(row(fit(&text, width), style, i == chosen));
        }
        if let Some(last) = trailer(t, self.steps.last()) {
            let i = self.steps.len();
            if i >= offset && i < offset + rows {
                let inner = lane.saturating_sub(2);
                let text = format!("{:>TIME$} │{:^inner$}│", "", fit(&last, inner));
                lines.push(row(fit(&text, width), Style::default().fg(Color::Gray), i == chosen));
            }
        }
        lines
    }
}

/// A row in `style`, reversed when selected.
fn row(text: String, style: Style, chosen: bool) -> Line<'static> {
    let line = Line::styled(text, style);
    if chosen { line.style(selected()) } else { line }
}

/// The last, frameless row: frames beyond those kept, or the answer that never came.
fn trailer(t: &Transaction, last: Option<&Step>) -> Option<String> {
    if t.frames_dropped > 0 {
        return Some(format!("… {} more frames, not kept", t.frames_dropped));
    }
    if t.outcome != Outcome::Incomplete {
        return None;
    }
    Some(match last.map(|s| s.side) {
        Some(Side::Server) => "no answer from the client".to_string(),
        _ => "no answer from the server".to_string(),
    })
}

/// The arrow of a frame `side` sent, between the two lifelines, `lane` columns wide:
/// `│ label ───→│` from the client, `│←─── label │` from the server.
fn arrow(side: Side, label: &str, lane: usize) -> String {
    let inner = lane.saturating_sub(2);
    // The label, a space either side, and at least a three-column shaft.
    let label = fit(label, inner.saturating_sub(5));
    let shaft = inner.saturating_sub(label.chars().count() + 3);
    let line = "─".repeat(shaft);
    match side {
        Side::Client => format!("│ {label} {line}→│"),
        Side::Server => format!("│←{line} {label} │"),
    }
}

/// `0x6040:00`.
fn object(index: u16, sub: u8) -> String {
    format!("0x{index:04X}:{sub:02X}")
}

/// ` size 20` when the size was indicated.
fn size(size: Option<u32>) -> String {
    size.map(|s| format!(" size {s}")).unwrap_or_default()
}

/// `n bytes 0F 00`: expedited data.
fn bytes(data: &[u8]) -> String {
    format!("{} bytes {}", data.len(), crate::frame::hex::spaced(data))
}

/// ` last` on the last segment.
fn last(last: bool) -> &'static str {
    if last { " last" } else { "" }
}

/// The short label of one SDO frame in the diagram.
fn label(cmd: &SdoCommand) -> String {
    use SdoCommand::*;
    let bit = |b: bool| u8::from(b);
    match *cmd {
        InitiateDownload {
            index,
            sub,
            expedited: true,
            data,
            ..
        } => format!("initiate download {} {}", object(index, sub), bytes(data.bytes())),
        InitiateDownload {
            index, sub, size: s, ..
        } => format!("initiate download {}{}", object(index, sub), size(s)),
        InitiateDownloadResponse { index, sub } => format!("download response {}", object(index, sub)),
        DownloadSegment { toggle, last: l, data } => {
            format!("segment toggle={} {} bytes{}", bit(toggle), data.bytes().len(), last(l))
        }
        DownloadSegmentResponse { toggle } => format!("segment response toggle={}", bit(toggle)),
        InitiateUpload { index, sub } => format!("initiate upload {}", object(index, sub)),
        InitiateUploadResponse {
            index,
            sub,
            expedited: true,
            data,
            ..
        } => format!("upload response {} {}", object(index, sub), bytes(data.bytes())),
        InitiateUploadResponse {
            index, sub, size: s, ..
        } => format!("upload response {}{}", object(index, sub), size(s)),
        UploadSegment { toggle } => format!("segment request toggle={}", bit(toggle)),
        UploadSegmentResponse { toggle, last: l, data } => {
            format!("segment toggle={} {} bytes{}", bit(toggle), data.bytes().len(), last(l))
        }
        Abort { code, .. } => format!("ABORT 0x{code:08X} {}", crate::sdo::abort_text(code)),
        BlockDownloadInitiate {
            index,
            sub,
            crc,
            size: s,
        } => format!(
            "initiate block download {}{}{}",
            object(index, sub),
            size(s),
            if crc { " crc" } else { "" }
        ),
        BlockDownloadInitiateResponse {
            index, sub, blksize, ..
        } => format!("block download response {} blksize={blksize}", object(index, sub)),
        BlockDownloadAck { ackseq, blksize } | BlockUploadAck { ackseq, blksize } => {
            format!("block ack ackseq={ackseq} blksize={blksize}")
        }
        BlockDownloadEnd { unused, crc } | BlockUploadEnd { unused, crc } => {
            format!("end block crc 0x{crc:04X} unused={unused}")
        }
        BlockDownloadEndResponse | BlockUploadEndResponse => "end block response".to_string(),
        BlockUploadInitiate {
            index,
            sub,
            blksize,
            pst,
            ..
        } => format!(
            "initiate block upload {} blksize={blksize} pst={pst}",
            object(index, sub)
        ),
        BlockUploadInitiateResponse {
            index, sub, size: s, ..
        } => {
            format!("block upload response {}{}", object(index, sub), size(s))
        }
        BlockUploadStart => "start block upload".to_string(),
        BlockSegment { seqno, last: l, .. } => format!("block seq {seqno}{}", last(l)),
        Unknown { command } => format!("unknown command 0x{command:02X}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrows_point_from_the_sender_and_fill_the_lane() {
        assert_eq!(arrow(Side::Client, "go", 12), "│ go ─────→│");
        assert_eq!(arrow(Side::Server, "ok", 12), "│←───── ok │");
        assert_eq!(arrow(Side::Client, "go", 12).chars().count(), 12);
    }

    #[test]
    fn labels_name_the_fields_a_user_checks() {
        let abort = decode(Side::Server, &[0x80, 0x00, 0x20, 0x00, 0x00, 0x00, 0x02, 0x06], false);
        assert_eq!(
            label(&abort),
            "ABORT 0x06020000 Object does not exist in the object dictionary"
        );
        let seg = decode(Side::Client, &[0x85, 1, 2, 3, 4, 5, 6, 7], true);
        assert_eq!(label(&seg), "block seq 5 last");
        let ack = decode(Side::Server, &[0xA2, 0x7F, 0x7F, 0, 0, 0, 0, 0], false);
        assert_eq!(label(&ack), "block ack ackseq=127 blksize=127");
        let end = decode(Side::Client, &[0xC9, 0x34, 0x12, 0, 0, 0, 0, 0], false);
        assert_eq!(label(&end), "end block crc 0x1234 unused=2");
        let seg = decode(Side::Server, &[0x10, b'a', b'b', 0, 0, 0, 0, 0], false);
        assert_eq!(label(&seg), "segment toggle=1 7 bytes");
    }
}
