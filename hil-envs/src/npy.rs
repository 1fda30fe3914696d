//! A small, exact reader and writer for NumPy `.npy` files (format versions
//! 1.0, 2.0 and 3.0), so that the Python research stack can produce and read
//! the dataset's arrays.
//!
//! Supported element types on read: little-endian `f8`, `f4`, `i8`, `i4`,
//! `u1` and `b1` (all returned as `f64`); C order only. Files are always
//! written as version 1.0, little-endian `f8`, C order.
//!
//! Limits: a file holds at most [`hil_core::files::limits::ARRAY`] bytes
//! (a FIFO, device or directory is refused before anything is read) and an
//! array at most [`MAX_ELEMENTS`] elements, so that a small element type
//! cannot expand past 1 GiB as `f64`. The declared shape must match the
//! data exactly; nothing is allocated for the data before that is checked.
//! Every error is a [`HilError::Data`] naming the file and the header field
//! (`magic`, `version`, `header`, `descr`, `fortran_order`, `shape`, `data`).
//!
//! Private to the crate: the dataset format ([`crate::dataset`]) is the
//! public interface to these files.

use std::path::Path;

use hil_core::{HilError, Result};

const MAGIC: &[u8] = b"\x93NUMPY";

/// The most elements an array may have: 2^27, i.e. 1 GiB as `f64`.
pub const MAX_ELEMENTS: usize = 1 << 27;

/// An n-dimensional array of `f64` in C (row-major) order.
#[derive(Clone, Debug, PartialEq)]
pub struct NpyArray {
    /// The shape; the product of its entries is `data.len()`.
    pub shape: Vec<usize>,
    /// The entries, row-major.
    pub data: Vec<f64>,
}

impl NpyArray {
    /// An array of `shape` holding `data`; errors if the sizes disagree.
    pub fn new(shape: Vec<usize>, data: Vec<f64>) -> Result<Self> {
        let n: usize = shape.iter().product();
        if n != data.len() {
            return Err(HilError::invalid_input(
                "array",
                format!("shape {shape:?} needs {n} entries, got {}", data.len()),
            ));
        }
        Ok(Self { shape, data })
    }

