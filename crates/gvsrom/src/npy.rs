//! NumPy `.npy` arrays (little-endian f64, C order, written by npyz) inside an [`OutputDir`]:
//! whole arrays, and arrays streamed row by row whose number of rows is known only at the end; and
//! reading an array back checked against the dtype and shape its `meta.json` gives.

use crate::output::OutputDir;
use npyz::WriterBuilder;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// A `.npy` file that is missing, unreadable, or not the array its `meta.json` describes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {message}")]
pub struct NpyError {
    pub file: String,
    pub message: String,
}

fn npy_error(file: &str, message: impl Into<String>) -> NpyError {
    NpyError {
        file: file.into(),
        message: message.into(),
    }
}

/// Reads `dir/name` as a C-order array of dtype `descr` and shape `shape`, with no byte missing or
/// extra.
pub fn read_checked<T: npyz::Deserialize>(
    dir: &Path,
    name: &str,
    descr: &str,
    shape: &[usize],
) -> Result<Vec<T>, NpyError> {
    let (bytes, shown) = read_file(dir, name)?;
    parse_checked(&bytes, &shown, descr, shape)
}

/// The bytes of the array file `dir/name` and its path as errors show it. Only a regular file is
/// read ([`crate::output::read`]).
pub fn read_file(dir: &Path, name: &str) -> Result<(Vec<u8>, String), NpyError> {
    let path = dir.join(name);
    let shown = path.display().to_string();
    match crate::output::read_regular(&path) {
        Ok(bytes) => Ok((bytes, shown)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Err(npy_error(&shown, "missing array"))
        }
        Err(e) => Err(npy_error(&shown, format!("cannot read it: {e}"))),
    }
}

/// The array held by `bytes` (of the file shown as `shown` in errors), which must be a C-order
/// `.npy` array of dtype `descr` and shape `shape`, with no byte missing or extra.
pub fn parse_checked<T: npyz::Deserialize>(
    bytes: &[u8],
    shown: &str,
    descr: &str,
    shape: &[usize],
) -> Result<Vec<T>, NpyError> {
    // npyz multiplies the shape's dimensions in u64 without checking, so a header whose numbers
    // could overflow that product is refused before npyz reads it
    if let Some(bits) = header_number_bits(bytes).filter(|&b| b > 64) {
        return Err(npy_error(
            shown,
            format!(
                "not a valid .npy file: its header holds numbers of up to {bits} bits together, more than the 64 bits any array shape (product of dimensions) can take"
            ),
        ));
    }
    let npy = npyz::NpyFile::new(bytes)
        .map_err(|e| npy_error(shown, format!("not a valid .npy file: {e}")))?;
    let dtype = npy.dtype().descr();
    if dtype != format!("'{descr}'") {
        return Err(npy_error(
            shown,
            format!("dtype {dtype}, expected '{descr}'"),
        ));
    }
    if npy.order() != npyz::Order::C {
        return Err(npy_error(shown, "Fortran order, expected C order"));
    }
    let got: Vec<usize> = npy.shape().iter().map(|&d| d as usize).collect();
    if got != shape {
        return Err(npy_error(
            shown,
            format!("shape {got:?}, expected {shape:?} from meta.json"),
        ));
    }
    let size = std::mem::size_of::<T>();
    let expected = shape
        .iter()
        .try_fold(size, |a, &d| a.checked_mul(d))
        .ok_or_else(|| {
            npy_error(
                shown,
                format!("shape {shape:?} of {size}-byte values holds more bytes than any file"),
            )
        })?;
    let data_len = npy.into_inner().len();
    if data_len != expected {
        return Err(npy_error(
            shown,
            format!(
                "{} ({data_len} data bytes, expected {expected} for shape {shape:?})",
                if data_len < expected {
                    "truncated"
                } else {
                    "has trailing bytes"
                },
            ),
        ));
    }
    npyz::NpyFile::new(bytes)
        .and_then(|f| f.into_vec::<T>())
        .map_err(|e| npy_error(shown, format!("cannot read the data: {e}")))
}

/// The 1-D little-endian f64 array held by `bytes` (of the file shown as `shown` in errors), of
/// whatever length its header gives (a curve such as a model's `train_loss.npy`), checked like
/// [`parse_checked`].
pub fn parse_vector(bytes: &[u8], shown: &str) -> Result<Vec<f64>, NpyError> {
    let len = header_number_bits(bytes)
        .filter(|&b| b <= 64)
        .and_then(|_| npyz::NpyFile::new(bytes).ok())
        .map(|npy| npy.shape().to_vec());
    match len.as_deref() {
        Some(&[n]) => parse_checked(bytes, shown, "<f8", &[n as usize]),
        Some(shape) => Err(npy_error(
            shown,
            format!("shape {shape:?}, expected a 1-D array"),
        )),
        None => Err(npy_error(shown, "not a valid .npy file")),
    }
}

