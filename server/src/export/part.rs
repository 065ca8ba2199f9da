//! Part files: a contiguous run of an export's tiles (a range of its entries, which are in
//! ascending PMTiles tile id), as rendered by one shard, before [`super::merge`] lays them into
//! the archive.
//!
//! Layout: `TEXTILE-PART 1\n`, a header line of JSON ([`Header`]: the archive's identity and
//! metadata, the whole export's tile count, the shard and its range), then one record per tile in
//! order: zoom (u8), column and row (u32 LE), length (u32 LE), the bytes. A part is written as
//! `NAME.partial` beside its final name, with `NAME.partial.checkpoint` (JSON: tiles and bytes
//! complete, synced before it is renamed into place, so it is whole or absent); run again with
//! the same arguments, the shard cuts the partial file back to its checkpoint and goes on. When
//! every tile is in, the partial file is renamed to NAME and the checkpoint removed.

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::Entry;

/// First line of every part file.
const MAGIC: &str = "TEXTILE-PART 1";
/// Longest header line read.
const MAX_HEADER: u64 = 1 << 20;
/// Largest tile record accepted (a 512² RGB PNG is under 1 MiB).
const MAX_TILE: u32 = 64 << 20;

/// What a part belongs to and holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// The archive's identity: its metadata (texture, mode, parameters, world, zooms, bounds,
    /// encoding, engine and analysis versions). Parts merge only with parts of equal identity.
    pub archive: serde_json::Value,
    /// Tiles of the whole export.
    pub total: u64,
    /// This shard, `index` of `count` (0-based).
    pub shard: (u64, u64),
    /// The entries it holds: `[start, end)` of the export's, in ascending tile id.
    pub range: (u64, u64),
}

/// How far a partial part got.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// Tiles complete.
    pub tiles: u64,
    /// Bytes of the file they end at.
    pub bytes: u64,
}

/// The partial file of a part named `path`.
pub fn partial_path(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(".partial");
    PathBuf::from(s)
}

/// The checkpoint of a partial file.
pub fn checkpoint_path(path: &Path) -> PathBuf {
    let mut s = partial_path(path).into_os_string();
    s.push(".checkpoint");
    PathBuf::from(s)
}

fn io(p: &Path) -> impl Fn(std::io::Error) -> String + '_ {
    move |e| format!("{}: {e}", p.display())
}

/// The header bytes of a part.
fn header_bytes(h: &Header) -> Vec<u8> {
    format!("{MAGIC}\n{}\n", serde_json::to_string(h).unwrap_or_default()).into_bytes()
}

/// A part being written (or resumed).
pub struct Writer {
    path: PathBuf,
    file: BufWriter<File>,
    done: Checkpoint,
    target: u64,
}

impl Writer {
    /// Open part `path` for `header`: resumed from its checkpoint when a partial file of the same
    /// header has one, else started afresh. `Ok(None)`: `path` is already complete for it.
    pub fn open(path: &Path, header: &Header) -> Result<Option<Writer>, String> {
        if path.exists() {
            let existing = read_header(path)?;
            if &existing == header {
                return Ok(None);
            }
            return Err(format!(
                "{} exists and is a part of another export (or shard); remove it or write elsewhere",
                path.display()
            ));
        }
        let partial = partial_path(path);
        let head = header_bytes(header);
        let resume = read_checkpoint(path).filter(|c| {
            c.tiles <= header.range.1 - header.range.0
                && c.bytes >= head.len() as u64
                && read_header(&partial).is_ok_and(|h| &h == header)
                && std::fs::metadata(&partial).is_ok_and(|m| m.len() >= c.bytes)
        });
        let (file, done) = match resume {
            Some(c) => {
                let f = OpenOptions::new().write(true).open(&partial).map_err(io(&partial))?;
                f.set_len(c.bytes).map_err(io(&partial))?;
                (f, c)
            }
            None => {
                let mut f = File::create(&partial).map_err(io(&partial))?;
                f.write_all(&head).map_err(io(&partial))?;
                (f, Checkpoint { tiles: 0, bytes: head.len() as u64 })
            }
        };
        let mut file = BufWriter::with_capacity(1 << 20, file);
        file.seek(SeekFrom::Start(done.bytes)).map_err(io(&partial))?;
        Ok(Some(Writer { path: path.to_path_buf(), file, done, target: header.range.1 - header.range.0 }))
    }

    /// Tiles already in (from a checkpoint).
    pub fn done(&self) -> u64 {
        self.done.tiles
    }

    /// Append a tile.
    pub fn add(&mut self, e: &Entry, bytes: &[u8]) -> Result<(), String> {
        let len = u32::try_from(bytes.len()).map_err(|_| format!("tile {}/{}/{} is too large", e.z, e.x, e.y))?;
        let mut rec = Vec::with_capacity(13);
        rec.push(e.z);
        rec.extend_from_slice(&e.x.to_le_bytes());
        rec.extend_from_slice(&e.y.to_le_bytes());
        rec.extend_from_slice(&len.to_le_bytes());
        let partial = partial_path(&self.path);
        self.file.write_all(&rec).and_then(|()| self.file.write_all(bytes)).map_err(io(&partial))?;
        self.done.tiles += 1;
        self.done.bytes += rec.len() as u64 + bytes.len() as u64;
        Ok(())
    }