    /// Row `i` of a 2-d array (or the `i`-th sub-array along axis 0).
    ///
    /// # Panics
    ///
    /// If the array has no axis or `i` is not below `shape[0]` (callers
    /// check the shape first, as the dataset loader does).
    pub fn row(&self, i: usize) -> &[f64] {
        let stride: usize = self.shape[1..].iter().product();
        &self.data[i * stride..(i + 1) * stride]
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Dtype {
    F8,
    F4,
    I8,
    I4,
    U1,
    B1,
}

impl Dtype {
    fn parse(descr: &str) -> Option<Self> {
        Some(match descr {
            "<f8" => Self::F8,
            "<f4" => Self::F4,
            "<i8" => Self::I8,
            "<i4" => Self::I4,
            "|u1" | "<u1" => Self::U1,
            "|b1" => Self::B1,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::F8 | Self::I8 => 8,
            Self::F4 | Self::I4 => 4,
            Self::U1 | Self::B1 => 1,
        }
    }

    fn decode(self, b: &[u8]) -> f64 {
        match self {
            Self::F8 => f64::from_le_bytes(b.try_into().expect("8 bytes")),
            Self::F4 => f32::from_le_bytes(b.try_into().expect("4 bytes")) as f64,
            Self::I8 => i64::from_le_bytes(b.try_into().expect("8 bytes")) as f64,
            Self::I4 => i32::from_le_bytes(b.try_into().expect("4 bytes")) as f64,
            Self::U1 | Self::B1 => b[0] as f64,
        }
    }
}

fn bad(path: &Path, field: &str, why: impl Into<String>) -> HilError {
    HilError::Data {
        path: path.to_path_buf(),
        record: 1,
        field: field.to_string(),
        why: why.into(),
    }
}

/// Reads a `.npy` file.
pub fn read_npy(path: &Path) -> Result<NpyArray> {
    let bytes = hil_core::files::read_bytes(path, hil_core::files::limits::ARRAY)?;
    read_npy_bytes(&bytes, path)
}

/// Parses `.npy` bytes; `path` only names the source in errors.
pub fn read_npy_bytes(bytes: &[u8], path: &Path) -> Result<NpyArray> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err(bad(path, "magic", "not a NumPy .npy file"));
    }
    let major = bytes[6];
    let (header_len, start): (usize, usize) = match major {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 => {
            if bytes.len() < 12 {
                return Err(bad(path, "header", "truncated header length"));
            }
            (
                u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
                12,
            )
        }
        v => {
            return Err(bad(
                path,
                "version",
                format!("unsupported .npy version {v}"),
            ));
        }
    };
    let end = start
        .checked_add(header_len)
        .filter(|&e| e <= bytes.len())
        .ok_or_else(|| bad(path, "header", "header runs past the end of the file"))?;
    let header = std::str::from_utf8(&bytes[start..end])
        .map_err(|_| bad(path, "header", "header is not text"))?;
    let descr =
        dict_value(header, "descr").ok_or_else(|| bad(path, "descr", "header has no `descr`"))?;
    let descr = descr.trim().trim_matches(|c| c == '\'' || c == '"');
    let dtype = Dtype::parse(descr).ok_or_else(|| {
        bad(
            path,
            "descr",
            format!("unsupported element type `{descr}` (use <f8, <f4, <i8, <i4, u1 or b1)"),
        )
    })?;
    let fortran = dict_value(header, "fortran_order")
        .ok_or_else(|| bad(path, "fortran_order", "header has no `fortran_order`"))?;
    if fortran.trim() != "False" {
        return Err(bad(
            path,
            "fortran_order",
            "Fortran-ordered arrays are not supported; save with np.ascontiguousarray",
        ));
    }
    let shape_txt =
        dict_value(header, "shape").ok_or_else(|| bad(path, "shape", "header has no `shape`"))?;
    let inner = shape_txt
        .trim()
        .strip_prefix('(')
        .and_then(|s| s.strip_suffix(')'))
        .ok_or_else(|| bad(path, "shape", format!("`{shape_txt}` is not a tuple")))?;
    let mut shape = Vec::new();
    for part in inner.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        shape.push(
            part.parse::<usize>()
                .map_err(|_| bad(path, "shape", format!("`{part}` is not a dimension")))?,
        );
    }
    let n = shape
        .iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .filter(|&n| n <= MAX_ELEMENTS)
        .ok_or_else(|| {
            bad(
                path,
                "shape",
                format!("shape {shape:?} has more than {MAX_ELEMENTS} elements"),
            )
        })?;
    let body = &bytes[end..];
    let need = n
        .checked_mul(dtype.size())
        .ok_or_else(|| bad(path, "shape", "shape overflows"))?;
    if body.len() != need {
        return Err(bad(
            path,
            "data",
            format!(
                "shape {shape:?} of {descr} needs {need} bytes of data, the file has {}",
                body.len()
            ),
        ));
    }
    let data = body
        .chunks_exact(dtype.size())
        .map(|c| dtype.decode(c))
        .collect();
    Ok(NpyArray { shape, data })
}

/// The text of `key`'s value in a Python dict literal (the `.npy` header).
fn dict_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let pat_single = format!("'{key}'");
    let pat_double = format!("\"{key}\"");
    let at = header
        .find(&pat_single)
        .map(|i| i + pat_single.len())
        .or_else(|| header.find(&pat_double).map(|i| i + pat_double.len()))?;
    let rest = header[at..].trim_start().strip_prefix(':')?;
    // The value ends at the first comma outside parentheses.
    let mut depth = 0i32;
    for (i, c) in rest.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' | '}' if depth == 0 => return Some(&rest[..i]),
            _ => {}
        }
    }
    None
}

