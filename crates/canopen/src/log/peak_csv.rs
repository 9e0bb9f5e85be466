//! PEAK CSV: the CSV that PEAK's tools (PEAK-Converter `/TF=CSV`, run by PCAN-View users on
//! their `.trc` traces) export a trace as, with the columns of a TRC 2.x message line:
//!
//! ```text
//! ;$FILEVERSION=2.1
//! ;$STARTTIME=45244.5
//! Number,Time,Bus,Direction,Type,ID,Reserved,Length,D0,D1,D2,D3
//! 1,1841.300,1,Rx,DT,0181,-,2,11,22,,
//! 2,1842.000,2,Tx,FB,18FF0102,-,12,00,01,02,03,...
//! 3,1843.000,1,Rx,ST,-,-,4,00,04,00,00
//! 4,1844.000,1,Rx,EC,-,-,2,02,81,,
//! ```
//! A row is `Number, Time, Bus, Direction, Type, ID, Reserved, Length, D0 ... D63`: the
//! time offset in milliseconds (added to `$STARTTIME`, read as TRC reads it, when the
//! header has one), the bus (1-based), `Rx` or `Tx`, the TRC 2.x message type, the id in
//! hex, the length and one hex byte a column; an empty cell, `-` or `--` holds no value.
//! The delimiter (`,`, `;` or a tab: PEAK-Converter's `/CS=`) is taken from the first row;
//! with `;` or a tab a time may have a decimal comma. Lines before the rows are the tool's
//! header: `;` lines (`$STARTTIME` read, the rest skipped), other text skipped as comments,
//! and a row of column names (`Number,Time,Bus,...`, any case) that places the columns.
//!
//! Rows read as TRC 2.x lines read (see [`super::trc`]): bus N is interface `can{N-1}` (no
//! bus: `can0`); ids
//! of more than 4 digits are 29-bit; `FD`, `FB` (BRS), `FE` (ESI), `BI` (BRS and ESI) are
//! CAN FD frames, `RR` remote frames; `ST` rows are controller states from the PCAN status
//! code in their bytes, `ER` rows bus errors, `EC` rows the error counters (RX, then TX)
//! with the state they imply; `EV` and other types are skipped as events. The length is
//! the data length; an FD length 9 to 15 (or 12 with 24 data bytes or more) is a DLC.
//! `DT` rows in the default column order are read by a fast path (`fast.rs`).

mod fast;

use super::lex::{Channels, dec_u32, err, hex_u32, skip_ws, trim_end};
use super::trc::{self, Kind};
use super::{Line, ParseError, SkipReason};
use crate::frame::{Flags, Frame, Interfaces};

/// The most cells read from one row (64 data bytes, the leading columns and some more);
/// cells past it are not read.
const MAX_FIELDS: usize = 96;

/// The cells of a row: each one's index in the line and its text (blanks and quotes trimmed).
type Fields<'a> = [(usize, &'a [u8]); MAX_FIELDS];

/// Where the columns are (cell indexes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Columns {
    time: usize,
    bus: Option<usize>,
    dir: Option<usize>,
    kind: usize,
    id: usize,
    len: usize,
    data: usize,
}

/// The columns without a row of names: `Number, Time, Bus, Direction, Type, ID, Reserved,
/// Length, D0 ...`.
const DEFAULT_COLUMNS: Columns = Columns {
    time: 1,
    bus: Some(2),
    dir: Some(3),
    kind: 4,
    id: 5,
    len: 7,
    data: 8,
};

/// Parser state: delimiter, columns, start time, bus names. Use one parser with one
/// [`Interfaces`] table: it caches indexes into it.
#[derive(Debug)]
pub struct Parser {
    delim: Option<u8>,
    columns: Columns,
    start_ns: u64,
    /// A row was read (text that is not one is no longer a header).
    rows: bool,
    /// A row of column names was read (its rows need not start with a number).
    named: bool,
    channels: Channels,
}

impl Default for Parser {
    fn default() -> Self {
        Parser {
            delim: None,
            columns: DEFAULT_COLUMNS,
            start_ns: 0,
            rows: false,
            named: false,
            channels: Channels::default(),
        }
    }
}

impl Parser {
    /// A parser that takes the delimiter and columns from the first rows.
    pub fn new() -> Self {
        Parser::default()
    }

