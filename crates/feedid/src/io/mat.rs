//! Reading recordings from MATLAB level-5 MAT-files (`save -v6` / `-v7`).
//!
//! **Why our own reader.** The `matfile` crate (0.5) was checked first: it
//! reads `DATA_EMPS.mat` correctly and did not panic on 300 single-byte
//! corruptions, but a *truncated* file is accepted silently (the variables
//! after the cut just disappear, so the user would get "no variable `qm`"
//! instead of "file truncated"), unsupported variables (struct, cell, char,
//! sparse, objects) are dropped without trace so they cannot be listed, it
//! does not recognise v7.3 files, and it contains an `unwrap` on a class
//! path. The subset we need is small, so this module implements it with
//! `flate2` for the compressed elements, bounds-checking every length read
//! from the file.
//!
//! **Format subset** (MathWorks, "MAT-File Format", level 5):
//!
//! - 128-byte header: descriptive text (bytes 0–115), subsystem offset
//!   (116–123), version (124–125) and the endianness indicator (126–127):
//!   `IM` → little-endian file, `MI` → big-endian.
//! - Data elements from byte 128: an 8-byte tag (type `u32`, byte count `u32`)
//!   followed by the data, padded to 8 bytes; or the *small data element*
//!   format (upper 16 bits of the first word = byte count ≤ 4, lower = type,
//!   data in the next 4 bytes).
//! - `miMATRIX` (14): sub-elements array flags (`miUINT32`; class in the low
//!   byte, bit 0x0800 complex, 0x0200 logical), dimensions (`miINT32`), name
//!   (`miINT8`), real part (any numeric storage type: MATLAB stores a double
//!   array as e.g. `miUINT8` when the values fit), imaginary part if complex.
//! - `miCOMPRESSED` (15): a zlib stream holding one `miMATRIX` element.
//!
//! Numeric classes double, single, int8…uint64 (and logical) are read as `f64`
//! (64-bit integers beyond 2⁵³ round). Struct, cell, char, sparse, object and
//! complex variables are listed by [`list_mat_variables`] as unsupported and
//! otherwise skipped. A channel must be a vector (n×1, 1×n) — scalars are
//! allowed by the reader but fail the length checks of a recording.
//!
//! Version 7.3 files (HDF5: header text `MATLAB 7.3`, HDF5 signature at byte 0
//! or 512) are recognised and refused. Truncated or corrupted files give
//! [`Error::MatFile`] with the reason; declared sizes are checked against the
//! bytes present (and, for compressed elements, against the maximum deflate
//! expansion) before anything is allocated.
//!
//! ```no_run
//! use feedid::io::{list_mat_variables, read_mat, ChannelRef, ReadOptions};
//! let path = std::path::Path::new("DATA_EMPS.mat");
//! for v in list_mat_variables(path)? {
//!     println!("{v}");
//! }
//! let opts = ReadOptions {
//!     time: Some(ChannelRef::Name("t".into())),
//!     command: Some(ChannelRef::Name("qg".into())),
//!     position: Some(ChannelRef::Name("qm".into())),
//!     ..ReadOptions::default()
//! };
//! let rec = read_mat(path, &opts)?;
//! # Ok::<(), feedid::Error>(())
//! ```

use std::fmt;
use std::io::Read;
use std::path::Path;

use serde::Serialize;

use crate::error::{Error, Result};
use crate::io::columns::{build_recording, failing_sample, in_file, short_list, Role};
use crate::io::options::{ChannelRef, ReadOptions};
use crate::io::source::read_file;
use crate::recording::Recording;

const HEADER_LEN: usize = 128;
const HDF5_SIGNATURE: &[u8; 8] = b"\x89HDF\r\n\x1a\n";
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;
/// Upper bound of the deflate expansion ratio (1032:1) plus slack.
const MAX_INFLATE_RATIO: usize = 1040;
/// Largest inflated element (2 GiB, 268 M doubles): a small compressed
/// "bomb" must not exhaust memory.
const MAX_INFLATED: usize = 1 << 31;
const V73_ADVICE: &str =
    "is a MATLAB v7.3 (HDF5) file, which is not supported; save it with -v7 or -v6 (save(f, '-v7'))";

