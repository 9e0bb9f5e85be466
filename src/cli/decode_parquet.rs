//! `cotui decode --format parquet -o DIR_OR_FILE`: the decoded frames and the decoded
//! values (SDO transactions and PDO signals) as two Parquet tables, for DuckDB, Spark or
//! Trino. Column names and types are a public contract, listed in the README
//! ("Parquet tables").

use super::decode_args::DecodeArgs;
use super::input;
use crate::command::ExitCode;
use crate::decode::{Body, Decoded, Decoder};
use crate::frame::{Flags, Frame, Interfaces};
use crate::od::Dictionary;
use crate::output::parquet::{Col, Table, Ty, V, WriteFailed};
use crate::sdo::{SdoCommand, Transaction};
use std::fs::File;
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};

const fn col(name: &'static str, ty: Ty, null: bool) -> Col {
    Col { name, ty, null }
}

/// Columns of `frames.parquet`, one row per frame.
pub const FRAME_COLS: [Col; 29] = [
    col("file", Ty::Str, false),
    col("line", Ty::I64Unique, false),
    col("ts", Ty::TimestampUs, false),
    col("ts_ns", Ty::I64Unique, false),
    col("iface", Ty::Str, false),
    col("id", Ty::I32, false),
    col("ext", Ty::Bool, false),
    col("rtr", Ty::Bool, false),
    col("fd", Ty::Bool, false),
    col("err", Ty::Bool, false),
    col("dir", Ty::Str, false),
    col("len", Ty::I32, false),
    col("data", Ty::Bin, false),
    col("kind", Ty::Str, false),
    col("node", Ty::I32, true),
    col("label", Ty::Text, false),
    col("malformed", Ty::Str, true),
    col("nmt_command", Ty::Str, true),
    col("nmt_target", Ty::I32, true),
    col("nmt_state", Ty::Str, true),
    col("emcy_code", Ty::I32, true),
    col("emcy_register", Ty::I32, true),
    col("emcy_text", Ty::Str, true),
    col("sdo_command", Ty::Str, true),
    col("sdo_index", Ty::I32, true),
    col("sdo_sub", Ty::I32, true),
    col("abort_code", Ty::I64, true),
    col("pdo_num", Ty::I32, true),
    col("pdo_transmit", Ty::Bool, true),
];

/// Columns of `values.parquet`: one row per SDO transaction and per PDO signal, of a node
/// of an interface (node 5 of can0 and node 5 of can1 are two nodes).
pub const VALUE_COLS: [Col; 22] = [
    col("file", Ty::Str, false),
    col("source", Ty::Str, false),
    col("ts", Ty::TimestampUs, false),
    col("ts_ns", Ty::I64Unique, false),
    col("start_ts", Ty::TimestampUs, false),
    col("start_ts_ns", Ty::I64Unique, false),
    col("iface", Ty::Str, false),
    col("node", Ty::I32, false),
    col("index", Ty::I32, true),
    col("sub", Ty::I32, true),
    col("name", Ty::Str, true),
    col("value", Ty::F64, true),
    col("value_text", Ty::Str, true),
    col("data", Ty::Bin, true),
    col("direction", Ty::Str, false),
    col("protocol", Ty::Str, true),
    col("outcome", Ty::Str, true),
    col("abort_code", Ty::I64, true),
    col("abort_text", Ty::Str, true),
    col("partial", Ty::Bool, false),
    col("pdo_num", Ty::I32, true),
    col("frames", Ty::I64, false),
];

/// Where the two tables go: `-o DIR` gives `DIR/frames.parquet` and `DIR/values.parquet`;
/// `-o NAME.parquet` gives `NAME.parquet` (frames) and `NAME.values.parquet`.
pub fn paths(output: &str) -> (PathBuf, PathBuf) {
    match output.strip_suffix(".parquet") {
        Some(stem) => (PathBuf::from(output), PathBuf::from(format!("{stem}.values.parquet"))),
        None => {
            let dir = Path::new(output);
            (dir.join("frames.parquet"), dir.join("values.parquet"))
        }
    }
}