/// An upper bound of log₂ of the product of all integers written in the header of the `.npy` file
/// `bytes` (`None`: no header where npyz would read one; npyz then refuses the file itself).
///
/// The header is a Python literal, where an integer is a token starting with a digit (decimal,
/// `0x…`, `0o…`, `0b…`, with `_` between digits): one of k characters is below 16ᵏ, and a sum
/// `a + b` of such tokens below the product of their bounds. So 4 bits per character of every such
/// token bound the product of any dimensions (and of any of their prefixes) the header can give.
fn header_number_bits(bytes: &[u8]) -> Option<u64> {
    if bytes.get(..6)? != b"\x93NUMPY" {
        return None;
    }
    // version 1.0: a u16 header length; 2.0 and 3.0: a u32
    let (len, at): (usize, usize) = match bytes.get(6)? {
        1 => (
            u16::from_le_bytes([*bytes.get(8)?, *bytes.get(9)?]).into(),
            10,
        ),
        2 | 3 => (
            u32::from_le_bytes(bytes.get(8..12)?.try_into().ok()?) as usize,
            12,
        ),
        _ => return None,
    };
    let text = bytes.get(at..at.checked_add(len)?)?;
    Some(
        text.split(|c| !(c.is_ascii_alphanumeric() || *c == b'_'))
            .filter(|t| t.first().is_some_and(u8::is_ascii_digit))
            .map(|t| 4 * t.len() as u64)
            .sum(),
    )
}

fn shape_u64(shape: &[usize]) -> Vec<u64> {
    shape.iter().map(|&d| d as u64).collect()
}

/// Writes `data` (C order, `shape.iter().product()` values) as the array `name` of `dir`.
pub fn write_array(
    dir: &mut OutputDir,
    name: &str,
    shape: &[usize],
    data: &[f64],
) -> io::Result<()> {
    write_array_of(dir, name, shape, data)
}

/// [`write_array`] for any plain element type (`u8` → `|u1`, `u32` → `<u4`, `f64` → `<f8`).
pub fn write_array_of<T: npyz::AutoSerialize + Copy>(
    dir: &mut OutputDir,
    name: &str,
    shape: &[usize],
    data: &[T],
) -> io::Result<()> {
    let n: usize = shape.iter().product();
    if n != data.len() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{name}: shape {shape:?} holds {n} values, got {}",
                data.len()
            ),
        ));
    }
    dir.write_file(name, |w| {
        let mut npy = npyz::WriteOptions::<T>::new()
            .default_dtype()
            .shape(&shape_u64(shape))
            .writer(w)
            .begin_nd()?;
        npy.extend(data.iter().copied())?;
        npy.finish()
    })
}

/// An array of shape `(rows, row_shape…)` written one row at a time, with memory independent of the
/// number of rows: rows go to the scratch file `NAME.rows` of the output; [`NpyRows::finish`] writes
/// the header for the final row count followed by the data as `NAME` and removes the scratch file.
pub struct NpyRows {
    name: String,
    scratch: String,
    row_shape: Vec<usize>,
    row_len: usize,
    rows: usize,
    out: BufWriter<File>,
}

impl NpyRows {
    pub fn new(dir: &mut OutputDir, name: &str, row_shape: &[usize]) -> io::Result<Self> {
        let scratch = format!("{name}.rows");
        let out = BufWriter::with_capacity(1 << 16, dir.create_file(&scratch)?);
        Ok(NpyRows {
            name: name.into(),
            scratch,
            row_shape: row_shape.to_vec(),
            row_len: row_shape.iter().product(),
            rows: 0,
            out,
        })
    }

    /// Appends one row (`row_shape.iter().product()` values, C order).
    pub fn push(&mut self, row: impl IntoIterator<Item = f64>) -> io::Result<()> {
        let mut k = 0;
        for v in row {
            self.out.write_all(&v.to_le_bytes())?;
            k += 1;
        }
        if k != self.row_len {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "{}: a row of {k} values, expected {}",
                    self.name, self.row_len
                ),
            ));
        }
        self.rows += 1;
        Ok(())
    }

    /// Rows written so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Writes the array `NAME` (header for the rows written, then the data) and removes the scratch.
    pub fn finish(self, dir: &mut OutputDir) -> io::Result<()> {
        let NpyRows {
            name,
            scratch,
            row_shape,
            rows,
            out,
            ..
        } = self;
        out.into_inner().map_err(|e| e.into_error())?;
        let mut shape = vec![rows];
        shape.extend(&row_shape);
        let scratch_path = dir.staging().join(&scratch);
        dir.write_file(&name, |w| {
            let w = npyz::WriteOptions::<f64>::new()
                .default_dtype()
                .shape(&shape_u64(&shape))
                .writer(w)
                .write_header_only()?;
            io::copy(&mut File::open(&scratch_path)?, w)?;
            Ok(())
        })?;
        dir.remove_file(&scratch)
    }
}
