//! One Parquet table written in row groups of at most [`ROW_GROUP`] rows:
//! columns buffered as they are filled, flushed when full, the file
//! written under a temporary name and renamed when closed (a reader never
//! sees half a file). Numbers are `DOUBLE` (NaN written as null, as pandas
//! writes a NaN) or `INT64`; the pages are Snappy-compressed.

use parquet::basic::Compression;
use parquet::data_type::{DoubleType, Int64Type};
use parquet::errors::ParquetError;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Most rows of one row group (bounds the memory a table takes whatever
/// the run's size).
pub const ROW_GROUP: usize = 1 << 20;

/// A column's kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// An optional `DOUBLE` (null for NaN).
    Number,
    /// A required `INT64`.
    Integer,
}

/// A column being filled.
enum Buffer {
    Number(Vec<f64>),
    Integer(Vec<i64>),
}

/// A table being written to `file`.
pub struct Table {
    file: PathBuf,
    partial: PathBuf,
    /// `None` once finished.
    writer: Option<SerializedFileWriter<File>>,
    columns: Vec<Buffer>,
    rows: usize,
}

/// `e` at `file`.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", file.display())]
pub struct WriteError {
    /// The table's file.
    pub file: PathBuf,
    /// Parquet's error (an I/O error among them).
    pub source: ParquetError,
}

impl Table {
    /// A table named `name` with `columns` (name, kind), to be written to `file`.
    ///
    /// # Errors
    /// The file cannot be created.
    pub fn create(file: &Path, name: &str, columns: &[(String, Kind)]) -> Result<Self, WriteError> {
        let partial = file.with_file_name(format!(
            ".{}.partial",
            file.file_name().unwrap_or_default().to_string_lossy()
        ));
        let at = |source| WriteError {
            file: file.to_owned(),
            source,
        };
        let fields = columns.iter().map(|(n, k)| Arc::new(field(n, *k)));
        let schema = Type::group_type_builder(name)
            .with_fields(fields.collect())
            .build()
            .map_err(at)?;
        let props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .build();
        let out = File::create(&partial).map_err(|e| at(e.into()))?;
        let writer =
            SerializedFileWriter::new(out, Arc::new(schema), Arc::new(props)).map_err(at)?;
        Ok(Self {
            file: file.to_owned(),
            partial,
            writer: Some(writer),
            columns: (columns.iter())
                .map(|(_, k)| match k {
                    Kind::Number => Buffer::Number(Vec::new()),
                    Kind::Integer => Buffer::Integer(Vec::new()),
                })
                .collect(),
            rows: 0,
        })
    }

    /// Appends `x` to number column `c`.
    pub fn number(&mut self, c: usize, x: f64) {
        if let Buffer::Number(v) = &mut self.columns[c] {
            v.push(x);
        }
    }

    /// Appends `x` to integer column `c`.
    pub fn integer(&mut self, c: usize, x: i64) {
        if let Buffer::Integer(v) = &mut self.columns[c] {
            v.push(x);
        }
    }

    /// Ends a row (every column filled once); flushes a full row group.
    ///
    /// # Errors
    /// Writing failed.
    pub fn end_row(&mut self) -> Result<(), WriteError> {
        self.rows += 1;
        if self.rows == ROW_GROUP {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes the buffered rows as a row group.
    fn flush(&mut self) -> Result<(), WriteError> {
        let file = self.file.clone();
        let at = |source| WriteError {
            file: file.clone(),
            source,
        };
        let writer =
            (self.writer.as_mut()).ok_or_else(|| at(ParquetError::General("finished".into())))?;
        let mut group = writer.next_row_group().map_err(at)?;
        for buffer in &mut self.columns {
            let mut column = (group.next_column().map_err(at)?).ok_or_else(|| {
                at(ParquetError::General(
                    "fewer columns than the schema".into(),
                ))
            })?;
            match buffer {
                Buffer::Number(v) => {
                    let defined: Vec<i16> = v.iter().map(|x| i16::from(!x.is_nan())).collect();
                    let values: Vec<f64> = v.iter().copied().filter(|x| !x.is_nan()).collect();
                    (column.typed::<DoubleType>())
                        .write_batch(&values, Some(&defined), None)
                        .map_err(at)?;
                    v.clear();
                }
                Buffer::Integer(v) => {
                    column
                        .typed::<Int64Type>()
                        .write_batch(v, None, None)
                        .map_err(at)?;
                    v.clear();
                }
            }
            column.close().map_err(at)?;
        }
        group.close().map_err(at)?;
        self.rows = 0;
        Ok(())
    }

    /// Writes the last row group and the footer, then renames the file into place.
    ///
    /// # Errors
    /// Writing or renaming failed (the partial file is removed).
    pub fn finish(mut self) -> Result<PathBuf, WriteError> {
        if self.rows > 0 {
            self.flush()?;
        }
        let at = |source| WriteError {
            file: self.file.clone(),
            source,
        };
        if let Some(writer) = self.writer.take() {
            writer.close().map_err(at)?;
        }
        std::fs::rename(&self.partial, &self.file).map_err(|e| at(e.into()))?;
        Ok(self.file.clone())
    }
}

impl Drop for Table {
    /// A table not finished leaves no file behind.
    fn drop(&mut self) {
        // Once renamed there is no partial file: this does nothing.
        let _ = std::fs::remove_file(&self.partial);
    }
}

/// The schema field of a column.
fn field(name: &str, kind: Kind) -> Type {
    use parquet::basic::{Repetition, Type as Physical};
    let (physical, repetition) = match kind {
        Kind::Number => (Physical::DOUBLE, Repetition::OPTIONAL),
        Kind::Integer => (Physical::INT64, Repetition::REQUIRED),
    };
    Type::primitive_type_builder(name, physical)
        .with_repetition(repetition)
        .build()
        .expect("a primitive column without a logical type is valid")
}