/// A file of the Parquet output that cannot be made, named in the message.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
struct CreateError {
    path: PathBuf,
    source: io::Error,
}

fn create(path: &Path, name: &str, cols: &[Col]) -> Result<Table, CreateError> {
    let at = |p: &Path| {
        let path = p.to_path_buf();
        move |source| CreateError { path, source }
    };
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(at(dir))?;
    }
    let f = File::create(path).map_err(at(path))?;
    Table::new(BufWriter::with_capacity(1 << 16, f), name, cols).map_err(at(path))
}

/// Runs `cotui decode --format parquet`; returns the exit status.
pub fn run(args: &DecodeArgs) -> ExitCode {
    if args.transactions || args.summary || args.events {
        eprintln!(
            "cotui decode: --format parquet writes the frame and value tables; it does not go with --transactions, --summary or --events"
        );
        return ExitCode::Usage;
    }
    let Some(output) = args.output.as_deref().filter(|o| *o != "-") else {
        eprintln!(
            "cotui decode: parquet is binary and written as two files: give -o DIR (DIR/frames.parquet, DIR/values.parquet) or -o NAME.parquet, not stdout"
        );
        return ExitCode::Usage;
    };
    let mut decoder = match super::bind::decoder(&args.profiles, &args.eds) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let (frames_path, values_path) = paths(output);
    if !output.ends_with(".parquet") && Path::new(output).exists() && !Path::new(output).is_dir() {
        eprintln!(
            "cotui decode: cannot write {output}: not a directory (-o DIR writes DIR/frames.parquet and DIR/values.parquet; -o NAME.parquet writes NAME.parquet and NAME.values.parquet)"
        );
        return ExitCode::Usage;
    }
    let tables =
        create(&frames_path, "frames", &FRAME_COLS).and_then(|f| Ok((f, create(&values_path, "values", &VALUE_COLS)?)));
    let (mut frames, mut values) = match tables {
        Ok(t) => t,
        Err(e) => {
            eprintln!("cotui decode: {e}");
            return ExitCode::Usage;
        }
    };
    let mut status = ExitCode::Ok;
    let mut last_file = String::new();
    // The interface names of the last input (the transfers it left running name theirs).
    let mut ifaces = Interfaces::default();
    let (inputs, failed) = input::open_inputs(&args.files, "decode", args.iface_per_file, args.input.format());
    if failed {
        status = ExitCode::Unavailable;
    }
    for (path, input) in inputs {
        let path = &path;
        last_file.clone_from(path);
        ifaces = Interfaces::default();
        let tables = Tables {
            frames: &mut frames,
            values: &mut values,
            paths: (&frames_path, &values_path),
        };
        match write_stream(path, input, &mut decoder, &mut ifaces, tables) {
            Ok(()) => {}
            Err(Failed::Read(e)) => {
                eprintln!("cotui decode: {path}: {e}");
                status = ExitCode::Unavailable;
            }
            Err(Failed::Write(m)) => {
                // The output is to blame (1); the tables are cut short, so no footer either.
                eprintln!("cotui decode: {m}; stopped, the tables are incomplete");
                return ExitCode::Usage;
            }
        }
    }
    let mut end = || -> Result<(), WriteFailed> {
        for t in decoder.finish() {
            // Past the last input: no line to name (the message names none).
            transaction_row(
                &mut values,
                (&last_file, 0),
                ifaces.name(t.iface),
                &t,
                decoder.dictionary(t.node),
            )?;
        }
        Ok(())
    };
    fn at(table: &Path) -> impl Fn(WriteFailed) -> String + '_ {
        move |f| format!("{}: {}", table.display(), f.error)
    }
    let result = end()
        .map_err(at(&values_path))
        .and_then(|_| frames.finish().map_err(at(&frames_path)))
        .and_then(|_| values.finish().map_err(at(&values_path)));
    match result {
        Err(e) => {
            // Writing the tables failed: the output is to blame (1), not an input.
            eprintln!("cotui decode: cannot write {e}");
            ExitCode::Usage
        }
        Ok(()) => status,
    }
}

