//! The payload of a VTU `<DataArray>`: its numbers, from whitespace-separated text
//! (`ascii`) or from binary bytes (inline base64, appended raw or base64), uncompressed or
//! in zlib blocks behind a UInt32 or UInt64 header, in either byte order. Counts in a header
//! are checked against the bytes present before anything is allocated from them.

use super::Precision;
use super::checks::check_finite;
use crate::error::{Error, Result};
use base64::Engine as _;
use std::io::Read as _;
use std::path::Path;

/// VTK's number types.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "Int8" => Scalar::I8,
            "UInt8" => Scalar::U8,
            "Int16" => Scalar::I16,
            "UInt16" => Scalar::U16,
            "Int32" => Scalar::I32,
            "UInt32" => Scalar::U32,
            "Int64" => Scalar::I64,
            "UInt64" => Scalar::U64,
            "Float32" => Scalar::F32,
            "Float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }

    fn precision(self) -> Precision {
        if self == Scalar::F32 {
            Precision::F32
        } else {
            Precision::F64
        }
    }
}

/// The numbers of an array: integers exactly, floats widened to f64.
pub(super) enum Numbers {
    Int(Vec<i64>),
    Float(Vec<f64>),
}

impl Numbers {
    pub(super) fn into_f64(self) -> Vec<f64> {
        match self {
            Numbers::Int(v) => v.into_iter().map(|x| x as f64).collect(),
            Numbers::Float(v) => v,
        }
    }
}

/// The byte order of binary data.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum ByteOrder {
    Little,
    Big,
}

/// Bytes of one number in the file's byte order, as a little-endian array of `N`.
fn ordered<const N: usize>(b: &[u8], order: ByteOrder) -> [u8; N] {
    let mut a: [u8; N] = b.try_into().expect("a chunk of the type's size");
    if order == ByteOrder::Big {
        a.reverse();
    }
    a
}

/// Decode packed binary numbers of type `t` in byte order `order`.
fn from_bytes(bytes: &[u8], t: Scalar, order: ByteOrder) -> std::result::Result<Numbers, String> {
    let n = t.size();
    let chunks = bytes.chunks_exact(n);
    Ok(match t {
        Scalar::F32 => Numbers::Float(
            chunks
                .map(|c| f32::from_le_bytes(ordered(c, order)) as f64)
                .collect(),
        ),
        Scalar::F64 => Numbers::Float(
            chunks
                .map(|c| f64::from_le_bytes(ordered(c, order)))
                .collect(),
        ),
        Scalar::I8 => Numbers::Int(chunks.map(|c| c[0] as i8 as i64).collect()),
        Scalar::U8 => Numbers::Int(chunks.map(|c| c[0] as i64).collect()),
        Scalar::I16 => Numbers::Int(
            chunks
                .map(|c| i16::from_le_bytes(ordered(c, order)) as i64)
                .collect(),
        ),
        Scalar::U16 => Numbers::Int(
            chunks
                .map(|c| u16::from_le_bytes(ordered(c, order)) as i64)
                .collect(),
        ),
        Scalar::I32 => Numbers::Int(
            chunks
                .map(|c| i32::from_le_bytes(ordered(c, order)) as i64)
                .collect(),
        ),
        Scalar::U32 => Numbers::Int(
            chunks
                .map(|c| u32::from_le_bytes(ordered(c, order)) as i64)
                .collect(),
        ),
        Scalar::I64 => Numbers::Int(
            chunks
                .map(|c| i64::from_le_bytes(ordered(c, order)))
                .collect(),
        ),
        Scalar::U64 => Numbers::Int(
            chunks
                .map(|c| {
                    let v = u64::from_le_bytes(ordered(c, order));
                    i64::try_from(v).map_err(|_| format!("the value {v} is out of range"))
                })
                .collect::<std::result::Result<_, _>>()?,
        ),
    })
}

/// The sections of a piece that hold arrays.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub(super) enum Section {
    PointData,
    CellData,
    Points,
    Cells,
}