/// What a MAT-file variable is.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct MatVariableInfo {
    /// Variable name.
    pub name: String,
    /// MATLAB class (`double`, `int32`, `logical`, `struct`, `complex double`, ...).
    pub class: String,
    /// Dimensions (e.g. `[24841, 1]`); empty for objects.
    pub dims: Vec<usize>,
    /// Whether it holds real numbers that can be read as a channel (if vector-shaped).
    pub supported: bool,
}

impl MatVariableInfo {
    /// Whether the dimensions describe a vector or a scalar (at most one dimension ≠ 1).
    pub fn is_vector(&self) -> bool {
        !self.dims.is_empty() && self.dims.iter().filter(|&&d| d != 1).count() <= 1
    }
}

impl fmt::Display for MatVariableInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({} {}", self.name, self.class, dims_text(&self.dims))?;
        if !self.supported {
            write!(f, ", unsupported")?;
        }
        write!(f, ")")
    }
}

fn dims_text(dims: &[usize]) -> String {
    if dims.is_empty() {
        return "?".into();
    }
    dims.iter()
        .map(|d| d.to_string())
        .collect::<Vec<_>>()
        .join("×")
}

/// A parsed variable; `real` holds the storage type and raw bytes of numeric ones.
struct RawVar {
    info: MatVariableInfo,
    real: Option<(u32, Vec<u8>)>,
    /// Whether `real` is big-endian.
    big: bool,
}

/// Read a recording from a MAT-file: variables by name from `opts`
/// (command and position required; time or `rate_hz` required).
pub fn read_mat(path: &Path, opts: &ReadOptions) -> Result<Recording> {
    let bytes = read_file(path)?;
    read_mat_from_bytes(&bytes, path, opts)
}

/// List the variables of a MAT-file, supported or not.
pub fn list_mat_variables(path: &Path) -> Result<Vec<MatVariableInfo>> {
    let bytes = read_file(path)?;
    list_mat_variables_from_bytes(&bytes, path)
}

/// Like [`list_mat_variables`] for bytes in memory; `source` names them in errors.
pub fn list_mat_variables_from_bytes(bytes: &[u8], source: &Path) -> Result<Vec<MatVariableInfo>> {
    Ok(parse_file(bytes, source)?
        .into_iter()
        .map(|v| v.info)
        .collect())
}

/// Like [`read_mat`] for bytes in memory; `source` names them in errors.
pub fn read_mat_from_bytes(bytes: &[u8], source: &Path, opts: &ReadOptions) -> Result<Recording> {
    opts.validate()?;
    let path = source;
    let vars = parse_file(bytes, path)?;
    let listing = || {
        if vars.is_empty() {
            "none".to_string()
        } else {
            short_list(vars.iter().map(|v| v.info.to_string()))
        }
    };
    let mat_err = |reason: String| Error::MatFile {
        path: path.to_path_buf(),
        reason,
    };
    let name_of = |r: &Option<ChannelRef>, what: &str| -> Result<String> {
        match r {
            Some(ChannelRef::Name(n)) => Ok(n.clone()),
            Some(ChannelRef::Index(i)) => Err(mat_err(format!(
                "variables are picked by name, not by index ({what}: {i}); available: {}",
                listing()
            ))),
            None => Err(mat_err(format!(
                "no variable chosen for the {what}; available: {}",
                listing()
            ))),
        }
    };
    let time_name = match (&opts.time, opts.rate_hz) {
        (None, Some(_)) => None,
        (t, _) => Some(name_of(t, "time (or give a sampling rate)")?),
    };
    let cmd_name = name_of(&opts.command, "command")?;
    let pos_name = name_of(&opts.position, "position")?;

    let get = |name: &str| -> Result<Vec<f64>> {
        let v = vars
            .iter()
            .find(|v| v.info.name == name)
            .ok_or_else(|| Error::MissingChannel {
                path: path.to_path_buf(),
                kind: "variable",
                name: name.to_string(),
                available: listing(),
            })?;
        vector_of(v).map_err(|reason| mat_err(format!("variable `{name}`: {reason}")))
    };
    let time = time_name.as_deref().map(get).transpose()?;
    let command = get(&cmd_name)?;
    let position = get(&pos_name)?;
    let n = command.len();

    let mut rec = build_recording(time, command, position, opts).map_err(|e| {
        let location = match failing_sample(&e) {
            Some((k, role)) => {
                let var = match role {
                    Some(Role::Time) => time_name.as_deref(),
                    Some(Role::Command) => Some(cmd_name.as_str()),
                    Some(Role::Position) => Some(pos_name.as_str()),
                    None => None,
                };
                match var {
                    Some(v) => format!("variable `{v}`, element {} (1-based)", k + 1),
                    None => format!("element {} (1-based)", k + 1),
                }
            }
            None => {
                let mut names: Vec<&str> = time_name.iter().map(|s| s.as_str()).collect();
                names.push(&cmd_name);
                names.push(&pos_name);
                format!("variables `{}`", names.join("`, `"))
            }
        };
        in_file(path, location, e)
    })?;

    // Other real vectors of the same length become extra channels (unscaled).
    for v in vars.iter().filter(|_| !opts.signals_only) {
        let name = v.info.name.as_str();
        let used = Some(name) == time_name.as_deref() || name == cmd_name || name == pos_name;
        if used || !v.info.supported || !v.info.is_vector() {
            continue;
        }
        if let Ok(values) = vector_of(v) {
            if values.len() == n && values.iter().all(|&x| crate::recording::is_usable(x)) {
                rec = rec.with_channel(name, values)?;
            }
        }
    }
    Ok(rec)
}