/// The two tables being written, and their paths (for a write error's message).
struct Tables<'a> {
    frames: &'a mut Table,
    values: &'a mut Table,
    paths: (&'a Path, &'a Path),
}

/// Why an input stopped: it could not be read, or a table could not be written (the
/// message names the table and where in the input it stopped).
enum Failed {
    Read(io::Error),
    Write(String),
}

/// Decodes one input into the two tables (parsing runs on a second thread); `names` keeps
/// up with its interface table.
fn write_stream(
    path: &str,
    input: input::Input,
    decoder: &mut Decoder,
    names: &mut Interfaces,
    tables: Tables,
) -> Result<(), Failed> {
    let Tables { frames, values, paths } = tables;
    // The first write error, said as the user reads it; reading stops there.
    let mut write_error: Option<String> = None;
    let mut wrote = |table: &Path, f: WriteFailed| {
        write_error.get_or_insert(format!(
            "cannot write {}: {} (at {path} line {})",
            table.display(),
            f.error,
            f.line
        ));
        io::Error::other("write failed")
    };
    let result = input::for_each_frame(path, input, |batch| {
        let ifaces = batch.ifaces;
        for name in ifaces.names().iter().skip(names.names().len()) {
            names.intern(name);
        }
        for (line, frame) in batch {
            let d = decoder.decode(frame);
            let iface = ifaces.name(frame.iface);
            frame_row(frames, (path, line), frame, iface, &d).map_err(|f| wrote(paths.0, f))?;
            if let (Body::Pdo(p), Some(node)) = (&d.body, d.node) {
                for s in &p.signals {
                    values
                        .row(line, |r| {
                            let (us, ns) = (V::I64(ts_us(frame.ts_ns)), V::I64(ts_ns(frame.ts_ns)));
                            r.push(Some(V::Str(path)))?
                                .push(Some(V::Str("pdo")))?
                                .push(Some(us.clone()))?
                                .push(Some(ns.clone()))?
                                .push(Some(us))?
                                .push(Some(ns))?
                                .push(Some(V::Str(iface)))?
                                .push(Some(V::I32(node as i32)))?
                                .push(Some(V::I32(s.index as i32)))?
                                .push(Some(V::I32(s.sub as i32)))?
                                .push(Some(V::Str(&s.name)))?
                                .push(s.value.as_f64().map(V::F64))?
                                .push(Some(V::Str(&s.text)))?
                                .push(None)?
                                .push(Some(V::Str(if p.transmit { "transmit" } else { "receive" })))?
                                .push(None)?
                                .push(None)?
                                .push(None)?
                                .push(None)?
                                .push(Some(V::Bool(false)))?
                                .push(Some(V::I32(p.num as i32)))?
                                .push(Some(V::I64(1)))?;
                            Ok(())
                        })
                        .map_err(|f| wrote(paths.1, f))?;
                }
            }
            decoder.recycle(d);
            for t in decoder.take_transactions() {
                transaction_row(
                    values,
                    (path, line),
                    ifaces.name(t.iface),
                    &t,
                    decoder.dictionary(t.node),
                )
                .map_err(|f| wrote(paths.1, f))?;
            }
        }
        Ok(())
    });
    // The row groups of this input written so far: a failed one is said with its line.
    let synced = frames
        .sync()
        .map_err(|f| wrote(paths.0, f))
        .and_then(|()| values.sync().map_err(|f| wrote(paths.1, f)));
    match (result.and_then(|counts| synced.map(|()| counts)), write_error) {
        (_, Some(m)) => Err(Failed::Write(m)),
        (Err(e), None) => Err(Failed::Read(e)),
        (Ok(counts), None) => {
            input::report_counts(path, &counts);
            Ok(())
        }
    }
}