impl Section {
    pub(super) fn name(self) -> &'static str {
        match self {
            Section::PointData => "PointData",
            Section::CellData => "CellData",
            Section::Points => "Points",
            Section::Cells => "Cells",
        }
    }
}

/// Where an array's numbers are.
#[derive(Clone, Debug)]
pub(super) enum Layout {
    /// Whitespace-separated text.
    Ascii,
    /// Inline base64 of a header and the (compressed) bytes.
    Binary,
    /// At this offset of the appended data.
    Appended(usize),
}

/// A `<DataArray>` as the XML gives it.
#[derive(Clone, Debug)]
pub(super) struct ArrayInfo {
    /// The section of the piece it is in.
    pub(super) section: Section,
    /// Its `Name`.
    pub(super) name: String,
    /// Its `type` as written (`Float64`, ...).
    pub(super) vtk_type: String,
    /// Its `NumberOfComponents`.
    pub(super) components: usize,
    /// Where its numbers are.
    pub(super) layout: Layout,
    /// The element's text (ascii numbers or inline base64).
    pub(super) text: String,
}

impl ArrayInfo {
    /// The error field of the array: `PointData/displacement`, `Points`, `Cells/types`.
    pub(super) fn field(&self) -> String {
        if self.section == Section::Points {
            "Points".into()
        } else {
            format!("{}/{}", self.section.name(), self.name)
        }
    }
}

/// The data after `<AppendedData encoding=...>_`.
pub(super) struct Appended<'a> {
    /// `encoding="base64"` (else raw bytes).
    pub(super) base64: bool,
    /// The bytes after `_`, up to `</AppendedData>`.
    pub(super) data: &'a [u8],
}

/// How a .vtu stores its binary arrays (the attributes of `<VTKFile>`).
#[derive(Clone, Copy)]
pub(super) struct BinaryFormat {
    /// The byte order of numbers and header words.
    pub(super) order: ByteOrder,
    /// UInt64 header words (else UInt32).
    pub(super) header64: bool,
    /// zlib blocks (`vtkZLibDataCompressor`).
    pub(super) compressed: bool,
}

/// A lenient base64 engine: padding optional, trailing bits allowed (VTK pads each stream).
const BASE64: base64::engine::GeneralPurpose = base64::engine::GeneralPurpose::new(
    &base64::alphabet::STANDARD,
    base64::engine::GeneralPurposeConfig::new()
        .with_decode_allow_trailing_bits(true)
        .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
);

/// Characters of the base64 of `bytes` bytes.
fn base64_chars(bytes: usize) -> Option<usize> {
    bytes.div_ceil(3).checked_mul(4)
}

/// Where the bytes of a binary array come from.
enum Source<'a> {
    /// Raw bytes (appended raw).
    Raw(&'a [u8]),
    /// base64 characters (inline binary, appended base64), whitespace removed.
    Base64(&'a [u8]),
}

impl Source<'_> {
    /// `n` bytes from byte `start` of the header stream (raw: of the data).
    fn header_bytes(&self, start: usize, n: usize) -> std::result::Result<Vec<u8>, String> {
        let end = start.checked_add(n).ok_or("a header past any file")?;
        match self {
            Source::Raw(d) => d.get(start..end).map(<[u8]>::to_vec).ok_or_else(|| {
                format!(
                    "the file ends inside the array's header ({} bytes from its offset, {end} needed)",
                    d.len()
                )
            }),
            Source::Base64(t) => {
                let chars = base64_chars(end).ok_or("a header past any file")?;
                let text = t.get(..chars).ok_or_else(|| {
                    format!(
                        "the base64 text ends inside the array's header ({} characters, {chars} needed)",
                        t.len()
                    )
                })?;
                let bytes = BASE64
                    .decode(text)
                    .map_err(|e| format!("the header is not valid base64 ({e})"))?;
                bytes
                    .get(start..end)
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| "the header is shorter than announced".into())
            }
        }
    }

    /// The `n` payload bytes after a header of `header` bytes.
    fn payload(&self, header: usize, n: usize) -> std::result::Result<Vec<u8>, String> {
        let end = header.checked_add(n).ok_or("a payload past any file")?;
        match self {
            Source::Raw(d) => d.get(header..end).map(<[u8]>::to_vec).ok_or_else(|| {
                format!(
                    "the file holds {} bytes from the array's offset, the header announces {end}",
                    d.len()
                )
            }),
            Source::Base64(t) => {
                let header_chars = base64_chars(header).ok_or("a header past any file")?;
                // VTK encodes a compressed array's header and its blocks as two base64
                // streams, the header padded; meshio and VTK encode an uncompressed one as
                // one stream. A header of a multiple of 3 bytes reads the same either way.
                let separate = header.is_multiple_of(3)
                    || t.get(..header_chars).is_some_and(|h| h.ends_with(b"="));
                let (from, chars, skip) = if separate {
                    (header_chars, base64_chars(n), 0)
                } else {
                    (0, base64_chars(end), header)
                };
                let to = chars
                    .and_then(|c| c.checked_add(from))
                    .ok_or("a payload past any file")?;
                let text = t.get(from..to).ok_or_else(|| {
                    format!(
                        "the base64 text holds {} characters, the header announces {n} bytes ({to} characters)",
                        t.len()
                    )
                })?;
                let bytes = BASE64
                    .decode(text)
                    .map_err(|e| format!("the data is not valid base64 ({e})"))?;
                bytes
                    .get(skip..skip.saturating_add(n))
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| "the data is shorter than announced".into())
            }
        }
    }
}