/// Whether `bytes` start like a MAT-file (level 5 header or v7.3/HDF5).
pub(crate) fn is_mat_bytes(bytes: &[u8]) -> bool {
    let v5 = bytes.len() >= HEADER_LEN
        && bytes.starts_with(b"MATLAB ")
        && matches!(bytes.get(126..128), Some(b"IM") | Some(b"MI"));
    v5 || is_hdf5(bytes)
}

fn is_hdf5(bytes: &[u8]) -> bool {
    bytes.starts_with(HDF5_SIGNATURE) || bytes.get(512..520) == Some(&HDF5_SIGNATURE[..])
}

/// Parse all variables of a MAT-file.
fn parse_file(bytes: &[u8], path: &Path) -> Result<Vec<RawVar>> {
    let err = |reason: String| Error::MatFile {
        path: path.to_path_buf(),
        reason,
    };
    let text = bytes.get(..116).unwrap_or(bytes);
    if is_hdf5(bytes) || text.windows(10).any(|w| w == b"MATLAB 7.3") {
        return Err(err(V73_ADVICE.to_string()));
    }
    if bytes.len() < HEADER_LEN {
        return Err(err(format!(
            "not a MATLAB v5 MAT-file: {} bytes, shorter than the 128-byte header",
            bytes.len()
        )));
    }
    let big = match bytes.get(126..128) {
        Some(b"IM") => false,
        Some(b"MI") => true,
        _ => {
            return Err(err(
                "not a MATLAB v5 MAT-file: no `IM`/`MI` endianness indicator at byte 126 \
                 (MATLAB v4 files are not supported)"
                    .to_string(),
            ))
        }
    };
    let mut vars = Vec::new();
    let mut pos = HEADER_LEN;
    while pos < bytes.len() {
        let rest = bytes.get(pos..).unwrap_or_default();
        if rest.len() < 8 {
            if rest.iter().all(|&b| b == 0) {
                break;
            }
            return Err(err(format!(
                "truncated: {} stray bytes at byte {pos}",
                rest.len()
            )));
        }
        let (dtype, body, consumed) = element(rest, big).map_err(|reason| {
            err(format!(
                "truncated or corrupted element at byte {pos}: {reason}"
            ))
        })?;
        let parsed = match dtype {
            MI_MATRIX => Some(parse_matrix(body, big)),
            MI_COMPRESSED => Some(inflate(body).and_then(|inner| {
                let (t, b, _) = element(&inner, big)?;
                if t != MI_MATRIX {
                    return Err(format!("compressed element holds type {t}, not a matrix"));
                }
                parse_matrix(b, big)
            })),
            _ => None, // other top-level elements carry no variables
        };
        if let Some(p) = parsed {
            vars.push(p.map_err(|reason| err(format!("variable at byte {pos}: {reason}")))?);
        }
        pos += consumed;
    }
    Ok(vars)
}

