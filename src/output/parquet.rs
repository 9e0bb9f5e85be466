//! A Parquet table written in row groups: rows are buffered column by column and
//! flushed every [`ROW_GROUP_ROWS`] rows or [`ROW_GROUP_BYTES`] buffered bytes, whichever
//! comes first, so memory stays flat whatever the input size.
//!
//! The schema is a list of [`Col`]umns (name, type, nullable); rows are pushed value by
//! value in schema order through [`Table::row`]. Values are buffered column by column
//! (strings and bytes of a column in one buffer, no allocation per value) and handed to
//! the Parquet encoder a column at a time when the row group is written. Short, repeated
//! strings ([`Ty::Str`]: kinds, interface and file names) are dictionary-encoded; free
//! text ([`Ty::Text`]) and bytes are plain-encoded without statistics (a dictionary of
//! values that hardly repeat only costs hashing). The file is Snappy-compressed.
//!
//! Every type is one Spark, Trino and DuckDB read as written: signed INT32/INT64 (no
//! unsigned annotations), DOUBLE, BOOLEAN, BYTE_ARRAY (UTF8 or plain binary) and
//! INT64 TIMESTAMP(MICROS, UTC) (Spark rejects TIMESTAMP(NANOS)).

use bytes::Bytes;
use parquet::basic::Compression;
use parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int32Type, Int64Type};
use parquet::file::properties::{EnabledStatistics, WriterProperties};
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::parser::parse_message_type;
use parquet::schema::types::ColumnPath;
use std::io::{self, Write};
use std::sync::Arc;

/// Rows per row group (a row group is the unit a reader skips or reads in parallel).
pub const ROW_GROUP_ROWS: usize = 65_536;

/// Buffered bytes (estimated) after which a row group is written even if it has fewer
/// rows: a table whose rows trickle in (SDO transactions) must not grow until 65536.
pub const ROW_GROUP_BYTES: usize = 16 << 20;

/// Values handed to the column encoder per step.
const WRITE_BATCH: usize = 8192;

/// Estimated buffer cost of one string or bytes value besides its bytes (its end offset,
/// and its `ByteArray` handle when the group is written).
const VALUE_OVERHEAD: usize = 40;

/// Physical and logical type of a column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ty {
    Bool,
    I32,
    I64,
    F64,
    /// INT64 microseconds since the Unix epoch, TIMESTAMP(MICROS, UTC).
    TimestampUs,
    /// UTF-8 text with few distinct values (BYTE_ARRAY, UTF8), dictionary-encoded.
    Str,
    /// UTF-8 text with mostly distinct values (BYTE_ARRAY, UTF8), plain-encoded.
    Text,
    /// Raw bytes (BYTE_ARRAY).
    Bin,
}

/// One column of a table's schema.
#[derive(Clone, Copy, Debug)]
pub struct Col {
    pub name: &'static str,
    pub ty: Ty,
    /// Nullable (OPTIONAL) rather than REQUIRED.
    pub null: bool,
}