impl BinaryFormat {
    /// The header words `start..start + n` of a binary array.
    fn words(
        &self,
        source: &Source,
        start: usize,
        n: usize,
    ) -> std::result::Result<Vec<u64>, String> {
        let word = self.word();
        let b = source.header_bytes(start * word, n * word)?;
        Ok(b.chunks_exact(word)
            .map(|c| {
                if word == 8 {
                    u64::from_le_bytes(ordered(c, self.order))
                } else {
                    u32::from_le_bytes(ordered(c, self.order)) as u64
                }
            })
            .collect())
    }

    /// Bytes of a header word.
    fn word(&self) -> usize {
        if self.header64 { 8 } else { 4 }
    }

    /// The bytes of a binary array, decompressed: `expected` bytes if given (the header is
    /// checked against it), else as many as its header announces.
    fn binary(
        &self,
        source: Source,
        expected: Option<usize>,
    ) -> std::result::Result<Vec<u8>, String> {
        let word = self.word();
        let need = |n: u64| match expected {
            Some(e) if n != e as u64 => Err(format!(
                "the header announces {n} bytes, the array's tuples and components need {e}"
            )),
            _ => usize::try_from(n).map_err(|_| format!("the header announces {n} bytes")),
        };
        if !self.compressed {
            let n = need(self.words(&source, 0, 1)?[0])?;
            // Checked against the data present before anything is allocated.
            return source.payload(word, n);
        }
        let blocks = self.words(&source, 0, 1)?[0];
        // The header is 3 + blocks words: refuse a count the data cannot hold before
        // reading (or allocating) it.
        let available = match &source {
            Source::Raw(d) => d.len() as u64,
            Source::Base64(t) => t.len() as u64 / 4 * 3,
        };
        if blocks.saturating_add(3).saturating_mul(word as u64) > available {
            return Err(format!(
                "the header announces {blocks} compressed blocks, more than the {available} bytes of data can hold"
            ));
        }
        let blocks = blocks as usize;
        let h = self.words(&source, 0, 3 + blocks)?;
        let (block_size, last_size) = (h[1], h[2]);
        // VTK writes 0 as the last block's size when it is full.
        let total = match blocks {
            0 => 0,
            b if last_size == 0 => (b as u64).saturating_mul(block_size),
            b => ((b - 1) as u64)
                .saturating_mul(block_size)
                .saturating_add(last_size),
        };
        if blocks > 0 && last_size > block_size {
            return Err(format!(
                "the header announces blocks of {block_size} bytes, the last of {last_size}"
            ));
        }
        let total = need(total).map_err(|m| {
            format!("{m} ({blocks} blocks of {block_size} bytes, the last {last_size})")
        })?;
        let compressed: u64 = h[3..].iter().fold(0u64, |s, &c| s.saturating_add(c));
        if compressed > available {
            return Err(format!(
                "the header announces {compressed} compressed bytes, the file holds {available}"
            ));
        }
        let data = source.payload(word * (3 + blocks), compressed as usize)?;
        // zlib expands at most about 1000 times: the capacity follows the bytes present.
        let mut out = Vec::with_capacity(total.min(4 * data.len() + 64));
        let mut at = 0usize;
        for (b, &size) in h[3..].iter().enumerate() {
            let size = size as usize;
            let want = if b + 1 == blocks && last_size != 0 {
                last_size
            } else {
                block_size
            };
            let before = out.len();
            flate2::read::ZlibDecoder::new(&data[at..at + size])
                .take(want.saturating_add(1))
                .read_to_end(&mut out)
                .map_err(|e| format!("block {b} is not a valid zlib stream ({e})"))?;
            if (out.len() - before) as u64 != want {
                return Err(format!(
                    "block {b} decompresses to {} bytes, the header announces {want}",
                    out.len() - before
                ));
            }
            at += size;
        }
        Ok(out)
    }