/// A timestamp in ns as Parquet's signed INT64 (saturating past year 2262).
fn ts_ns(ns: u64) -> i64 {
    i64::try_from(ns).unwrap_or(i64::MAX)
}

/// A timestamp in ns as the microseconds of a TIMESTAMP(MICROS) column (truncated).
fn ts_us(ns: u64) -> i64 {
    (ns / 1000) as i64
}

/// One row of `frames.parquet` for frame `f` at `(file, line)`.
fn frame_row(t: &mut Table, (file, line): (&str, u64), f: &Frame, iface: &str, d: &Decoded) -> Result<(), WriteFailed> {
    let i32v = |v: i32| Some(V::I32(v));
    let (mut nmt_command, mut nmt_target, mut nmt_state) = (None, None, None);
    let (mut emcy_code, mut emcy_register, mut emcy_text) = (None, None, None);
    let (mut sdo_command, mut sdo_index, mut sdo_sub, mut abort_code) = (None, None, None, None);
    let (mut pdo_num, mut pdo_transmit) = (None, None);
    match &d.body {
        Body::Nmt(n) => {
            nmt_command = Some(V::Str(n.command()));
            nmt_target = i32v(n.target as i32);
        }
        Body::Heartbeat(h) => nmt_state = h.state.map(|s| V::Str(s.as_str())),
        Body::Emcy(e) => {
            emcy_code = i32v(e.code as i32);
            emcy_register = i32v(e.register as i32);
            emcy_text = Some(V::Str(&e.text));
        }
        Body::Sdo(s) => {
            sdo_command = Some(V::Str(s.command.cs_name()));
            if let Some((index, sub)) = s.object {
                sdo_index = i32v(index as i32);
                sdo_sub = i32v(sub as i32);
            }
            if let SdoCommand::Abort { code, .. } = s.command {
                abort_code = Some(V::I64(code as i64));
            }
        }
        Body::Pdo(p) => {
            pdo_num = i32v(p.num as i32);
            pdo_transmit = Some(V::Bool(p.transmit));
        }
        _ => {}
    }
    t.row(line, |r| {
        r.push(Some(V::Str(file)))?
            .push(Some(V::I64(line as i64)))?
            .push(Some(V::I64(ts_us(f.ts_ns))))?
            .push(Some(V::I64(ts_ns(f.ts_ns))))?
            .push(Some(V::Str(iface)))?
            .push(i32v(f.id as i32))?
            .push(Some(V::Bool(f.is_ext())))?
            .push(Some(V::Bool(f.is_rtr())))?
            .push(Some(V::Bool(f.is_fd())))?
            .push(Some(V::Bool(f.is_err())))?
            .push(Some(V::Str(if f.flags.has(Flags::TX) { "tx" } else { "rx" })))?
            .push(i32v(f.len as i32))?
            .push(Some(V::Bin(f.payload())))?
            .push(Some(V::Str(d.kind.as_str())))?
            .push(d.node.map(|n| V::I32(n as i32)))?
            .push(Some(V::Str(&d.label)))?
            .push(d.malformed.as_deref().map(V::Str))?
            .push(nmt_command)?
            .push(nmt_target)?
            .push(nmt_state)?
            .push(emcy_code)?
            .push(emcy_register)?
            .push(emcy_text)?
            .push(sdo_command)?
            .push(sdo_index)?
            .push(sdo_sub)?
            .push(abort_code)?
            .push(pdo_num)?
            .push(pdo_transmit)?;
        Ok(())
    })
}