/// Read one data element at the start of `buf`: (type, data, bytes consumed incl. padding).
fn element(buf: &[u8], big: bool) -> std::result::Result<(u32, &[u8], usize), String> {
    let w0 = u32_at(buf, 0, big).ok_or("no room for a tag")?;
    if w0 >> 16 != 0 {
        // Small data element: byte count in the upper half, data in bytes 4..8.
        let n = (w0 >> 16) as usize;
        if n > 4 {
            return Err(format!("small element declares {n} bytes (max 4)"));
        }
        let data = buf.get(4..4 + n).ok_or("small element cut short")?;
        return Ok((w0 & 0xffff, data, 8));
    }
    let n = u32_at(buf, 4, big).ok_or("tag cut short")? as usize;
    let data = buf.get(8..).and_then(|b| b.get(..n)).ok_or_else(|| {
        format!(
            "declares {n} bytes but only {} remain (file truncated?)",
            buf.len().saturating_sub(8)
        )
    })?;
    // Padding to 8 bytes; top-level compressed elements are not padded.
    let consumed = if w0 == MI_COMPRESSED {
        8 + n
    } else {
        8 + n.div_ceil(8) * 8
    };
    Ok((w0, data, consumed.min(buf.len())))
}

fn u32_at(buf: &[u8], off: usize, big: bool) -> Option<u32> {
    let b: [u8; 4] = buf.get(off..off + 4)?.try_into().ok()?;
    Some(if big {
        u32::from_be_bytes(b)
    } else {
        u32::from_le_bytes(b)
    })
}

/// Inflate a zlib stream holding one element, bounded by the declared element size.
fn inflate(data: &[u8]) -> std::result::Result<Vec<u8>, String> {
    let mut dec = flate2::read::ZlibDecoder::new(data);
    let mut tag = [0u8; 8];
    dec.read_exact(&mut tag)
        .map_err(|e| format!("corrupted compressed data: {e}"))?;
    // Endianness of the size does not matter for the bound: take the smaller reading.
    let le = u32::from_le_bytes([tag[4], tag[5], tag[6], tag[7]]) as usize;
    let be = u32::from_be_bytes([tag[4], tag[5], tag[6], tag[7]]) as usize;
    let declared = le.min(be);
    if declared > MAX_INFLATED {
        return Err(format!(
            "compressed element declares {declared} bytes, more than the {MAX_INFLATED} supported"
        ));
    }
    let limit = data
        .len()
        .saturating_mul(MAX_INFLATE_RATIO)
        .saturating_add(64);
    if declared > limit {
        return Err(format!(
            "compressed element declares {declared} bytes, impossible for {} compressed bytes",
            data.len()
        ));
    }
    let mut out = tag.to_vec();
    dec.take(declared as u64)
        .read_to_end(&mut out)
        .map_err(|e| format!("corrupted or truncated compressed data: {e}"))?;
    Ok(out)
}

/// Parse the body of a `miMATRIX` element.
fn parse_matrix(body: &[u8], big: bool) -> std::result::Result<RawVar, String> {
    let mut pos = 0;
    let mut next = |what: &str| -> std::result::Result<(u32, &[u8]), String> {
        let rest = body.get(pos..).unwrap_or_default();
        let (t, d, used) = element(rest, big).map_err(|e| format!("{what}: {e}"))?;
        pos += used;
        Ok((t, d))
    };
    let (t, flags) = next("array flags")?;
    if t != 6 || flags.len() < 4 {
        return Err(format!(
            "array flags have type {t} and {} bytes",
            flags.len()
        ));
    }
    let f0 = u32_at(flags, 0, big).unwrap_or(0);
    let class = (f0 & 0xff) as u8;
    let complex = f0 & 0x0800 != 0;
    let logical = f0 & 0x0200 != 0;

    let mut dims = Vec::new();
    if class != 17 {
        let (t, d) = next("dimensions")?;
        if t != 5 || d.len() % 4 != 0 {
            return Err(format!("dimensions have type {t} and {} bytes", d.len()));
        }
        for k in 0..d.len() / 4 {
            let v = u32_at(d, 4 * k, big).unwrap_or(0) as i32;
            if v < 0 {
                return Err(format!("negative dimension {v}"));
            }
            dims.push(v as usize);
        }
    }
    let (_, name) = next("name")?;
    let name = String::from_utf8_lossy(name).into_owned();

    let class_name = match class {
        1 => "cell",
        2 => "struct",
        3 => "object",
        4 => "char",
        5 => "sparse",
        6 => "double",
        7 => "single",
        8 => "int8",
        9 if logical => "logical",
        9 => "uint8",
        10 => "int16",
        11 => "uint16",
        12 => "int32",
        13 => "uint32",
        14 => "int64",
        15 => "uint64",
        16 => "function handle",
        17 => "object (opaque)",
        _ => "unknown class",
    };
    let numeric = (6..=15).contains(&class);
    let supported = numeric && !complex;
    let class = if numeric && complex {
        format!("complex {class_name}")
    } else {
        class_name.to_string()
    };
    let real = if supported {
        let (t, d) = next("real part")?;
        Some((t, d.to_vec()))
    } else {
        None
    };
    Ok(RawVar {
        info: MatVariableInfo {
            name,
            class,
            dims,
            supported,
        },
        real,
        big,
    })
}