    /// Decode `a` as `tuples` tuples of its components, or as many as it holds (`None`).
    pub(super) fn numbers(
        &self,
        a: &ArrayInfo,
        appended: Option<&Appended>,
        tuples: Option<usize>,
        path: &Path,
    ) -> Result<(Numbers, Precision)> {
        let t = Scalar::parse(&a.vtk_type).ok_or_else(|| {
            a.refuse(path, format!(
                "type \"{}\" is not a VTK number type (Int8 ... UInt64, Float32, Float64): write the array as numbers",
                a.vtk_type
            ))
        })?;
        if a.components == 0 {
            return Err(a.refuse(path,
                "NumberOfComponents=\"0\": an array has at least one component per tuple; write the file again".into(),
            ));
        }
        let count = match tuples {
            None => None,
            Some(n) => Some(n.checked_mul(a.components).ok_or_else(|| {
                a.refuse(path, format!(
                    "{n} tuples of {} components overflow: the counts are corrupt; write the file again",
                    a.components
                ))
            })?),
        };
        let numbers = match &a.layout {
            Layout::Ascii => a.ascii(t, tuples, count, path)?,
            _ => self.binary_array(a, t, appended, tuples, count, path)?,
        };
        if let Numbers::Float(v) = &numbers {
            check_finite(v, a.components, path, &a.field(), a.counted().0)?;
        }
        Ok((numbers, t.precision()))
    }

    /// The numbers of a binary array (inline or appended), `count` values if given.
    fn binary_array(
        &self,
        a: &ArrayInfo,
        t: Scalar,
        appended: Option<&Appended>,
        tuples: Option<usize>,
        count: Option<usize>,
        path: &Path,
    ) -> Result<Numbers> {
        let expected = match count {
            None => None,
            Some(c) => Some(
                c.checked_mul(t.size())
                    .ok_or_else(|| a.wrong_count(path, tuples, count, 0))?,
            ),
        };
        let text: Vec<u8>;
        let source = match a.layout {
            Layout::Binary => {
                text = a
                    .text
                    .bytes()
                    .filter(|b| !b.is_ascii_whitespace())
                    .collect();
                Source::Base64(&text)
            }
            Layout::Appended(offset) => a.appended_source(offset, appended, path)?,
            Layout::Ascii => unreachable!("an ascii array is read as text"),
        };
        let bytes = self.binary(source, expected).map_err(|m| {
            let counts = match tuples {
                Some(n) => format!(
                    " ({} = {n} tuples of {} components of {})",
                    a.counted().1,
                    a.components,
                    a.vtk_type
                ),
                None => String::new(),
            };
            a.refuse(path, format!(
                "{m}{counts}; the binary data does not match the array (a truncated or edited file, or a wrong header_type): write the file again"
            ))
        })?;
        let tuple_bytes = t.size().saturating_mul(a.components);
        if !bytes.len().is_multiple_of(tuple_bytes) {
            return Err(a.wrong_count(path, tuples, count, bytes.len() / t.size()));
        }
        from_bytes(&bytes, t, self.order)
            .map_err(|m| a.refuse(path, format!("{m}: write the array again")))
    }
}