/// One row of `values.parquet` for an SDO transaction of interface `iface`; the decoded
/// value, name and abort text are the ones `--transactions --format jsonl` gives.
fn transaction_row(
    t: &mut Table,
    (file, line): (&str, u64),
    iface: &str,
    tr: &Transaction,
    dict: &Dictionary,
) -> Result<(), WriteFailed> {
    let j = tr.to_json(dict);
    let partial = tr.is_partial();
    let frames = tr.frames.len() as u64 + tr.frames_dropped;
    t.row(line, |r| {
        r.push(Some(V::Str(file)))?
            .push(Some(V::Str("sdo")))?
            .push(Some(V::I64(ts_us(tr.end_ns))))?
            .push(Some(V::I64(ts_ns(tr.end_ns))))?
            .push(Some(V::I64(ts_us(tr.start_ns))))?
            .push(Some(V::I64(ts_ns(tr.start_ns))))?
            .push(Some(V::Str(iface)))?
            .push(Some(V::I32(tr.node as i32)))?
            .push((!partial).then_some(V::I32(tr.index as i32)))?
            .push((!partial).then_some(V::I32(tr.sub as i32)))?
            .push(j.name.map(V::Str))?
            .push(j.value.as_ref().and_then(|v| v.json.as_f64()).map(V::F64))?
            .push(j.value_text.as_deref().map(V::Str))?
            .push(Some(V::Bin(&tr.data)))?
            .push(Some(V::Str(tr.direction.as_str())))?
            .push(Some(V::Str(tr.protocol.as_str())))?
            .push(Some(V::Str(tr.outcome.as_str())))?
            .push(j.abort_code.map(|c| V::I64(c.into())))?
            .push(j.abort_text.map(V::Str))?
            .push(Some(V::Bool(partial)))?
            .push(None)?
            .push(Some(V::I64(frames as i64)))?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::Interfaces;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Arbitrary frames (any id, flags, length, bytes, time) decode into both tables
        /// without an error or a panic, and the file is complete.
        #[test]
        fn arbitrary_frames_make_valid_tables(
            frames in proptest::collection::vec(
                (prop_oneof![0u32..0x800, any::<u32>()], any::<u8>(), proptest::collection::vec(any::<u8>(), 0..9), any::<u64>()),
                0..40,
            )
        ) {
            let mut decoder = Decoder::new(Dictionary::default(), vec![]);
            let path = std::env::temp_dir().join(format!("cotui-parquet-fuzz-{}.parquet", std::process::id()));
            let mut t = Table::new(File::create(&path).unwrap(), "frames", &FRAME_COLS).unwrap();
            let mut v = Table::new(Vec::new(), "values", &VALUE_COLS).unwrap();
            let mut ifaces = Interfaces::default();
            ifaces.intern("can\u{1b}0");
            for (i, (id, flags, data, ts_ns)) in frames.iter().enumerate() {
                let mut f = Frame::classic(id & 0x1FFF_FFFF, data);
                f.flags = Flags(*flags);
                f.ts_ns = *ts_ns;
                let d = decoder.decode(&f);
                frame_row(&mut t, ("fuzz", i as u64), &f, ifaces.name(0), &d).unwrap();
                for tr in decoder.take_transactions() {
                    transaction_row(&mut v, ("fuzz", i as u64), ifaces.name(0), &tr, decoder.dictionary(tr.node)).unwrap();
                }
            }
            for tr in decoder.finish() {
                transaction_row(&mut v, ("fuzz", 0), ifaces.name(0), &tr, decoder.dictionary(tr.node)).unwrap();
            }
            t.finish().unwrap();
            v.finish().unwrap();
            let out = std::fs::read(&path).unwrap();
            std::fs::remove_file(&path).unwrap();
            prop_assert_eq!(&out[out.len() - 4..], b"PAR1");
        }
    }

    #[test]
    fn output_layout() {
        assert_eq!(
            paths("out/run1.parquet"),
            ("out/run1.parquet".into(), "out/run1.values.parquet".into())
        );
        assert_eq!(
            paths("pq/run1"),
            ("pq/run1/frames.parquet".into(), "pq/run1/values.parquet".into())
        );
    }
}