/// The values of a supported vector variable, as `f64`.
fn vector_of(v: &RawVar) -> std::result::Result<Vec<f64>, String> {
    let info = &v.info;
    let Some((dtype, bytes)) = v.real.as_ref().filter(|_| info.supported) else {
        return Err(format!("is {}, not a real numeric array", info.class));
    };
    if !info.is_vector() {
        return Err(format!(
            "is a {} matrix, not a vector (n×1 or 1×n)",
            dims_text(&info.dims)
        ));
    }
    let numel = info
        .dims
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .ok_or("dimensions overflow")?;
    let values = decode(*dtype, bytes, v.big)?;
    if values.len() != numel {
        return Err(format!(
            "holds {} values but its dimensions {} say {numel}",
            values.len(),
            dims_text(&info.dims)
        ));
    }
    Ok(values)
}

/// Decode numeric storage of type `dtype` to `f64`.
fn decode(dtype: u32, b: &[u8], big: bool) -> std::result::Result<Vec<f64>, String> {
    macro_rules! conv {
        ($t:ty, $n:expr) => {{
            let chunks = b.chunks_exact($n);
            if !chunks.remainder().is_empty() {
                return Err(format!("{} data bytes, not a multiple of {}", b.len(), $n));
            }
            chunks
                .map(|c| {
                    let mut a = [0u8; $n];
                    a.copy_from_slice(c);
                    if big {
                        <$t>::from_be_bytes(a) as f64
                    } else {
                        <$t>::from_le_bytes(a) as f64
                    }
                })
                .collect()
        }};
    }
    Ok(match dtype {
        1 => conv!(i8, 1),
        2 => conv!(u8, 1),
        3 => conv!(i16, 2),
        4 => conv!(u16, 2),
        5 => conv!(i32, 4),
        6 => conv!(u32, 4),
        7 => conv!(f32, 4),
        9 => conv!(f64, 8),
        12 => conv!(i64, 8),
        13 => conv!(u64, 8),
        t => return Err(format!("unsupported numeric storage type {t}")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fixture(name: &str) -> Vec<u8> {
        let p = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../tests/data")
            .join(name);
        std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
    }

    fn le_header() -> Vec<u8> {
        let mut h = b"MATLAB 5.0 MAT-file, test".to_vec();
        h.resize(116, b' ');
        h.extend_from_slice(&[0; 8]);
        h.extend_from_slice(&0x0100u16.to_le_bytes());
        h.extend_from_slice(b"IM");
        h
    }

    fn tag(t: u32, n: u32) -> Vec<u8> {
        let mut v = t.to_le_bytes().to_vec();
        v.extend_from_slice(&n.to_le_bytes());
        v
    }

    #[test]
    fn lists_supported_and_unsupported_variables() {
        let vars = list_mat_variables_from_bytes(&fixture("compressed_v7.mat"), Path::new("c.mat"))
            .unwrap();
        let get = |n: &str| vars.iter().find(|v| v.name == n).unwrap();
        assert_eq!(get("t").dims, vec![1, 40]);
        assert_eq!(get("qg").dims, vec![40, 1]);
        assert!(get("t").supported && get("t").is_vector() && get("kp").is_vector());
        assert!(get("M").supported && !get("M").is_vector());
        assert_eq!(get("label").class, "char");
        assert_eq!(get("z").class, "complex double");
        assert_eq!(get("s").class, "struct");
        assert_eq!(get("c").class, "cell");
        for n in ["label", "z", "s", "c"] {
            assert!(!get(n).supported, "{n}");
        }
        assert_eq!(get("c").to_string(), "c (cell 1×2, unsupported)");
    }

    #[test]
    fn decodes_every_storage_type_both_endiannesses() {
        let v = decode(5, &(-7i32).to_le_bytes(), false).unwrap();
        assert_eq!(v, vec![-7.0]);
        let v = decode(4, &[0x01, 0x02], true).unwrap();
        assert_eq!(v, vec![258.0]);
        let v = decode(7, &1.5f32.to_be_bytes(), true).unwrap();
        assert_eq!(v, vec![1.5]);
        let v = decode(13, &u64::MAX.to_le_bytes(), false).unwrap();
        assert_eq!(v, vec![u64::MAX as f64]);
        assert!(decode(9, &[0; 7], false).is_err());
        assert!(decode(99, &[0; 8], false).is_err());
    }

    #[test]
    fn huge_declared_sizes_are_errors_not_allocations() {
        let mut b = le_header();
        b.extend(tag(MI_MATRIX, 0xFFFF_FFF0));
        b.extend([0u8; 16]);
        let e = list_mat_variables_from_bytes(&b, Path::new("h.mat")).unwrap_err();
        assert!(e.to_string().contains("declares 4294967280 bytes"), "{e}");

        // A tiny zlib stream whose inner tag claims 1 GB: more than deflate can give.
        let bomb = |claim: u32| {
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
            std::io::Write::write_all(&mut z, &tag(MI_MATRIX, claim)).unwrap();
            let z = z.finish().unwrap();
            let mut b = le_header();
            b.extend(tag(MI_COMPRESSED, z.len() as u32));
            b.extend(&z);
            list_mat_variables_from_bytes(&b, Path::new("h.mat")).unwrap_err()
        };
        let e = bomb(0x4000_0040); // the same read in either byte order
        assert!(e.to_string().contains("impossible"), "{e}");
        // Beyond 2 GiB whatever the compressed size (a real bomb of 3 MB could
        // otherwise inflate to 3 GB).
        let e = bomb(0xFFFF_FFF0);
        assert!(
            e.to_string().contains("more than the 2147483648 supported"),
            "{e}"
        );
    }

    #[test]
    fn non_mat_and_v73_files_are_refused_with_reason() {
        let e = list_mat_variables_from_bytes(b"time,x\n1,2\n", Path::new("a.mat")).unwrap_err();
        assert!(e.to_string().contains("not a MATLAB v5 MAT-file"), "{e}");
        let e = list_mat_variables_from_bytes(&fixture("v73.mat"), Path::new("v.mat")).unwrap_err();
        assert!(
            e.to_string().contains("v7.3 (HDF5)") && e.to_string().contains("-v7"),
            "{e}"
        );
        assert!(is_mat_bytes(&fixture("v73.mat")) && is_mat_bytes(&fixture("double_v6.mat")));
    }

    #[test]
    fn every_truncation_and_byte_flip_gives_a_result_never_a_panic() {
        for name in [
            "compressed_v7.mat",
            "double_v6.mat",
            "big_endian.mat",
            "int_types.mat",
        ] {
            let data = fixture(name);
            for cut in 0..data.len() {
                let _ = list_mat_variables_from_bytes(&data[..cut], Path::new(name));
            }
            for pos in 0..data.len() {
                for flip in [0xFFu8, 0x80, 0x01] {
                    let mut d = data.clone();
                    d[pos] ^= flip;
                    if let Ok(vars) = parse_file(&d, Path::new(name)) {
                        for v in &vars {
                            let _ = vector_of(v);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn truncated_file_is_reported_as_truncated() {
        let e = list_mat_variables_from_bytes(&fixture("truncated.mat"), Path::new("t.mat"))
            .unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, Error::MatFile { .. }), "{msg}");
        assert!(msg.contains("truncated"), "{msg}");
    }
}