    /// Parses one line: a header line, the column names, or a row.
    pub fn parse_line(&mut self, line: &[u8], ifaces: &mut Interfaces) -> Result<Line, ParseError> {
        let s = trim_end(line);
        let at = skip_ws(s, 0);
        if at == s.len() {
            return Ok(Line::Skip(SkipReason::Blank));
        }
        if s[at] == b';' {
            return Ok(Line::Skip(match trc::header_entry(&s[at + 1..]) {
                Some((b"$STARTTIME", v)) => {
                    self.start_ns = trc::ole_days_to_ns(v).unwrap_or(0);
                    SkipReason::Header
                }
                Some((key, _)) if key.starts_with(b"$") => SkipReason::Header,
                _ => SkipReason::Comment,
            }));
        }
        let delim = self.delim.unwrap_or_else(|| delimiter(s));
        let mut fields = [(0usize, &s[..0]); MAX_FIELDS];
        let fields = split(s, delim, &mut fields);
        if !fields[0].1.first().is_some_and(u8::is_ascii_digit) {
            if let Some(names) = names(fields) {
                self.columns = names.map_err(|(at, m)| err(at, m))?;
                self.delim = Some(delim);
                self.named = true;
                return Ok(Line::Skip(SkipReason::Header));
            }
            if !self.named {
                return if self.rows {
                    Err(err(fields[0].0, "expected a message number"))
                } else {
                    Ok(Line::Skip(SkipReason::Comment))
                };
            }
        }
        self.delim = Some(delim);
        self.rows = true;
        self.row(fields, delim, s.len(), ifaces)
    }

    /// A message row of `end` bytes.
    fn row(
        &mut self,
        fields: &[(usize, &[u8])],
        delim: u8,
        end: usize,
        ifaces: &mut Interfaces,
    ) -> Result<Line, ParseError> {
        let c = self.columns;
        let cell = |i: usize| match fields.get(i) {
            Some(&(at, t)) if !is_none(t) => (at, Some(t)),
            Some(&(at, _)) => (at, None),
            None => (end, None),
        };
        let offset = time_ns(cell(c.time), delim)?;
        let (t_at, t) = cell(c.kind);
        let t = t.ok_or_else(|| err(t_at, "expected a message type"))?;
        let (bus, bus_at) = match c.bus.map(cell) {
            Some((at, Some(b))) => (dec_u32(b).ok_or_else(|| err(at, "expected a bus number"))?, at),
            _ => (1, 0),
        };
        let data = fields.get(c.data..).unwrap_or_default();
        let mut f = match trc::v2_kind(t) {
            Kind::Frame { fd, brs, esi, rtr, .. } => {
                let mut f = Frame::default();
                if let Some(d) = c.dir {
                    match cell(d) {
                        (_, None | Some(b"Rx" | b"RX" | b"rx")) => {}
                        (_, Some(b"Tx" | b"TX" | b"tx")) => f.flags.set(Flags::TX, true),
                        (at, Some(_)) => return Err(err(at, "expected Rx or Tx")),
                    }
                }
                let (id_at, id) = cell(c.id);
                trc::parse_id(&mut f, id_at, id.ok_or_else(|| err(id_at, "expected a CAN id"))?)?;
                let (n_at, n) = cell(c.len);
                let n = n.and_then(dec_u32).ok_or_else(|| err(n_at, "expected a data length"))?;
                let cells = data.iter().filter(|(_, t)| !is_none(t)).count();
                let is_dlc = fd && matches!(n, 9..=11 | 13..=15) || fd && n == 12 && cells >= 24;
                let n = Some((n, n_at));
                let (dlc, len) = if is_dlc { (n, None) } else { (None, n) };
                trc::set_length(&mut f, [fd, brs, esi, rtr], dlc, len, end)?;
                if !rtr {
                    bytes(&mut f, data, end)?;
                }
                f
            }
            Kind::Status => trc::status_frame(trc::hex_pairs(data.iter().copied()).0),
            Kind::Error => super::status::protocol_error(),
            Kind::Counters => trc::counters_frame(trc::hex_pairs(data.iter().copied()))
                .ok_or_else(|| err(data.first().map_or(end, |d| d.0), trc::COUNTERS))?,
            Kind::Other => return Ok(Line::Skip(SkipReason::Event)),
        };
        f.iface = self.channels.get(ifaces, bus, bus_at)?;
        f.ts_ns = self.start_ns.saturating_add(offset);
        Ok(Line::Frame(f))
    }
}

