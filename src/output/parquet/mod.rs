//! A Parquet table written in row groups by a thread of its own: rows are buffered column
//! by column on the caller's thread and each full row group ([`ROW_GROUP_ROWS`] rows or
//! [`ROW_GROUP_BYTES`] buffered bytes, whichever comes first) goes to the table's writer
//! thread, which encodes and compresses it while the caller fills the next one (two row
//! groups at most per table, so memory stays flat whatever the input size).
//!
//! The schema is a list of [`Col`]umns (name, type, nullable); rows are pushed value by
//! value in schema order through [`Table::row`]. Short, repeated strings ([`Ty::Str`]:
//! kinds, interface and file names) and INT64s are dictionary-encoded; INT32s, free text
//! ([`Ty::Text`]) and bytes are plain-encoded, timestamps and [`Ty::I64Unique`] numbers
//! delta-encoded (a dictionary of values that hardly repeat only costs hashing). Strings
//! and bytes have no statistics. The file is Snappy-compressed.
//!
//! Every type is one Spark, Trino and DuckDB read as written: signed INT32/INT64 (no
//! unsigned annotations), DOUBLE, BOOLEAN, BYTE_ARRAY (UTF8 or plain binary) and
//! INT64 TIMESTAMP(MICROS, UTC) (Spark rejects TIMESTAMP(NANOS)).

mod column;
mod group;

use column::pq_err;
pub use column::{Col, Ty, V};
use group::Group;
pub use group::Row;
use parquet::basic::{Compression, Encoding};
use parquet::file::properties::{EnabledStatistics, WriterProperties};
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::parser::parse_message_type;
use parquet::schema::types::ColumnPath;
use std::io::{self, Write};
use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, SyncSender, channel, sync_channel};
use std::thread::JoinHandle;

/// Rows per row group (a row group is the unit a reader skips or reads in parallel).
pub const ROW_GROUP_ROWS: usize = 65_536;

/// Buffered bytes (estimated) after which a row group is written even if it has fewer
/// rows: a table whose rows trickle in (SDO transactions) must not grow until 65536.
pub const ROW_GROUP_BYTES: usize = 16 << 20;

/// Values handed to the column encoder per step.
const WRITE_BATCH: usize = 8192;

/// A table that could not be written: the error, and the input line of the last row of
/// the row group being written then (or of the row that did not fit).
#[derive(Debug)]
pub struct WriteFailed {
    pub line: u64,
    pub error: io::Error,
}

/// The schema line of one column, in the Parquet message-type syntax.
fn schema_line(c: &Col) -> String {
    let rep = if c.null { "OPTIONAL" } else { "REQUIRED" };
    let ty = match c.ty {
        Ty::Bool => "BOOLEAN",
        Ty::I32 => "INT32",
        Ty::I64 | Ty::I64Unique => "INT64",
        Ty::F64 => "DOUBLE",
        Ty::TimestampUs => "INT64",
        Ty::Str | Ty::Text | Ty::Bin => "BYTE_ARRAY",
    };
    let logical = match c.ty {
        Ty::TimestampUs => " (TIMESTAMP(MICROS,true))",
        Ty::Str | Ty::Text => " (UTF8)",
        _ => "",
    };
    format!("  {rep} {ty} {}{logical};\n", c.name)
}

/// A Parquet file being written.
pub struct Table {
    cols: Vec<Col>,
    /// The row group being filled.
    group: Group,
    /// An emptied group back from the writer thread, to fill next.
    spare: Option<Group>,
    /// Full groups to the writer thread; `None` asks it for the footer.
    to_writer: SyncSender<Option<Group>>,
    /// Emptied groups back from it.
    back: Receiver<Group>,
    /// A group is at the writer thread and not back yet.
    in_flight: bool,
    writer: Option<JoinHandle<Result<(), WriteFailed>>>,
}

