//! Part files: a contiguous run of an export's tiles (a range of its entries, which are in
//! ascending PMTiles tile id), as rendered by one shard, before [`super::merge`] lays them into
//! the archive. A part proves itself: merge refuses any record it cannot verify.
//!
//! Layout (version 2):
//! - `TEXTILE-PART 2\n`;
//! - a header line of JSON ([`Header`]: the archive's identity and metadata, the whole export's
//!   tile count and [`Layout`], the shard and its range);
//! - `crc32 XXXXXXXX\n`, the CRC-32 of that JSON line's bytes;
//! - one record per tile of the range, in order: zoom (u8), column and row (u32 LE), length
//!   (u32 LE), the CRC-32 (u32 LE) of those 13 bytes followed by the tile's, then the tile's
//!   bytes. A reader checks every checksum, and that each record is the next tile of the
//!   layout from the part's range on.
//!
//! A part is written as `NAME.partial` beside its final name, with `NAME.partial.checkpoint`
//! (JSON: version, the header's CRC, tiles and bytes complete; synced before it is renamed into
//! place, so it is whole or absent); run again with the same arguments, the shard cuts the
//! partial file back to its checkpoint and goes on. When every tile is in, the partial file is
//! renamed to NAME and the checkpoint removed. The writer holds an exclusive `flock` on the
//! partial file throughout, so a second process on the same shard is refused at once, naming
//! the first, and touches nothing. Version-1 parts (no checksums) are refused with a message
//! that says to run their shard again.

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::layout::Tiles;
use super::{Entry, Layout};

/// First line of every part file of this version.
const MAGIC: &str = "TEXTILE-PART 2";
/// First line of the previous version's part files.
const MAGIC_V1: &str = "TEXTILE-PART 1";
/// The part format's version, as checkpoints record it.
const VERSION: u32 = 2;
/// Longest header line read.
const MAX_HEADER: u64 = 1 << 20;
/// Largest tile record accepted (a 512² RGB PNG is under 1 MiB).
const MAX_TILE: u32 = 64 << 20;
/// Bytes of a record before its tile: zoom, column, row, length, CRC.
const RECORD_HEAD: usize = 17;

/// What a part belongs to and holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// The archive's identity: its metadata (texture, mode, parameters, world, zooms, bounds,
    /// encoding, engine and analysis versions). Parts merge only with parts of equal identity.
    pub archive: serde_json::Value,
    /// Tiles of the whole export.
    pub total: u64,
    /// The whole export's tiles, in the order they are written.
    pub layout: Layout,
    /// This shard, `index` of `count` (0-based).
    pub shard: (u64, u64),
    /// The entries it holds: `[start, end)` of the export's, in ascending tile id.
    pub range: (u64, u64),
}

impl Header {
    /// The command line's words for redoing this part.
    fn rerun(&self) -> String {
        format!("run shard {}/{} again", self.shard.0, self.shard.1)
    }

    /// The JSON line (without its newline) and its CRC.
    fn line(&self) -> (String, u32) {
        let json = serde_json::to_string(self).unwrap_or_default();
        let crc = crc32fast::hash(json.as_bytes());
        (json, crc)
    }

    /// The header bytes of a part.
    fn bytes(&self) -> Vec<u8> {
        let (json, crc) = self.line();
        format!("{MAGIC}\n{json}\ncrc32 {crc:08x}\n").into_bytes()
    }
}

/// How far a partial part got.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// The part format's version (absent, so 0, in version 1's checkpoints).
    #[serde(default)]
    pub version: u32,
    /// The CRC of the header it continues: a checkpoint applies to that header only.
    #[serde(default)]
    pub header: u32,
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

/// The pid holding an exclusive `flock` on `f`, from the kernel's table of locks.
fn lock_holder(f: &File) -> Option<String> {
    use std::os::unix::fs::MetadataExt;
    let m = f.metadata().ok()?;
    let want = format!("{:02x}:{:02x}:{}", libc::major(m.dev()), libc::minor(m.dev()), m.ino());
    let table = std::fs::read_to_string("/proc/locks").ok()?;
    table.lines().find_map(|line| {
        let w: Vec<&str> = line.split_whitespace().collect();
        let at = w.iter().position(|t| *t == "FLOCK")?;
        (w.get(at + 4) == Some(&want.as_str())).then(|| w.get(at + 3).map(|p| p.to_string())).flatten()
    })
}

/// A part being written (or resumed); the partial file stays locked while it lives.
pub struct Writer {
    path: PathBuf,
    file: BufWriter<File>,
    done: Checkpoint,
    target: u64,
}

/// Whether `path` is already the complete part for `header`; an error if it is another file.
fn complete(path: &Path, header: &Header) -> Result<bool, String> {
    if !path.exists() {
        return Ok(false);
    }
    let existing = match open_reader(path) {
        Ok((h, _)) => h,
        Err(PartError::Version1) => {
            return Err(format!(
                "{}: a version-1 part from an older textile (no checksums): remove it and {}",
                path.display(),
                header.rerun()
            ))
        }
        // Running the shard again would meet the same file: it must go first.
        Err(PartError::Other(e)) => {
            return Err(format!("{e} (the file is in the way of this shard: remove it and {})", header.rerun()))
        }
    };
    if &existing == header {
        return Ok(true);
    }
    Err(format!("{} exists and is a part of another export (or shard); remove it or write elsewhere", path.display()))
}

