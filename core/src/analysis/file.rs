//! The stored analysis file (design note §1.2e): a fixed header (magic, format version, declared
//! length), a JSON descriptive header, a binary payload and a trailing BLAKE3 checksum. Written
//! to a temporary file and renamed, so a reader never sees half a file. Every way a file can be
//! wrong is a typed [`AnalysisFileProblem`].

use std::fs;
use std::path::Path;

use crate::analysis::features::{RUNTIME_DIMS, TAPS5};
use crate::analysis::{Analysis, AnalysisHeader, Candidate, CorrectionLevel, FIRST_CORRECTED_LEVEL};
use crate::error::{AnalysisFileProblem, CoreError, Result};

/// First bytes of every analysis file.
pub const MAGIC: &[u8; 8] = b"TXTLANA\0";
/// Binary layout version.
pub const FORMAT_VERSION: u32 = 1;
const FIXED: usize = 8 + 4 + 8 + 4; // magic, version, total length, json length
const CHECKSUM: usize = 32;

impl Analysis {
    /// Serialise to the file format.
    pub fn to_bytes(&self) -> Vec<u8> {
        let json = serde_json::to_vec(&self.header).unwrap_or_default();
        let mut b = Vec::with_capacity(FIXED + json.len() + self.exemplar.len() * 64);
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        b.extend_from_slice(&0u64.to_le_bytes()); // total length, patched below
        b.extend_from_slice(&(json.len() as u32).to_le_bytes());
        b.extend_from_slice(&json);
        for p in &self.exemplar {
            b.extend_from_slice(p);
        }
        for level in &self.stack {
            for p in level {
                for v in p {
                    b.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        for lv in &self.corrected {
            for v in &lv.proj {
                b.extend_from_slice(&v.to_le_bytes());
            }
            for pair in &lv.cands {
                for c in pair {
                    b.extend_from_slice(&c.coord.to_le_bytes());
                    for f in c.feat {
                        b.extend_from_slice(&f.to_le_bytes());
                    }
                }
            }
        }
        let total = (b.len() + CHECKSUM) as u64;
        b[12..20].copy_from_slice(&total.to_le_bytes());
        let sum = blake3::hash(&b);
        b.extend_from_slice(sum.as_bytes());
        b
    }

    /// Parse the file format. Problems are reported with an empty path; [`Analysis::load`]
    /// fills in the file name.
    pub fn from_bytes(bytes: &[u8]) -> Result<Analysis> {
        parse(bytes).map_err(|problem| CoreError::AnalysisFile { path: Default::default(), problem })
    }

    /// Hash of the serialised file (hex), identifying these exact bytes.
    pub fn file_hash(&self) -> String {
        blake3::hash(&self.to_bytes()).to_hex()[..16].to_string()
    }

    /// Write atomically: a temporary file beside `path`, fsync, rename.
    pub fn save(&self, path: &Path) -> Result<()> {
        write_atomically(path, &self.to_bytes())
    }

    /// Read and validate an analysis file.
    pub fn load(path: &Path) -> Result<Analysis> {
        let bytes = fs::read(path).map_err(|source| CoreError::Io { path: path.to_path_buf(), source })?;
        parse(&bytes).map_err(|problem| CoreError::AnalysisFile { path: path.to_path_buf(), problem })
    }

    /// Read only the descriptive header of an analysis file: its magic, version and JSON
    /// header, not the payload (so neither its length nor its checksum is checked: loading
    /// does that).
    pub fn read_header(path: &Path) -> Result<AnalysisHeader> {
        use std::io::Read;
        let bad = |problem| CoreError::AnalysisFile { path: path.to_path_buf(), problem };
        let io = |source| CoreError::Io { path: path.to_path_buf(), source };
        let mut f = fs::File::open(path).map_err(io)?;
        let mut fixed = [0u8; FIXED];
        let got = f.by_ref().take(FIXED as u64).read(&mut fixed).map_err(io)?;
        if got < 8 || &fixed[..8] != MAGIC {
            return Err(bad(AnalysisFileProblem::BadMagic));
        }
        if got < FIXED {
            return Err(bad(AnalysisFileProblem::Truncated { actual: got as u64, declared: FIXED as u64 }));
        }
        let version = u32::from_le_bytes([fixed[8], fixed[9], fixed[10], fixed[11]]);
        if version != FORMAT_VERSION {
            return Err(bad(AnalysisFileProblem::UnsupportedVersion { found: version, expected: FORMAT_VERSION }));
        }
        let json_len = u32::from_le_bytes([fixed[20], fixed[21], fixed[22], fixed[23]]) as u64;
        let mut json = Vec::new();
        f.take(json_len).read_to_end(&mut json).map_err(io)?;
        if (json.len() as u64) < json_len {
            return Err(bad(AnalysisFileProblem::Truncated {
                actual: (FIXED + json.len()) as u64,
                declared: FIXED as u64 + json_len,
            }));
        }
        serde_json::from_slice(&json).map_err(|e| bad(AnalysisFileProblem::Corrupt(format!("header: {e}"))))
    }
}

/// Write `bytes` to `path` atomically ([`crate::files::write_atomic`]: a temporary file beside
/// it, fsync, rename), creating its folder first, so a reader never sees half a file.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |source| CoreError::Io { path: path.to_path_buf(), source };
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    fs::create_dir_all(dir).map_err(io)?;
    crate::files::write_atomic(path, bytes).map_err(io)
}

struct Reader<'a> {
    b: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], AnalysisFileProblem> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.b.len());
        let end = end.ok_or_else(|| AnalysisFileProblem::Corrupt("payload shorter than its header says".into()))?;
        let s = &self.b[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    fn u16(&mut self) -> Result<u16, AnalysisFileProblem> {
        let s = self.take(2)?;
        Ok(u16::from_le_bytes([s[0], s[1]]))
    }
    fn u32(&mut self) -> Result<u32, AnalysisFileProblem> {
        let s = self.take(4)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
}

pub(crate) fn parse(bytes: &[u8]) -> Result<Analysis, AnalysisFileProblem> {
    if bytes.len() < MAGIC.len() || &bytes[..8] != MAGIC {
        return Err(AnalysisFileProblem::BadMagic);
    }
    if bytes.len() < FIXED {
        return Err(AnalysisFileProblem::Truncated { actual: bytes.len() as u64, declared: FIXED as u64 });
    }
    let mut r = Reader { b: bytes, pos: 8 };
    let version = r.u32()?;
    if version != FORMAT_VERSION {
        return Err(AnalysisFileProblem::UnsupportedVersion { found: version, expected: FORMAT_VERSION });
    }
    let total = u64::from_le_bytes(r.take(8)?.try_into().unwrap_or([0; 8]));
    if (bytes.len() as u64) < total {
        return Err(AnalysisFileProblem::Truncated { actual: bytes.len() as u64, declared: total });
    }
    if bytes.len() as u64 != total || total < (FIXED + CHECKSUM) as u64 {
        return Err(AnalysisFileProblem::Corrupt(format!("length {} differs from declared {total}", bytes.len())));
    }
    let (body, sum) = bytes.split_at(bytes.len() - CHECKSUM);
    if blake3::hash(body).as_bytes() != sum {
        return Err(AnalysisFileProblem::ChecksumMismatch);
    }
    let mut r = Reader { b: body, pos: 20 };
    let json_len = r.u32()? as usize;
    let mut header: AnalysisHeader =
        serde_json::from_slice(r.take(json_len)?).map_err(|e| AnalysisFileProblem::Corrupt(format!("header: {e}")))?;
    // Written when exemplars were square: the height is the width.
    if header.height == 0 {
        header.height = header.width;
    }
    if header.preparation.height == 0 {
        header.preparation.height = header.preparation.width;
    }
    if header.algorithm_version != crate::analysis::ALGORITHM_VERSION {
        return Err(AnalysisFileProblem::UnsupportedVersion {
            found: header.algorithm_version,
            expected: crate::analysis::ALGORITHM_VERSION,
        });
    }
    let (w, h) = (header.width as usize, header.height as usize);
    let sides = crate::exemplar::MIN_INPUT_SIDE as usize..=crate::exemplar::MAX_SIDE as usize;
    if !sides.contains(&w)
        || !sides.contains(&h)
        || header.levels != crate::geom::levels_for(header.width, header.height)
    {
        return Err(AnalysisFileProblem::Corrupt(format!("invalid exemplar size {w}x{h}")));
    }
    let n = w * h;
    let exemplar: Vec<[u8; 3]> = r.take(n * 3)?.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let mut stack = Vec::new();
    for _ in 0..=header.levels {
        let mut lv = Vec::with_capacity(n);
        for _ in 0..n {
            lv.push([r.u16()?, r.u16()?, r.u16()?]);
        }
        stack.push(lv);
    }
    let mut corrected = Vec::new();
    for _ in FIRST_CORRECTED_LEVEL..=header.levels {
        let proj: Vec<i16> =
            r.take(TAPS5 * 3 * RUNTIME_DIMS * 2)?.chunks_exact(2).map(|c| i16::from_le_bytes([c[0], c[1]])).collect();
        let mut cands = Vec::with_capacity(n);
        for _ in 0..n {
            let mut pair = [Candidate::default(); 2];
            for c in pair.iter_mut() {
                c.coord = r.u32()?;
                if (c.coord & 0xFFFF) as usize >= w || (c.coord >> 16) as usize >= h {
                    return Err(AnalysisFileProblem::Corrupt("candidate outside the exemplar".into()));
                }
                for f in c.feat.iter_mut() {
                    *f = r.u16()? as i16;
                }
            }
            cands.push(pair);
        }
        corrected.push(CorrectionLevel { proj, cands });
    }
    if r.pos != body.len() {
        return Err(AnalysisFileProblem::Corrupt("trailing bytes after payload".into()));
    }
    Ok(Analysis::from_parts(header, exemplar, stack, corrected))
}
