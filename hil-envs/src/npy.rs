//! A small, exact reader and writer for NumPy `.npy` files (format versions
//! 1.0, 2.0 and 3.0), so that the Python research stack can produce and read
//! the dataset's arrays.
//!
//! Supported element types on read: little-endian `f8`, `f4`, `i8`, `i4`,
//! `u1` and `b1` (all returned as `f64`), in any spelling `numpy.dtype`
//! accepts (`float64`, `d`, ...); C order only. The header is read as
//! `numpy.load` reads it (checked against numpy 2.4): a dict literal with
//! exactly the keys `descr`, `fortran_order` and `shape` (a repeated key
//! keeps its last value; any other key is refused). This small reader is
//! kept rather than the `npyz` crate because the limits below (size checked
//! before any allocation, errors naming the header field) are its point. Files are always
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
    /// The element type of a `descr`, in every spelling `numpy.dtype`
    /// accepts for it: a byte-order mark (`<`, or `=` / `|` / none for
    /// the native order, little-endian on every platform hil builds for)
    /// and a type code (`f8`, `float64`, `d`, `float`, ...). Big-endian
    /// (`>`) is not supported.
    fn parse(descr: &str) -> Option<Self> {
        let code = match descr.as_bytes().first()? {
            b'<' | b'=' | b'|' => &descr[1..],
            _ => descr,
        };
        Some(match code {
            "f8" | "float64" | "d" | "float" | "double" => Self::F8,
            "f4" | "float32" | "f" | "single" => Self::F4,
            "i8" | "int64" | "q" | "longlong" => Self::I8,
            "i4" | "int32" | "i" | "intc" => Self::I4,
            "u1" | "uint8" | "B" | "ubyte" => Self::U1,
            "b1" | "bool" | "?" => Self::B1,
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
    let header = Header::parse(header).map_err(|why| bad(path, "header", why))?;
    let descr = header.descr.as_str();
    let dtype = Dtype::parse(descr).ok_or_else(|| {
        bad(
            path,
            "descr",
            format!("unsupported element type `{descr}` (use <f8, <f4, <i8, <i4, u1 or b1)"),
        )
    })?;
    if header.fortran_order {
        return Err(bad(
            path,
            "fortran_order",
            "Fortran-ordered arrays are not supported; save with np.ascontiguousarray",
        ));
    }
    let shape = header.shape;
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

/// The `.npy` header: a Python dict literal with exactly the keys `descr`,
/// `fortran_order` and `shape`, read as numpy reads it (a literal parse,
/// where a key given twice keeps its last value, and any other key is
/// refused, as numpy's "Header does not contain the correct keys").
#[derive(Debug, PartialEq)]
struct Header {
    descr: String,
    fortran_order: bool,
    shape: Vec<usize>,
}

/// A value in the header's dict literal.
#[derive(Debug)]
enum Literal {
    Str(String),
    Bool(bool),
    Tuple(Vec<usize>),
    /// Any other value (kept as text for the error).
    Other(String),
}

impl std::fmt::Display for Literal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Str(s) => write!(f, "'{s}'"),
            Self::Bool(b) => f.write_str(if *b { "True" } else { "False" }),
            Self::Tuple(t) => write!(f, "{t:?}"),
            Self::Other(text) => f.write_str(&hil_core::error::echo(text)),
        }
    }
}

impl Header {
    fn parse(text: &str) -> std::result::Result<Self, String> {
        let mut p = LiteralParser { rest: text };
        let mut descr = None;
        let mut fortran_order = None;
        let mut shape = None;
        p.expect('{')?;
        loop {
            if p.eat('}') {
                break;
            }
            let key = match p.value()? {
                Literal::Str(k) => k,
                other => return Err(format!("a key is not a string: {other}")),
            };
            p.expect(':')?;
            let value = p.value()?;
            match key.as_str() {
                "descr" => descr = Some(value),
                "fortran_order" => fortran_order = Some(value),
                "shape" => shape = Some(value),
                other => {
                    return Err(format!(
                        "unexpected key `{other}` (the header has exactly `descr`, `fortran_order` and `shape`)"
                    ));
                }
            }
            if !p.eat(',') {
                p.expect('}')?;
                break;
            }
        }
        if !p.rest.trim().is_empty() {
            return Err(format!("text after the dict: `{}`", p.rest.trim()));
        }
        let missing = |k: &str| format!("no `{k}` key");
        Ok(Self {
            descr: match descr.ok_or_else(|| missing("descr"))? {
                Literal::Str(d) => d,
                other => return Err(format!("`descr` {other} is not a string")),
            },
            fortran_order: match fortran_order.ok_or_else(|| missing("fortran_order"))? {
                Literal::Bool(b) => b,
                other => return Err(format!("`fortran_order` {other} is not True or False")),
            },
            shape: match shape.ok_or_else(|| missing("shape"))? {
                Literal::Tuple(s) => s,
                other => return Err(format!("`shape` {other} is not a tuple of sizes")),
            },
        })
    }
}