impl Writer {
    /// Open part `path` for `header`: resumed from its checkpoint when a partial file of the same
    /// header has one, else started afresh. `Ok(None)`: `path` is already complete for it. A
    /// partial file that another process is writing is refused at once, naming it.
    pub fn open(path: &Path, header: &Header) -> Result<Option<Writer>, String> {
        if complete(path, header)? {
            return Ok(None);
        }
        let partial = partial_path(path);
        let existed = partial.exists();
        let mut f = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&partial)
            .map_err(io(&partial))?;
        match f.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                let who = lock_holder(&f).map(|p| format!("process {p}")).unwrap_or_else(|| "another process".into());
                return Err(format!(
                    "{} is being written by {who}, another run of this shard: wait for it to finish, or stop it",
                    partial.display()
                ));
            }
            Err(std::fs::TryLockError::Error(e)) => return Err(format!("{}: cannot lock it: {e}", partial.display())),
        }
        // Another run may have completed the part between the check above and the lock.
        if complete(path, header)? {
            if !existed {
                let _ = std::fs::remove_file(&partial);
            }
            return Ok(None);
        }
        let (head, crc) = (header.bytes(), header.line().1);
        // What the partial file holds: this version's header (maybe this one's), version 1's
        // (not resumable), or nothing readable.
        let (old, partial_header) = match open_reader(&partial) {
            Ok((h, _)) => (false, Some(h)),
            Err(PartError::Version1) => (true, None),
            Err(PartError::Other(_)) => (false, None),
        };
        let cp = read_checkpoint(path);
        if old || cp.is_some_and(|c| c.version != VERSION) {
            return Err(format!(
                "{}: a partial part of an older textile (version 1), which cannot be resumed: remove it and {}, then {}",
                partial.display(),
                checkpoint_path(path).display(),
                header.rerun()
            ));
        }
        let len = f.metadata().map_err(io(&partial))?.len();
        let resume = cp.filter(|c| {
            c.header == crc
                && c.tiles <= header.range.1 - header.range.0
                && c.bytes >= head.len() as u64
                && len >= c.bytes
                && partial_header.as_ref() == Some(header)
        });
        let done = match resume {
            Some(c) => {
                f.set_len(c.bytes).map_err(io(&partial))?;
                c
            }
            None => {
                // A checkpoint of anything else must not apply to what is written now.
                let _ = std::fs::remove_file(checkpoint_path(path));
                f.set_len(0).and_then(|()| f.rewind()).and_then(|()| f.write_all(&head)).map_err(io(&partial))?;
                Checkpoint { version: VERSION, header: crc, tiles: 0, bytes: head.len() as u64 }
            }
        };
        let mut file = BufWriter::with_capacity(1 << 20, f);
        file.seek(SeekFrom::Start(done.bytes)).map_err(io(&partial))?;
        Ok(Some(Writer { path: path.to_path_buf(), file, done, target: header.range.1 - header.range.0 }))
    }

    /// Tiles already in (from a checkpoint).
    pub fn done(&self) -> u64 {
        self.done.tiles
    }

    /// Append a tile.
    pub fn add(&mut self, e: &Entry, bytes: &[u8]) -> Result<(), String> {
        let len = u32::try_from(bytes.len())
            .ok()
            .filter(|l| *l <= MAX_TILE)
            .ok_or_else(|| format!("tile {}/{}/{} is too large", e.z, e.x, e.y))?;
        let mut rec = Vec::with_capacity(RECORD_HEAD);
        rec.push(e.z);
        rec.extend_from_slice(&e.x.to_le_bytes());
        rec.extend_from_slice(&e.y.to_le_bytes());
        rec.extend_from_slice(&len.to_le_bytes());
        rec.extend_from_slice(&record_crc(&rec, bytes).to_le_bytes());
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
        let text = serde_json::to_vec(&self.done).unwrap_or_default();
        textile_core::files::write_atomic(&cp, &text).map_err(io(&cp))
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

/// The CRC-32 of a record: its first 13 bytes (zoom, column, row, length), then the tile's.
fn record_crc(head: &[u8], bytes: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(&head[..13]);
    h.update(bytes);
    h.finalize()
}

/// The checkpoint beside a part's partial file, if there is a readable one.
pub fn read_checkpoint(path: &Path) -> Option<Checkpoint> {
    serde_json::from_slice(&std::fs::read(checkpoint_path(path)).ok()?).ok()
}

/// Why a part's header could not be read.
enum PartError {
    /// A part of format version 1.
    Version1,
    /// Anything else, said.
    Other(String),
}

impl From<String> for PartError {
    fn from(s: String) -> Self {
        PartError::Other(s)
    }
}

impl PartError {
    fn say(self, path: &Path) -> String {
        match self {
            PartError::Version1 => format!(
                "{}: a version-1 part from an older textile, without checksums: run its shard again with this \
                 textile (remove the old part first)",
                path.display()
            ),
            PartError::Other(s) => s,
        }
    }
}

/// Read one line of at most `max` bytes.
fn line(r: &mut BufReader<File>, max: u64, path: &Path) -> Result<String, String> {
    let mut s = String::new();
    r.take(max).read_line(&mut s).map_err(|_| format!("{}: not a textile part file", path.display()))?;
    Ok(s)
}

/// Open a part file and check its header; the reader is left at its first record.
fn open_reader(path: &Path) -> Result<(Header, BufReader<File>), PartError> {
    let f = File::open(path).map_err(io(path))?;
    let mut r = BufReader::with_capacity(1 << 20, f);
    let not_part = || format!("{}: not a textile part file (from `textile export --shard`)", path.display());
    let magic = line(&mut r, MAGIC.len() as u64 + 1, path)?;
    match magic.trim_end() {
        MAGIC => {}
        MAGIC_V1 => return Err(PartError::Version1),
        _ => return Err(not_part().into()),
    }
    let damaged = |what: &str| format!("{}: its header is damaged ({what}): run its shard again", path.display());
    let json = line(&mut r, MAX_HEADER, path)?;
    let sum = line(&mut r, 16, path)?;
    let json = json.strip_suffix('\n').ok_or_else(|| damaged("cut short"))?;
    let crc = sum.trim_end().strip_prefix("crc32 ").and_then(|h| u32::from_str_radix(h, 16).ok());
    if crc != Some(crc32fast::hash(json.as_bytes())) {
        return Err(damaged("checksum mismatch").into());
    }
    let h: Header = serde_json::from_str(json).map_err(|_| not_part())?;
    let zooms = super::meta_zooms(&h.archive).ok();
    if h.range.0 > h.range.1
        || h.range.1 > h.total
        || h.shard.0 >= h.shard.1
        || !h.layout.is_valid()
        || h.layout.count() != h.total
        || zooms != Some(h.layout.zooms)
    {
        return Err(format!("{}: a part header with impossible numbers", path.display()).into());
    }
    Ok((h, r))
}

/// A part's header, checked.
pub fn read_header(path: &Path) -> Result<Header, String> {
    open_reader(path).map(|(h, _)| h).map_err(|e| e.say(path))
}

/// One tile of a part: archive zoom, column, row, and its bytes.
pub type Tile = (u8, u32, u32, Vec<u8>);

/// A complete part, read record by record, every record checked.
pub struct Reader {
    path: PathBuf,
    file: BufReader<File>,
    /// Its header.
    pub header: Header,
    read: u64,
    /// The tiles its records must be, in order.
    expected: Tiles,
}

impl Reader {
    /// Open a part for reading.
    pub fn open(path: &Path) -> Result<Reader, String> {
        let (header, file) = open_reader(path).map_err(|e| e.say(path))?;
        let expected = header.layout.tiles_from(header.range.0);
        Ok(Reader { path: path.to_path_buf(), file, header, read: 0, expected })
    }

    /// The next tile, proved: its checksum holds and it is the next tile of the part's range;
    /// `None` after the last. A record that fails, a part that ends early or holds more than
    /// its range is an error naming the part, the record and the tile.
    pub fn next_tile(&mut self) -> Result<Option<Tile>, String> {
        let want = self.header.range.1 - self.header.range.0;
        let mut rec = [0u8; RECORD_HEAD];
        let got = read_full(&mut self.file, &mut rec).map_err(io(&self.path))?;
        if self.read == want {
            if got == 0 {
                return Ok(None);
            }
            return Err(format!(
                "{}: holds more than its {want} tiles: damaged; {}",
                self.path.display(),
                self.header.rerun()
            ));
        }
        let n = self.read + 1;
        let (ez, ex, ey) = self.expected.next().unwrap_or((0, 0, 0));
        let at = format!("{}: record {n} of {want}, tile {ez}/{ex}/{ey}", self.path.display());
        let rerun = self.header.rerun();
        if got == 0 {
            return Err(format!("{at}: missing, with the {} after it: the part is truncated; {rerun}", want - n));
        }
        if got < rec.len() {
            return Err(format!("{at}: cut short: the part is truncated; {rerun}"));
        }
        let le = |i: usize| u32::from_le_bytes([rec[i], rec[i + 1], rec[i + 2], rec[i + 3]]);
        let (z, x, y, len, crc) = (rec[0], le(1), le(5), le(9), le(13));
        if len > MAX_TILE {
            return Err(format!("{at}: a length of {len} bytes: the part is damaged; {rerun}"));
        }
        let mut bytes = vec![0u8; len as usize];
        if read_full(&mut self.file, &mut bytes).map_err(io(&self.path))? < bytes.len() {
            return Err(format!("{at}: cut short: the part is truncated; {rerun}"));
        }
        if record_crc(&rec, &bytes) != crc {
            return Err(format!("{at}: checksum mismatch: the part is damaged; {rerun}"));
        }
        if (z, x, y) != (ez, ex, ey) {
            return Err(format!("{at}: holds tile {z}/{x}/{y} instead: the part is damaged or out of order; {rerun}"));
        }
        self.read = n;
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