/// Encodes an array as `.npy` version 1.0, little-endian `f8`, C order.
pub fn write_npy_bytes(a: &NpyArray) -> Vec<u8> {
    let shape = match a.shape.len() {
        1 => format!("({},)", a.shape[0]),
        _ => format!(
            "({})",
            a.shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape}, }}");
    // Pad so that the data starts on a 64-byte boundary, ending in '\n'.
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - unpadded % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 8 * a.data.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in &a.data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// Writes an array to a `.npy` file.
pub fn write_npy(path: &Path, a: &NpyArray) -> Result<()> {
    std::fs::write(path, write_npy_bytes(a)).map_err(|e| HilError::io("writing", path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("t.npy")
    }

    /// Bytes NumPy 1.26 writes for `np.save(f, np.array([[1.5, -2.0]], dtype='<f4'))`.
    fn numpy_f4() -> Vec<u8> {
        let mut header = "{'descr': '<f4', 'fortran_order': False, 'shape': (1, 2), }".to_string();
        header.push_str(&" ".repeat(128 - 10 - header.len() - 1));
        header.push('\n');
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        b.extend_from_slice(&(header.len() as u16).to_le_bytes());
        b.extend_from_slice(header.as_bytes());
        b.extend_from_slice(&1.5f32.to_le_bytes());
        b.extend_from_slice(&(-2.0f32).to_le_bytes());
        b
    }

    #[test]
    fn reads_f4_as_numpy_writes_it() {
        let a = read_npy_bytes(&numpy_f4(), p()).unwrap();
        assert_eq!(a.shape, vec![1, 2]);
        assert_eq!(a.data, vec![1.5, -2.0]);
    }

    #[test]
    fn header_is_aligned_and_round_trips_1d_and_3d() {
        for shape in [vec![5], vec![2, 3, 4], vec![0, 7]] {
            let n: usize = shape.iter().product();
            let a = NpyArray::new(shape, (0..n).map(|i| i as f64 * 0.25 - 1.0).collect()).unwrap();
            let b = write_npy_bytes(&a);
            let hl = u16::from_le_bytes([b[8], b[9]]) as usize;
            assert_eq!((10 + hl) % 64, 0);
            assert_eq!(b[10 + hl - 1], b'\n');
            assert_eq!(read_npy_bytes(&b, p()).unwrap(), a);
        }
    }

    #[test]
    fn rejects_bad_files_naming_the_field() {
        let err = |b: &[u8]| read_npy_bytes(b, p()).unwrap_err().to_string();
        assert!(err(b"hello world, not numpy").contains("magic"));
        let mut trunc = numpy_f4();
        trunc.pop();
        assert!(err(&trunc).contains("data"));
        let mut c16 = numpy_f4();
        let pos = c16.windows(3).position(|w| w == b"<f4").unwrap();
        c16[pos..pos + 3].copy_from_slice(b"<c8");
        assert!(err(&c16).contains("descr"));
    }

    #[test]
    fn huge_shapes_are_refused_before_allocating() {
        for shape in [
            "(134217729,)",
            "(99999999999, 99999999999)",
            "(18446744073709551615, 2)",
        ] {
            let mut b = numpy_f4();
            let at = b.windows(6).position(|w| w == b"(1, 2)").unwrap();
            b.splice(at..at + 6, shape.bytes());
            match read_npy_bytes(&b, p()).unwrap_err() {
                HilError::Data { path, field, .. } => {
                    assert_eq!((path.as_path(), field.as_str()), (p(), "shape"), "{shape}")
                }
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn fortran_order_is_rejected() {
        let mut b = numpy_f4();
        let pos = b.windows(5).position(|w| w == b"False").unwrap();
        b[pos..pos + 5].copy_from_slice(b"True ");
        let e = read_npy_bytes(&b, p()).unwrap_err().to_string();
        assert!(e.contains("fortran_order"), "{e}");
    }
}