impl Table {
    /// Starts a table named `name` with `cols` on `out`, written by a thread of its own.
    pub fn new<W: Write + Send + 'static>(out: W, name: &str, cols: &[Col]) -> io::Result<Table> {
        let mut schema = format!("message {name} {{\n");
        for c in cols {
            schema.push_str(&schema_line(c));
        }
        schema.push('}');
        let schema = Arc::new(parse_message_type(&schema).map_err(pq_err)?);
        let mut props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .set_created_by(format!("cotui {}", env!("CARGO_PKG_VERSION")))
            // Values go to the encoder a row group at a time: bigger steps, less overhead.
            .set_write_batch_size(WRITE_BATCH);
        for c in cols {
            let path = ColumnPath::from(c.name);
            // A dictionary of values that hardly repeat only costs hashing each of them
            // (until the dictionary outgrows its page and the column falls back to plain);
            // one of INT32s (ids, lengths, node-IDs) kept the file 13 % smaller for 14 %
            // more encoding work, and the encoding is what the decode waits on.
            if matches!(c.ty, Ty::I32 | Ty::I64Unique | Ty::TimestampUs | Ty::Text | Ty::Bin) {
                props = props.set_column_dictionary_enabled(path.clone(), false);
            }
            // Rising numbers: a few bits per value where plain spent 8 (and Snappy found
            // little to squeeze).
            if matches!(c.ty, Ty::I64Unique | Ty::TimestampUs) {
                props = props.set_column_encoding(path.clone(), Encoding::DELTA_BINARY_PACKED);
            }
            // No min/max of strings or bytes: comparing every value cost more than
            // encoding the column, and a reader rarely skips a row group on them.
            if matches!(c.ty, Ty::Str | Ty::Text | Ty::Bin) {
                props = props.set_column_statistics_enabled(path, EnabledStatistics::None);
            }
        }
        let props = props.build();
        let file = SerializedFileWriter::new(out, schema, Arc::new(props)).map_err(pq_err)?;
        // One group queued while the thread encodes another: the caller never waits on a
        // thread that keeps up.
        let (to_writer, groups) = sync_channel(1);
        let (done, back) = channel();
        let writer = std::thread::Builder::new()
            .name(format!("parquet {name}"))
            .spawn(move || write_groups(file, groups, done))?;
        Ok(Table {
            cols: cols.to_vec(),
            group: Group::new(cols),
            spare: None,
            to_writer,
            back,
            in_flight: false,
            writer: Some(writer),
        })
    }

    /// Adds one row from input line `line`: `fill` pushes every column's value in schema
    /// order. An error is the row's, or that of an earlier row group the thread wrote.
    pub fn row(&mut self, line: u64, fill: impl FnOnce(&mut Row) -> io::Result<()>) -> Result<(), WriteFailed> {
        self.group
            .row(line, fill)
            .map_err(|error| WriteFailed { line, error })?;
        if self.group.rows == ROW_GROUP_ROWS || self.group.bytes >= ROW_GROUP_BYTES {
            self.send()?;
        }
        Ok(())
    }

    /// Hands the filled group to the writer thread and takes an empty one.
    fn send(&mut self) -> Result<(), WriteFailed> {
        let next = match self.spare.take() {
            Some(g) => g,
            None if self.in_flight => self.take_back()?,
            None => Group::new(&self.cols),
        };
        let full = std::mem::replace(&mut self.group, next);
        if self.to_writer.send(Some(full)).is_err() {
            return Err(self.failure());
        }
        self.in_flight = true;
        Ok(())
    }

    /// Waits for the group at the writer thread to be written.
    fn take_back(&mut self) -> Result<Group, WriteFailed> {
        self.in_flight = false;
        self.back.recv().map_err(|_| self.failure())
    }

    /// Waits until every full row group is written; an error is the first write's.
    pub fn sync(&mut self) -> Result<(), WriteFailed> {
        if self.in_flight {
            let g = self.take_back()?;
            self.spare = Some(g);
        }
        Ok(())
    }

    /// The error the writer thread stopped on.
    fn failure(&mut self) -> WriteFailed {
        let joined = self.writer.take().map(JoinHandle::join);
        match joined {
            Some(Ok(Err(f))) => f,
            _ => WriteFailed {
                line: self.group.line,
                error: io::Error::other("parquet: the writer thread stopped"),
            },
        }
    }

    /// Writes the last row group and the footer.
    pub fn finish(mut self) -> Result<(), WriteFailed> {
        let last = std::mem::replace(&mut self.group, Group::new(&[]));
        if self.to_writer.send(Some(last)).is_err() || self.to_writer.send(None).is_err() {
            return Err(self.failure());
        }
        match self.writer.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            _ => Err(WriteFailed {
                line: 0,
                error: io::Error::other("parquet: the writer thread stopped"),
            }),
        }
    }
}