/// One value of a row; `None` is a null.
#[derive(Clone, Debug, PartialEq)]
pub enum V<'a> {
    Bool(bool),
    I32(i32),
    I64(i64),
    F64(f64),
    Str(&'a str),
    Bin(&'a [u8]),
}

/// The buffered values of one column in the current row group.
enum Values {
    Bool(Vec<bool>),
    I32(Vec<i32>),
    I64(Vec<i64>),
    F64(Vec<f64>),
    /// All values' bytes back to back, and where each value ends in `buf`.
    Bytes {
        buf: Vec<u8>,
        ends: Vec<usize>,
    },
}

struct Column {
    col: Col,
    values: Values,
    /// Definition levels (1 = present, 0 = null); only kept for nullable columns.
    defs: Vec<i16>,
}

impl Column {
    fn new(col: Col) -> Column {
        let values = match col.ty {
            Ty::Bool => Values::Bool(Vec::new()),
            Ty::I32 => Values::I32(Vec::new()),
            Ty::I64 | Ty::TimestampUs => Values::I64(Vec::new()),
            Ty::F64 => Values::F64(Vec::new()),
            Ty::Str | Ty::Text | Ty::Bin => Values::Bytes {
                buf: Vec::new(),
                ends: Vec::new(),
            },
        };
        Column {
            col,
            values,
            defs: Vec::new(),
        }
    }

    /// Appends one value and returns its estimated buffer cost; a value of the wrong type
    /// or a null in a required column is an error naming the column.
    #[inline]
    fn push(&mut self, v: Option<V>) -> io::Result<usize> {
        let cost = match &v {
            Some(V::Str(s)) => VALUE_OVERHEAD + s.len(),
            Some(V::Bin(b)) => VALUE_OVERHEAD + b.len(),
            _ => 8,
        };
        let ok = match (&mut self.values, v) {
            (_, None) if !self.col.null => false,
            (_, None) => {
                self.defs.push(0);
                return Ok(2);
            }
            (Values::Bool(b), Some(V::Bool(x))) => {
                b.push(x);
                true
            }
            (Values::I32(b), Some(V::I32(x))) => {
                b.push(x);
                true
            }
            (Values::I64(b), Some(V::I64(x))) => {
                b.push(x);
                true
            }
            (Values::F64(b), Some(V::F64(x))) => {
                b.push(x);
                true
            }
            (Values::Bytes { buf, ends }, Some(V::Str(s))) if self.col.ty != Ty::Bin => {
                buf.extend_from_slice(s.as_bytes());
                ends.push(buf.len());
                true
            }
            (Values::Bytes { buf, ends }, Some(V::Bin(s))) if self.col.ty == Ty::Bin => {
                buf.extend_from_slice(s);
                ends.push(buf.len());
                true
            }
            _ => false,
        };
        if !ok {
            return Err(io::Error::other(format!(
                "parquet column {}: value does not fit the column",
                self.col.name
            )));
        }
        if self.col.null {
            self.defs.push(1);
        }
        Ok(cost)
    }

    fn clear(&mut self) {
        self.defs.clear();
        match &mut self.values {
            Values::Bool(v) => v.clear(),
            Values::I32(v) => v.clear(),
            Values::I64(v) => v.clear(),
            Values::F64(v) => v.clear(),
            Values::Bytes { buf, ends } => {
                buf.clear();
                ends.clear();
            }
        }
    }

    /// The buffered strings or bytes as `ByteArray`s into `out` (cleared first): slices
    /// of one shared buffer, so no copy or allocation per value.
    fn byte_arrays(&mut self, out: &mut Vec<ByteArray>) {
        out.clear();
        let Values::Bytes { buf, ends } = &mut self.values else {
            return;
        };
        // The next group's values need as much room again: keep the capacity.
        let data = Bytes::from(std::mem::replace(buf, Vec::with_capacity(buf.capacity())));
        let mut start = 0;
        out.extend(ends.iter().map(|&end| {
            let v = ByteArray::from(data.slice(start..end));
            start = end;
            v
        }));
        ends.clear();
    }
}

/// The schema line of one column, in the Parquet message-type syntax.
fn schema_line(c: &Col) -> String {
    let rep = if c.null { "OPTIONAL" } else { "REQUIRED" };
    let ty = match c.ty {
        Ty::Bool => "BOOLEAN",
        Ty::I32 => "INT32",
        Ty::I64 => "INT64",
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

fn pq_err(e: parquet::errors::ParquetError) -> io::Error {
    // A failed write of the file underneath (disk full) is that error, as the OS says it.
    if let parquet::errors::ParquetError::External(inner) = &e
        && let Some(io) = inner.downcast_ref::<io::Error>()
    {
        return io::Error::new(io.kind(), io.to_string());
    }
    io::Error::other(format!("parquet: {e}"))
}

/// A Parquet file being written.
pub struct Table<W: Write + Send> {
    writer: SerializedFileWriter<W>,
    columns: Vec<Column>,
    rows: usize,
    /// Estimated bytes buffered in `columns`.
    bytes: usize,
    /// The `ByteArray`s of the string or bytes column being written (reused).
    arrays: Vec<ByteArray>,
}

/// One row being pushed: values go to the columns in schema order.
pub struct Row<'t> {
    columns: &'t mut [Column],
    at: usize,
    bytes: usize,
}

impl Row<'_> {
    /// Pushes the next column's value (`None` for null).
    #[inline]
    pub fn push(&mut self, v: Option<V>) -> io::Result<&mut Self> {
        let Some(c) = self.columns.get_mut(self.at) else {
            return Err(io::Error::other("parquet: more values than columns in a row"));
        };
        self.bytes += c.push(v)?;
        self.at += 1;
        Ok(self)
    }
}

impl<W: Write + Send> Table<W> {
    /// Starts a table named `name` with `cols` on `out`.
    pub fn new(out: W, name: &str, cols: &[Col]) -> io::Result<Table<W>> {
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
        for c in cols.iter().filter(|c| matches!(c.ty, Ty::Text | Ty::Bin)) {
            let path = ColumnPath::from(c.name);
            props = props
                .set_column_dictionary_enabled(path.clone(), false)
                .set_column_statistics_enabled(path, EnabledStatistics::None);
        }
        let props = props.build();
        let writer = SerializedFileWriter::new(out, schema, Arc::new(props)).map_err(pq_err)?;
        Ok(Table {
            writer,
            columns: cols.iter().map(|c| Column::new(*c)).collect(),
            rows: 0,
            bytes: 0,
            arrays: Vec::new(),
        })
    }

    /// Adds one row: `fill` pushes every column's value in schema order.
    pub fn row(&mut self, fill: impl FnOnce(&mut Row) -> io::Result<()>) -> io::Result<()> {
        let mut row = Row {
            columns: &mut self.columns,
            at: 0,
            bytes: 0,
        };
        fill(&mut row)?;
        let (pushed, bytes) = (row.at, row.bytes);
        if pushed != self.columns.len() {
            return Err(io::Error::other(format!(
                "parquet: a row has {pushed} values for {} columns",
                self.columns.len()
            )));
        }
        self.rows += 1;
        self.bytes += bytes;
        if self.rows == ROW_GROUP_ROWS || self.bytes >= ROW_GROUP_BYTES {
            self.flush_group()?;
        }
        Ok(())
    }

    /// Writes the buffered rows as one row group.
    fn flush_group(&mut self) -> io::Result<()> {
        if self.rows == 0 {
            return Ok(());
        }
        let mut group = self.writer.next_row_group().map_err(pq_err)?;
        for c in &mut self.columns {
            let Some(mut w) = group.next_column().map_err(pq_err)? else {
                return Err(io::Error::other(
                    "parquet: fewer columns in the file than in the schema",
                ));
            };
            c.byte_arrays(&mut self.arrays);
            let defs = c.col.null.then_some(c.defs.as_slice());
            match &c.values {
                Values::Bool(v) => w.typed::<BoolType>().write_batch(v, defs, None),
                Values::I32(v) => w.typed::<Int32Type>().write_batch(v, defs, None),
                Values::I64(v) => w.typed::<Int64Type>().write_batch(v, defs, None),
                Values::F64(v) => w.typed::<DoubleType>().write_batch(v, defs, None),
                Values::Bytes { .. } => w.typed::<ByteArrayType>().write_batch(&self.arrays, defs, None),
            }
            .map_err(pq_err)?;
            self.arrays.clear();
            w.close().map_err(pq_err)?;
            c.clear();
        }
        group.close().map_err(pq_err)?;
        self.rows = 0;
        self.bytes = 0;
        Ok(())
    }

    /// Writes the last row group and the footer.
    pub fn finish(mut self) -> io::Result<()> {
        self.flush_group()?;
        self.writer.close().map_err(pq_err)?;
        Ok(())
    }
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

    #[test]
    fn writes_a_parquet_file() {
        let mut out = Vec::new();
        let mut t = Table::new(&mut out, "t", &COLS).unwrap();
        for i in 0..3 {
            t.row(|r| {
                r.push(Some(V::I32(i)))?
                    .push((i != 1).then_some(V::Str("x")))?
                    .push(Some(V::I64(i as i64)))?;
                Ok(())
            })
            .unwrap();
        }
        t.finish().unwrap();
        assert_eq!(&out[..4], b"PAR1");
        assert_eq!(&out[out.len() - 4..], b"PAR1");
    }

    #[test]
    fn row_groups_are_cut_by_bytes_as_well_as_rows() {
        use parquet::file::reader::{FileReader, SerializedFileReader};
        let path = std::env::temp_dir().join(format!("cotui-parquet-groups-{}.parquet", std::process::id()));
        let mut t = Table::new(std::fs::File::create(&path).unwrap(), "t", &COLS).unwrap();
        let big = "x".repeat(100_000);
        for i in 0..300 {
            t.row(|r| {
                r.push(Some(V::I32(i)))?
                    .push(Some(V::Str(&big)))?
                    .push(Some(V::I64(0)))?;
                Ok(())
            })
            .unwrap();
        }
        t.finish().unwrap();
        let meta = SerializedFileReader::new(std::fs::File::open(&path).unwrap())
            .unwrap()
            .metadata()
            .clone();
        std::fs::remove_file(&path).unwrap();
        // 300 rows of 100 kB: about 30 MB, so two row groups of at most 16 MiB, not one.
        assert_eq!(meta.file_metadata().num_rows(), 300);
        assert_eq!(meta.num_row_groups(), 2);
        assert!(meta.row_groups().iter().all(|g| g.num_rows() < 300));
    }

    #[test]
    fn wrong_rows_are_errors_not_panics() {
        let mut t = Table::new(Vec::new(), "t", &COLS).unwrap();
        let short = t.row(|r| {
            r.push(Some(V::I32(1)))?;
            Ok(())
        });
        assert!(short.unwrap_err().to_string().contains("1 values for 3 columns"));
        let mut t = Table::new(Vec::new(), "t", &COLS).unwrap();
        let null = t.row(|r| {
            r.push(None)?;
            Ok(())
        });
        assert!(null.unwrap_err().to_string().contains("column a"));
    }
}