/// An empty cell, `-` or `--`: no value.
fn is_none(t: &[u8]) -> bool {
    matches!(t, b"" | b"-" | b"--")
}

/// The delimiter of a first row: a tab, else `;`, else `,` (a row with `;` or tabs between
/// its cells may have decimal commas).
fn delimiter(s: &[u8]) -> u8 {
    if s.contains(&b'\t') {
        b'\t'
    } else if s.contains(&b';') {
        b';'
    } else {
        b','
    }
}

/// The cells of `s` split at `delim` (at most [`MAX_FIELDS`]), blanks and double quotes
/// trimmed, into `out`.
fn split<'a, 'b>(s: &'a [u8], delim: u8, out: &'b mut Fields<'a>) -> &'b [(usize, &'a [u8])] {
    let mut n = 0;
    let mut at = 0;
    for cell in s.split(|&b| b == delim).take(MAX_FIELDS) {
        let lead = skip_ws(cell, 0);
        let mut t = trim_end(&cell[lead..]);
        let mut from = at + lead;
        if let [b'"', inner @ .., b'"'] = t {
            t = inner;
            from += 1;
        }
        out[n] = (from, t);
        n += 1;
        at += cell.len() + 1;
    }
    &out[..n]
}

/// The columns a row of names places, when `fields` is one (it names a type and an id
/// column, each cell a name alone or with a unit: `Time [ms]`); an error (index, message)
/// when it lacks a column rows need.
fn names(fields: &[(usize, &[u8])]) -> Option<Result<Columns, (usize, &'static str)>> {
    // A name, maybe with a unit after it (`Time [ms]`), lower-cased; `None` for other text.
    let word = |t: &[u8]| {
        let end = t
            .iter()
            .position(|&b| matches!(b, b' ' | b'[' | b'('))
            .unwrap_or(t.len());
        let unit = &t[skip_ws(t, end)..];
        let mut w = [0u8; 12];
        let n = end.min(w.len());
        w[..n].copy_from_slice(&t[..n]);
        w.make_ascii_lowercase();
        (unit.is_empty() || unit[0] == b'[' || unit[0] == b'(').then_some((w, n))
    };
    let find = |names: &[&[u8]]| {
        fields
            .iter()
            .position(|&(_, t)| word(t).is_some_and(|(w, n)| names.contains(&&w[..n])))
    };
    let (kind, id) = (find(&[b"type"])?, find(&[b"id"])?);
    let at = fields[0].0;
    let Some(time) = find(&[b"time"]) else {
        return Some(Err((at, "PEAK CSV column names without a Time column")));
    };
    let Some(len) = find(&[b"length", b"len", b"dlc"]) else {
        return Some(Err((at, "PEAK CSV column names without a Length column")));
    };
    Some(Ok(Columns {
        time,
        bus: find(&[b"bus"]),
        dir: find(&[b"direction", b"dir", b"rx/tx"]),
        kind,
        id,
        len,
        data: find(&[b"d0", b"data"]).unwrap_or(len + 1),
    }))
}

/// The time offset cell (milliseconds, `1841.300`; with `delim` not `,` also `1841,300`)
/// as nanoseconds.
fn time_ns((at, t): (usize, Option<&[u8]>), delim: u8) -> Result<u64, ParseError> {
    let t = t.ok_or_else(|| err(at, "expected a time offset (ms)"))?;
    let mut buf = [0u8; 32];
    let t = match t.iter().position(|&b| b == b',') {
        Some(i) if delim != b',' && t.len() <= buf.len() => {
            buf[..t.len()].copy_from_slice(t);
            buf[i] = b'.';
            &buf[..t.len()]
        }
        _ => t,
    };
    trc::offset_ns(Some((at, t)), at + t.len())
}

/// `f.len` data bytes, one a cell of 1 or 2 hex digits, from `cells`; `end` is the line's length.
fn bytes(f: &mut Frame, cells: &[(usize, &[u8])], end: usize) -> Result<(), ParseError> {
    for k in 0..f.len as usize {
        let (at, t) = match cells.get(k) {
            Some(&(_, t)) if is_none(t) => return Err(err(cells[k].0, "fewer data bytes than the length says")),
            Some(&c) => c,
            None => return Err(err(end, "fewer data bytes than the length says")),
        };
        f.data[k] = hex_u32(t)
            .filter(|&b| b <= 0xFF && t.len() <= 2)
            .ok_or_else(|| err(at, "expected a data byte of 2 hex digits"))? as u8;
    }
    Ok(())
}

/// Whether `s` is a PEAK CSV line: a row of column names (`Type`, `ID` and `Time`), or a
/// row `Number, Time, Bus, Direction, Type, ...` with a TRC 2.x message type.
pub(crate) fn is_peak_csv(s: &[u8]) -> bool {
    let mut fields = [(0usize, &s[..0]); MAX_FIELDS];
    let fields = split(s, delimiter(s), &mut fields);
    if fields.len() < 5 {
        return false;
    }
    if let Some(names) = names(fields) {
        return names.is_ok();
    }
    let number = fields[0].1;
    let time = fields[1].1;
    !number.is_empty()
        && number.iter().all(u8::is_ascii_digit)
        && !time.is_empty()
        && time.iter().all(|&b| b.is_ascii_digit() || b == b'.' || b == b',')
        && matches!(
            fields[4].1,
            b"DT" | b"FD" | b"FB" | b"FE" | b"BI" | b"RR" | b"ST" | b"ER" | b"EC" | b"EV"
        )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::log::{Format, LogReader, Outcome};

    fn lines(text: &str) -> (Vec<Result<Line, ParseError>>, Interfaces) {
        let (mut p, mut ifaces) = (Parser::new(), Interfaces::default());
        let got = text.lines().map(|l| p.parse_line(l.as_bytes(), &mut ifaces)).collect();
        (got, ifaces)
    }

    fn frame(got: &Result<Line, ParseError>) -> Frame {
        match got {
            Ok(Line::Frame(f)) => *f,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn rows_after_a_trc_header_and_column_names() {
        let (got, ifaces) = lines(
            ";$FILEVERSION=2.1\n;$STARTTIME=25570\n;   Start time: 02.01.1970\nNumber,Time,Bus,Direction,Type,ID,Reserved,Length,D0,D1,D2,D3\n\
             1,0.100,1,Rx,DT,0181,-,2,11,22,,\n\
             2,0.200,2,Tx,FB,18FF0102,-,12,00,01,02,03,04,05,06,07,08,09,0A,0B\n\
             3,0.300,1,Rx,RR,0701,-,1,,,,\n\
             4,0.400,1,Rx,ST,-,-,4,00,04,00,00\n\
             5,0.500,1,Rx,ER,-,-,5,04,00,02,00,00\n\
             6,0.600,1,Rx,EC,-,-,2,02,81\n\
             7,0.700,-,Rx,EV,-,-,-,user text\n\
             8,0.800,1,Rx,BI,00000123,-,9,0,1,2,3,4,5,6,7,8,9,A,B\n",
        );
        assert_eq!(got[0], Ok(Line::Skip(SkipReason::Header)));
        assert_eq!(got[2], Ok(Line::Skip(SkipReason::Comment)));
        assert_eq!(got[3], Ok(Line::Skip(SkipReason::Header)));
        let f = frame(&got[4]);
        assert_eq!(
            (f.ts_ns, f.id, f.payload(), ifaces.name(f.iface)),
            (86_400_000_100_000, 0x181, &[0x11, 0x22][..], "can0")
        );
        let f = frame(&got[5]);
        assert_eq!(
            (ifaces.name(f.iface), f.flags.0, f.len, f.data[11]),
            (
                "can1",
                Flags::EXT | Flags::TX | Flags::FD | Flags::FDF | Flags::BRS,
                12,
                0x0B
            )
        );
        let f = frame(&got[6]);
        assert_eq!((f.id, f.flags.0, f.len), (0x701, Flags::RTR, 1));
        assert_eq!((frame(&got[7]).id, frame(&got[7]).data[1]), (0x004, 0x20), "BUSPASSIVE");
        assert_eq!(frame(&got[8]).id, 0x88);
        let f = frame(&got[9]);
        assert_eq!((f.id, f.data[1], f.data[6], f.data[7]), (0x204, 0x20, 0x81, 0x02));
        assert_eq!(got[10], Ok(Line::Skip(SkipReason::Event)));
        let f = frame(&got[11]);
        assert_eq!(
            (f.id, f.len, f.flags.0, f.data[11]),
            (
                0x123,
                12,
                Flags::EXT | Flags::FD | Flags::FDF | Flags::BRS | Flags::ESI,
                0x0B
            ),
            "BI, DLC 9"
        );
    }

    #[test]
    fn semicolons_tabs_quotes_and_named_columns() {
        let (got, _) =
            lines("; PEAK-Converter\nType of export: CSV, ID in hex, Time in ms\n1;1841,300;1;Rx;DT;0181;-;1;05;;\n");
        assert_eq!(got[0], Ok(Line::Skip(SkipReason::Comment)));
        assert_eq!(
            got[1],
            Ok(Line::Skip(SkipReason::Comment)),
            "header text, not column names"
        );
        assert_eq!((frame(&got[2]).ts_ns, frame(&got[2]).data[0]), (1_841_300_000, 5));
        let (got, _) = lines("1\t2.5\t3\tTx\tDT\t0123\t-\t0\n");
        let f = frame(&got[0]);
        assert_eq!((f.ts_ns, f.flags.0, f.id), (2_500_000, Flags::TX, 0x123));
        let (got, ifaces) =
            lines("\"type\",\"id\",\"time [ms]\",\"len\",\"bus\",\"d0\"\n\"DT\",\"7FF\",\"1.0\",\"1\",\"4\",\"AA\"\n");
        let f = frame(&got[1]);
        assert_eq!((f.id, f.data[0], ifaces.name(f.iface)), (0x7FF, 0xAA, "can3"));
    }

    #[test]
    fn malformed_rows_are_located() {
        let (got, _) = lines(
            "1,x.5,1,Rx,DT,0181,-,0\n1,1.0,1,Up,DT,0181,-,0\n1,1.0,1,Rx,DT,0800,-,0\n1,1.0,1,Rx,DT,0181,-,2,11\n1,1.0,1,Rx,DT,0181,-,1,1G\n1,1.0,1,Rx,EC,-,-,1,02\nNumber,Type,ID\ngarbage\n",
        );
        let e = |k: usize| got[k].unwrap_err();
        assert_eq!(e(0).column, 3);
        assert_eq!((e(1).column, e(1).message), (9, "expected Rx or Tx"));
        assert_eq!((e(2).column, e(2).message), (15, "CAN id out of range"));
        assert_eq!(
            (e(3).column, e(3).message),
            (26, "fewer data bytes than the length says")
        );
        assert_eq!(
            (e(4).column, e(4).message),
            (24, "expected a data byte of 2 hex digits")
        );
        assert_eq!(e(5).message, trc::COUNTERS);
        assert_eq!(e(6).message, "PEAK CSV column names without a Time column");
        assert_eq!((e(7).column, e(7).message), (1, "expected a message number"));
    }

    #[test]
    fn the_readers_batches_read_as_the_general_parser() {
        let text = "Number,Time,Bus,Direction,Type,ID,Reserved,Length,D0,D1\n1,0.100,1,Rx,DT,0181,-,2,11,22\n\
            2,0.200,2,Tx,DT,1ABCDEF0,-,1,AA,\r\n3,0.300,1,Rx,ST,-,-,4,00,04,00,00\n4,0.400,1,Rx,DT,0701,-,1,5\n\
            5,0.500,3,Rx,DT,0701,-,0,,\n";
        let (general, _) = lines(text);
        let want: Vec<Outcome> = general
            .into_iter()
            .map(|l| match l {
                Ok(Line::Frame(f)) => Outcome::Frame(f),
                Ok(Line::Skip(r)) => Outcome::Skip(r),
                Err(e) => Outcome::Warning(e.to_string()),
            })
            .collect();
        for cap in [7, 40, 4096] {
            let src = std::io::BufReader::with_capacity(cap, text.as_bytes());
            let mut r = LogReader::with_format(src, Format::PeakCsv);
            let mut got = Vec::new();
            r.fill(&mut got, 100).unwrap();
            let got: Vec<_> = got.into_iter().map(|(_, o)| o).collect();
            assert_eq!(got, want, "capacity {cap}");
        }
    }

    #[test]
    fn tells_its_lines() {
        assert!(is_peak_csv(b"1,1841.300,1,Rx,DT,0181,-,2,11,22"));
        assert!(is_peak_csv(b"Number;Time;Bus;Direction;Type;ID;Reserved;Length;D0"));
        assert!(!is_peak_csv(
            b"166064000,0000021A,false,Rx,0,8,FE,36,12,FE,69,05,07,AD,"
        ));
        assert!(!is_peak_csv(b"1700000000.1,0x181,0,0,0,2,ESI="));
        assert!(!is_peak_csv(b"      1         0.100 DT  1      0181 Rx -  2    11 22"));
    }
}