impl ArrayInfo {
    /// Bad input at this array.
    fn refuse(&self, path: &Path, message: String) -> Error {
        Error::input(path, self.field(), message)
    }

    /// What one tuple is and the count attribute that gives their number:
    /// (`point`, `NumberOfPoints`) or (`cell`, `NumberOfCells`).
    fn counted(&self) -> (&'static str, &'static str) {
        match self.section {
            Section::PointData | Section::Points => ("point", "NumberOfPoints"),
            _ => ("cell", "NumberOfCells"),
        }
    }

    /// The refusal of `found` values where `tuples` tuples (`count` values) are expected,
    /// or where the values make no whole number of tuples.
    fn wrong_count(
        &self,
        path: &Path,
        tuples: Option<usize>,
        count: Option<usize>,
        found: usize,
    ) -> Error {
        let (tuple, count_name) = self.counted();
        self.refuse(path, match (tuples, count) {
            (Some(n), Some(c)) => format!(
                "{found} values, but {count_name} = {n} tuples of {} components need {c}: write one tuple per {tuple} (a field of another mesh, or of the boundary?)",
                self.components
            ),
            _ => format!(
                "{found} values are not a whole number of tuples of {} components: write the file again",
                self.components
            ),
        })
    }

    /// The numbers of an ascii array, `count` values if given.
    fn ascii(
        &self,
        t: Scalar,
        tuples: Option<usize>,
        count: Option<usize>,
        path: &Path,
    ) -> Result<Numbers> {
        let found = self.text.split_ascii_whitespace().count();
        if count.is_some_and(|c| c != found) || !found.is_multiple_of(self.components) {
            return Err(self.wrong_count(path, tuples, count, found));
        }
        ascii_numbers(&self.text, t).map_err(|(i, s)| {
            self.refuse(
                path,
                format!(
                    "value {i} '{s}' is not a{} {}: write the array again",
                    if t.is_float() {
                        ""
                    } else {
                        "n integer of type"
                    },
                    self.vtk_type
                ),
            )
        })
    }

    /// The bytes of an appended array, from its `offset` on.
    fn appended_source<'a>(
        &self,
        offset: usize,
        appended: Option<&Appended<'a>>,
        path: &Path,
    ) -> Result<Source<'a>> {
        let ap = appended.ok_or_else(|| {
            self.refuse(
                path,
                "format=\"appended\", but the file has no <AppendedData>: write the file again"
                    .into(),
            )
        })?;
        let data = ap.data.get(offset..).ok_or_else(|| {
            self.refuse(path, format!(
                "offset {offset} is past the end of the appended data ({} bytes): write the file again",
                ap.data.len()
            ))
        })?;
        Ok(if ap.base64 {
            Source::Base64(data)
        } else {
            Source::Raw(data)
        })
    }
}

/// Parse whitespace-separated numbers of type `t`; a bad one as (index, text).
fn ascii_numbers(text: &str, t: Scalar) -> std::result::Result<Numbers, (usize, String)> {
    let tokens = text.split_ascii_whitespace().enumerate();
    let bad = |i: usize, s: &str| (i, s.to_string());
    Ok(match t {
        Scalar::F32 => Numbers::Float(
            tokens
                .map(|(i, s)| s.parse::<f32>().map(f64::from).map_err(|_| bad(i, s)))
                .collect::<std::result::Result<_, _>>()?,
        ),
        Scalar::F64 => Numbers::Float(
            tokens
                .map(|(i, s)| s.parse::<f64>().map_err(|_| bad(i, s)))
                .collect::<std::result::Result<_, _>>()?,
        ),
        _ => Numbers::Int(
            tokens
                .map(|(i, s)| s.parse::<i64>().map_err(|_| bad(i, s)))
                .collect::<std::result::Result<_, _>>()?,
        ),
    })
}