    /// Make what is written durable, then record it in the checkpoint (synced, renamed into place).
    pub fn checkpoint(&mut self) -> Result<(), String> {
        let partial = partial_path(&self.path);
        self.file.flush().map_err(io(&partial))?;
        self.file.get_ref().sync_data().map_err(io(&partial))?;
        let cp = checkpoint_path(&self.path);
        let tmp = textile_core::files::temp_path(&cp);
        let text = serde_json::to_vec(&self.done).unwrap_or_default();
        let written = File::create(&tmp).and_then(|mut f| f.write_all(&text).and_then(|()| f.sync_all()));
        written.and_then(|()| std::fs::rename(&tmp, &cp)).map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            format!("{}: {e}", cp.display())
        })
    }

    /// Complete the part: every tile must be in; renamed to its name, checkpoint removed.
    pub fn finish(mut self) -> Result<(), String> {
        if self.done.tiles != self.target {
            return Err(format!("{}: {} of {} tiles written", self.path.display(), self.done.tiles, self.target));
        }
        self.checkpoint()?;
        std::fs::rename(partial_path(&self.path), &self.path).map_err(io(&self.path))?;
        let _ = std::fs::remove_file(checkpoint_path(&self.path));
        Ok(())
    }
}

/// The checkpoint beside a part's partial file, if there is a readable one.
pub fn read_checkpoint(path: &Path) -> Option<Checkpoint> {
    serde_json::from_slice(&std::fs::read(checkpoint_path(path)).ok()?).ok()
}

/// Open a part file and read its header; the reader is left at its first record.
fn open_reader(path: &Path) -> Result<(Header, BufReader<File>), String> {
    let f = File::open(path).map_err(io(path))?;
    let mut r = BufReader::with_capacity(1 << 20, f);
    let not_part = || format!("{}: not a textile part file (from `textile export --shard`)", path.display());
    let mut magic = String::new();
    (&mut r).take(MAGIC.len() as u64 + 1).read_line(&mut magic).map_err(io(path))?;
    if magic.trim_end() != MAGIC {
        return Err(not_part());
    }
    let mut line = String::new();
    (&mut r).take(MAX_HEADER).read_line(&mut line).map_err(io(path))?;
    let h: Header = serde_json::from_str(line.trim_end()).map_err(|_| not_part())?;
    if h.range.0 > h.range.1 || h.range.1 > h.total || h.shard.0 >= h.shard.1 {
        return Err(format!("{}: a part header with impossible numbers", path.display()));
    }
    Ok((h, r))
}

/// A part's header.
pub fn read_header(path: &Path) -> Result<Header, String> {
    open_reader(path).map(|(h, _)| h)
}

/// One tile of a part: archive zoom, column, row, and its bytes.
pub type Tile = (u8, u32, u32, Vec<u8>);

/// A complete part, read record by record.
pub struct Reader {
    path: PathBuf,
    file: BufReader<File>,
    /// Its header.
    pub header: Header,
    read: u64,
}

impl Reader {
    /// Open a part for reading.
    pub fn open(path: &Path) -> Result<Reader, String> {
        let (header, file) = open_reader(path)?;
        Ok(Reader { path: path.to_path_buf(), file, header, read: 0 })
    }

    /// The next tile: `(zoom, column, row, bytes)`; `None` after the last. A part that ends
    /// early, or holds more than its range, is an error naming it.
    pub fn next_tile(&mut self) -> Result<Option<Tile>, String> {
        let want = self.header.range.1 - self.header.range.0;
        let mut rec = [0u8; 13];
        let got = read_full(&mut self.file, &mut rec).map_err(io(&self.path))?;
        if got == 0 && self.read == want {
            return Ok(None);
        }
        let truncated =
            || format!("{}: truncated after {} of {want} tiles (resume its shard)", self.path.display(), self.read);
        if got < rec.len() {
            return Err(truncated());
        }
        if self.read == want {
            return Err(format!("{}: holds more than its {want} tiles", self.path.display()));
        }
        let le = |i: usize| u32::from_le_bytes([rec[i], rec[i + 1], rec[i + 2], rec[i + 3]]);
        let (z, x, y, len) = (rec[0], le(1), le(5), le(9));
        if len > MAX_TILE {
            return Err(format!("{}: a tile record of {len} bytes: damaged", self.path.display()));
        }
        let mut bytes = vec![0u8; len as usize];
        if read_full(&mut self.file, &mut bytes).map_err(io(&self.path))? < bytes.len() {
            return Err(truncated());
        }
        self.read += 1;
        Ok(Some((z, x, y, bytes)))
    }
}

/// Read as much of `buf` as the file has; the count read.
fn read_full(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match r.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}
