//! The columns of a Parquet table: their types, the values of a row, and the IO error a
//! Parquet error stands for (shared by the table and its column buffers).

use std::io;

/// Physical and logical type of a column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ty {
    Bool,
    I32,
    I64,
    /// INT64 whose values hardly repeat (nanosecond times, line numbers), delta-encoded.
    I64Unique,
    F64,
    /// INT64 microseconds since the Unix epoch, TIMESTAMP(MICROS, UTC), delta-encoded.
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

/// The IO error a Parquet error stands for: a failed write of the file underneath (disk
/// full) is that error, as the OS says it.
pub(super) fn pq_err(e: parquet::errors::ParquetError) -> io::Error {
    if let parquet::errors::ParquetError::External(inner) = &e
        && let Some(io) = inner.downcast_ref::<io::Error>()
    {
        return io::Error::new(io.kind(), io.to_string());
    }
    io::Error::other(format!("parquet: {e}"))
}