/// The writer thread: writes each group it gets and hands it back emptied; the footer
/// when asked (`None`), not when the table is dropped (a table cut short has none).
fn write_groups<W: Write + Send>(
    mut file: SerializedFileWriter<W>,
    groups: Receiver<Option<Group>>,
    back: Sender<Group>,
) -> Result<(), WriteFailed> {
    let mut line = 0;
    loop {
        match groups.recv() {
            Ok(Some(mut group)) => {
                line = group.line;
                group.write(&mut file).map_err(|error| WriteFailed { line, error })?;
                // The table may be finishing: then the group is not needed back.
                let _ = back.send(group);
            }
            Ok(None) => break,
            Err(_) => return Ok(()),
        }
    }
    file.finish().map_err(|e| WriteFailed { line, error: pq_err(e) })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const COLS: [Col; 3] = [
        Col {
            name: "a",
            ty: Ty::I32,
            null: false,
        },
        Col {
            name: "b",
            ty: Ty::Str,
            null: true,
        },
        Col {
            name: "t",
            ty: Ty::TimestampUs,
            null: false,
        },
    ];

    /// A file of the table's test, removed when dropped.
    struct TempFile(std::path::PathBuf);

    impl TempFile {
        fn new(name: &str) -> TempFile {
            TempFile(std::env::temp_dir().join(format!("cotui-parquet-{name}-{}.parquet", std::process::id())))
        }
    }

    impl Drop for TempFile {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }

    fn three_rows(t: &mut Table) {
        for i in 0..3 {
            t.row(i as u64, |r| {
                r.push(Some(V::I32(i)))?
                    .push((i != 1).then_some(V::Str("x")))?
                    .push(Some(V::I64(i as i64)))?;
                Ok(())
            })
            .unwrap();
        }
    }

    #[test]
    fn writes_a_parquet_file() {
        let path = TempFile::new("file");
        let mut t = Table::new(std::fs::File::create(&path.0).unwrap(), "t", &COLS).unwrap();
        three_rows(&mut t);
        t.finish().unwrap();
        let out = std::fs::read(&path.0).unwrap();
        assert_eq!(&out[..4], b"PAR1");
        assert_eq!(&out[out.len() - 4..], b"PAR1");
    }

    #[test]
    fn row_groups_are_cut_by_bytes_as_well_as_rows() {
        use parquet::file::reader::{FileReader, SerializedFileReader};
        let path = TempFile::new("groups");
        let mut t = Table::new(std::fs::File::create(&path.0).unwrap(), "t", &COLS).unwrap();
        let big = "x".repeat(100_000);
        for i in 0..300 {
            t.row(i as u64, |r| {
                r.push(Some(V::I32(i)))?
                    .push(Some(V::Str(&big)))?
                    .push(Some(V::I64(0)))?;
                Ok(())
            })
            .unwrap();
        }
        t.finish().unwrap();
        let meta = SerializedFileReader::new(std::fs::File::open(&path.0).unwrap())
            .unwrap()
            .metadata()
            .clone();
        // 300 rows of 100 kB: about 30 MB, so two row groups of at most 16 MiB, not one.
        assert_eq!(meta.file_metadata().num_rows(), 300);
        assert_eq!(meta.num_row_groups(), 2);
        assert!(meta.row_groups().iter().all(|g| g.num_rows() < 300));
    }

    /// A disk that is full from the first byte.
    struct Full;

    impl Write for Full {
        fn write(&mut self, _: &[u8]) -> io::Result<usize> {
            Err(io::Error::from(io::ErrorKind::StorageFull))
        }
        fn flush(&mut self) -> io::Result<()> {
            Err(io::Error::from(io::ErrorKind::StorageFull))
        }
    }

    #[test]
    fn a_failed_write_names_the_last_line_of_its_row_group() {
        let mut t = Table::new(Full, "t", &COLS).unwrap();
        for i in 0..ROW_GROUP_ROWS as i32 + 10 {
            t.row(1000 + i as u64, |r| {
                r.push(Some(V::I32(i)))?.push(None)?.push(Some(V::I64(i as i64)))?;
                Ok(())
            })
            .unwrap();
        }
        let failed = t.sync().unwrap_err();
        assert_eq!(failed.line, 1000 + ROW_GROUP_ROWS as u64 - 1);
        assert_eq!(failed.error.kind(), io::ErrorKind::StorageFull);
        // Finishing after a failure is that failure again, not a panic.
        let mut t = Table::new(Full, "t", &COLS).unwrap();
        three_rows(&mut t);
        assert_eq!(t.finish().unwrap_err().error.kind(), io::ErrorKind::StorageFull);
    }

    #[test]
    fn wrong_rows_are_errors_not_panics() {
        let mut t = Table::new(Vec::new(), "t", &COLS).unwrap();
        let short = t.row(7, |r| {
            r.push(Some(V::I32(1)))?;
            Ok(())
        });
        let short = short.unwrap_err();
        assert_eq!(short.line, 7);
        assert!(short.error.to_string().contains("1 values for 3 columns"));
        let mut t = Table::new(Vec::new(), "t", &COLS).unwrap();
        let null = t.row(0, |r| {
            r.push(None)?;
            Ok(())
        });
        assert!(null.unwrap_err().error.to_string().contains("column a"));
    }
}