/// Reads the few Python literals a `.npy` header holds.
struct LiteralParser<'a> {
    rest: &'a str,
}

impl LiteralParser<'_> {
    fn eat(&mut self, c: char) -> bool {
        self.rest = self.rest.trim_start();
        match self.rest.strip_prefix(c) {
            Some(r) => {
                self.rest = r;
                true
            }
            None => false,
        }
    }

    fn expect(&mut self, c: char) -> std::result::Result<(), String> {
        if self.eat(c) {
            Ok(())
        } else {
            Err(format!(
                "expected `{c}` at `{}`",
                hil_core::error::echo(self.rest)
            ))
        }
    }

    fn value(&mut self) -> std::result::Result<Literal, String> {
        self.rest = self.rest.trim_start();
        let quote = self.rest.chars().next().ok_or("the header ends early")?;
        if quote == '\'' || quote == '"' {
            let body = &self.rest[1..];
            let end = body.find(quote).ok_or("a string is not closed")?;
            let s = &body[..end];
            if s.contains('\\') {
                return Err(format!("escapes are not supported in `{s}`"));
            }
            self.rest = &body[end + 1..];
            return Ok(Literal::Str(s.to_string()));
        }
        if self.eat('(') {
            let mut dims = Vec::new();
            loop {
                if self.eat(')') {
                    return Ok(Literal::Tuple(dims));
                }
                let digits = self.rest.len()
                    - self
                        .rest
                        .trim_start_matches(|c: char| c.is_ascii_digit())
                        .len();
                let (n, rest) = self.rest.split_at(digits);
                dims.push(n.parse::<usize>().map_err(|_| {
                    format!("`{}` is not a size", hil_core::error::echo(self.rest))
                })?);
                self.rest = rest;
                if !self.eat(',') {
                    self.expect(')')?;
                    return Ok(Literal::Tuple(dims));
                }
            }
        }
        // A bare word or number: up to the next separator.
        let end = self.rest.find([',', '}', ':']).unwrap_or(self.rest.len());
        let (word, rest) = self.rest.split_at(end);
        self.rest = rest;
        Ok(match word.trim() {
            "True" => Literal::Bool(true),
            "False" => Literal::Bool(false),
            other => Literal::Other(other.to_string()),
        })
    }
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

    /// A file of two `f8` values, 1.5 and -2.0, under `header`.
    fn with_header(header: &str) -> Vec<u8> {
        let mut h = header.to_string();
        h.push_str(&" ".repeat((64 - (10 + h.len() + 1) % 64) % 64));
        h.push('\n');
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        b.extend_from_slice(&(h.len() as u16).to_le_bytes());
        b.extend_from_slice(h.as_bytes());
        for v in [1.5f64, -2.0] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b
    }

    /// What `numpy.load` (2.4) does with each header, checked with numpy:
    /// other spellings of the element type and a repeated key (the last
    /// one counts) load; an extra key, a non-bool order or a list shape
    /// are refused.
    #[test]
    fn headers_are_read_as_numpy_reads_them() {
        for h in [
            "{'descr': 'float64', 'fortran_order': False, 'shape': (2,), }",
            "{'descr': 'f8', 'fortran_order': False, 'shape': (2,)}",
            "{'descr': '=d', 'fortran_order': False, 'shape': (2,)}",
            "{\"descr\": \"<f8\", 'fortran_order': False, 'shape': (2,)}",
            "{'descr': '<f8', 'fortran_order': False, 'shape': (3,), 'shape': (2,), }",
        ] {
            let a = read_npy_bytes(&with_header(h), p()).unwrap_or_else(|e| panic!("{h}: {e}"));
            assert_eq!((a.shape, a.data), (vec![2], vec![1.5, -2.0]), "{h}");
        }
        for h in [
            "{'descr': '<f8', 'fortran_order': False, 'shape': (2,), 'extra': 1, }",
            "{'descr': '<f8', 'fortran_order': 0, 'shape': (2,)}",
            "{'descr': '<f8', 'fortran_order': False, 'shape': [2]}",
            "{'descr': '<f8', 'fortran_order': False}",
            "{'descr': '<f8', 'fortran_order': False, 'shape': (2,)} x",
        ] {
            match read_npy_bytes(&with_header(h), p()) {
                Err(HilError::Data { field, .. }) => assert_eq!(field, "header", "{h}"),
                other => panic!("{h}: {other:?}"),
            }
        }
        let big = with_header("{'descr': '>f8', 'fortran_order': False, 'shape': (2,)}");
        assert!(
            matches!(read_npy_bytes(&big, p()), Err(HilError::Data { field, .. }) if field == "descr")
        );
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
