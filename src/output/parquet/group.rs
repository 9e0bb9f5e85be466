//! One row group being filled: the buffered values of every column (strings and bytes of
//! a column in one buffer, no allocation per value), and its encoding into the file.

use super::column::{Col, Ty, V, pq_err};
use bytes::Bytes;
use parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int32Type, Int64Type};
use parquet::file::writer::SerializedFileWriter;
use std::io::{self, Write};

/// Estimated buffer cost of one string or bytes value besides its bytes (its end offset,
/// and its `ByteArray` handle when the group is written).
const VALUE_OVERHEAD: usize = 40;

/// The buffered values of one column.
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
            Ty::I64 | Ty::I64Unique | Ty::TimestampUs => Values::I64(Vec::new()),
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
    #[inline(always)]
    fn push(&mut self, v: Option<V>) -> io::Result<usize> {
        let cost = match (&mut self.values, v) {
            (_, None) if self.col.null => {
                self.defs.push(0);
                return Ok(2);
            }
            (Values::Bool(b), Some(V::Bool(x))) => {
                b.push(x);
                1
            }
            (Values::I32(b), Some(V::I32(x))) => {
                b.push(x);
                4
            }
            (Values::I64(b), Some(V::I64(x))) => {
                b.push(x);
                8
            }
            (Values::F64(b), Some(V::F64(x))) => {
                b.push(x);
                8
            }
            (Values::Bytes { buf, ends }, Some(V::Str(s))) if self.col.ty != Ty::Bin => {
                buf.extend_from_slice(s.as_bytes());
                ends.push(buf.len());
                VALUE_OVERHEAD + s.len()
            }
            (Values::Bytes { buf, ends }, Some(V::Bin(s))) if self.col.ty == Ty::Bin => {
                buf.extend_from_slice(s);
                ends.push(buf.len());
                VALUE_OVERHEAD + s.len()
            }
            _ => {
                return Err(io::Error::other(format!(
                    "parquet column {}: value does not fit the column",
                    self.col.name
                )));
            }
        };
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
    /// of one shared buffer, so no copy or allocation per value. The buffer is lent until
    /// [`Column::reclaim`] (`None` for other columns).
    fn byte_arrays(&mut self, out: &mut Vec<ByteArray>) -> Option<Bytes> {
        out.clear();
        let Values::Bytes { buf, ends } = &mut self.values else {
            return None;
        };
        let data = Bytes::from(std::mem::take(buf));
        let mut start = 0;
        out.extend(ends.iter().map(|&end| {
            let v = ByteArray::from(data.slice(start..end));
            start = end;
            v
        }));
        Some(data)
    }

    /// Takes back the buffer lent by [`Column::byte_arrays`] once no value refers to it:
    /// the next group fills the same memory (a fresh buffer per group, allocated on the
    /// writer thread and grown on the decoder's, let the heap grow with the log).
    fn reclaim(&mut self, data: Bytes) {
        if let Values::Bytes { buf, .. } = &mut self.values {
            *buf = match data.try_into_mut() {
                Ok(unique) => Vec::from(unique),
                Err(shared) => Vec::with_capacity(shared.len()),
            };
        }
    }
}

/// The rows of one row group, column by column.
pub(super) struct Group {
    columns: Vec<Column>,
    pub(super) rows: usize,
    /// Estimated bytes buffered.
    pub(super) bytes: usize,
    /// The input line of the last row (where a failed write of this group is said to be).
    pub(super) line: u64,
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
    // Always inlined: the value's variant is then known where it is pushed.
    #[inline(always)]
    pub fn push(&mut self, v: Option<V>) -> io::Result<&mut Self> {
        let Some(c) = self.columns.get_mut(self.at) else {
            return Err(io::Error::other("parquet: more values than columns in a row"));
        };
        self.bytes += c.push(v)?;
        self.at += 1;
        Ok(self)
    }
}

impl Group {
    pub(super) fn new(cols: &[Col]) -> Group {
        Group {
            columns: cols.iter().map(|c| Column::new(*c)).collect(),
            rows: 0,
            bytes: 0,
            line: 0,
            arrays: Vec::new(),
        }
    }

    /// Adds one row from input line `line`: `fill` pushes every column's value in order.
    #[inline]
    pub(super) fn row(&mut self, line: u64, fill: impl FnOnce(&mut Row) -> io::Result<()>) -> io::Result<()> {
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
        self.line = line;
        Ok(())
    }

    /// Writes the buffered rows as one row group of `writer` and empties the group.
    pub(super) fn write<W: Write + Send>(&mut self, writer: &mut SerializedFileWriter<W>) -> io::Result<()> {
        if self.rows == 0 {
            return Ok(());
        }
        let mut group = writer.next_row_group().map_err(pq_err)?;
        for c in &mut self.columns {
            let Some(mut w) = group.next_column().map_err(pq_err)? else {
                return Err(io::Error::other(
                    "parquet: fewer columns in the file than in the schema",
                ));
            };
            let lent = c.byte_arrays(&mut self.arrays);
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
            if let Some(data) = lent {
                c.reclaim(data);
            }
            c.clear();
        }
        group.close().map_err(pq_err)?;
        self.rows = 0;
        self.bytes = 0;
        Ok(())
    }
}
