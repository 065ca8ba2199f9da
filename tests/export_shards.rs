//! Sharded export through the real binary: a `--world 16` export rendered by 1, 3 and 8 shard
//! processes at once (`--shard I/N --workers 1`) and merged is byte-identical to one process's
//! archive, in PMTiles and MBTiles, and the independent readers read every tile back; a shard
//! killed with SIGKILL at three moments resumes and the merge is still identical; merge names a
//! missing shard, a doubled one, and parts of another world; bad `--shard` values are refused;
//! the Kubernetes manifests validate against the Kubernetes schema.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use common::{binary, check_archive as check, reader_available, shared_data_dir, skip, Server};

fn textile(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(binary()).args(args).output().expect("run textile");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The arguments of an export of gravel's 16-tile world (341 tiles, archive zooms 0..4).
fn export_args(world: &str, out: &Path) -> Vec<String> {
    let data = shared_data_dir();
    ["export", "--texture", "gravel", "--world", world, "--data-dir", data.to_str().unwrap(), "-o"]
        .iter()
        .map(|s| s.to_string())
        .chain([out.to_str().unwrap().to_string()])
        .collect()
}

fn run_ok(args: &[String]) -> String {
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, out, err) = textile(&a);
    assert_eq!(code, 0, "{args:?}: {err}");
    out + &err
}

fn shard(world: &str, i: usize, n: usize, dir: &Path) -> (Vec<String>, PathBuf) {
    let part = dir.join(format!("w{world}-{i}of{n}.part"));
    let mut args = export_args(world, &part);
    args.extend(["--shard".into(), format!("{i}/{n}"), "--workers".into(), "1".into()]);
    (args, part)
}

/// Run the N shards of an export as N processes at once; their part files.
fn shards(world: &str, n: usize, dir: &Path) -> Vec<PathBuf> {
    let started: Vec<(Child, PathBuf, Vec<String>)> = (0..n)
        .map(|i| {
            let (args, part) = shard(world, i, n, dir);
            let child =
                Command::new(binary()).args(&args).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
            (child, part, args)
        })
        .collect();
    started
        .into_iter()
        .map(|(c, part, args)| {
            let out = c.wait_with_output().unwrap();
            assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
            part
        })
        .collect()
}

fn merge(parts: &[PathBuf], out: &Path) -> (i32, String) {
    let mut args: Vec<&str> = vec!["merge"];
    args.extend(parts.iter().map(|p| p.to_str().unwrap()));
    args.extend(["-o", out.to_str().unwrap()]);
    let (code, stdout, err) = textile(&args);
    (code, stdout + &err)
}

/// Names in `dir` of partial parts, checkpoints and temporary files (hidden names).
fn stray_files(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("partial") || n.starts_with('.'))
        .collect()
}

fn merged(parts: &[PathBuf], out: &Path) -> Vec<u8> {
    let (code, text) = merge(parts, out);
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("MB/s"), "{text}");
    std::fs::read(out).unwrap()
}

#[test]
fn shards_merge_into_the_single_process_archive_and_resume_after_sigkill() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (single_pm, single_mb) = (d.join("single.pmtiles"), d.join("single.mbtiles"));
    run_ok(&export_args("16", &single_pm));
    run_ok(&export_args("16", &single_mb));
    let (want_pm, want_mb) = (std::fs::read(&single_pm).unwrap(), std::fs::read(&single_mb).unwrap());

    let one = shards("16", 1, d);
    assert_eq!(merged(&one, &d.join("m1.pmtiles")), want_pm, "1 shard");
    assert_eq!(merged(&one, &d.join("m1.mbtiles")), want_mb, "1 shard, MBTiles");
    let three = shards("16", 3, d);
    assert_eq!(merged(&three, &d.join("m3.pmtiles")), want_pm, "3 shards, PMTiles");
    assert_eq!(merged(&three, &d.join("m3.mbtiles")), want_mb, "3 shards, MBTiles");
    let mut eight = shards("16", 8, d);
    eight.reverse(); // any order
    assert_eq!(merged(&eight, &d.join("m8.pmtiles")), want_pm, "8 shards");
    assert_eq!(merged(&eight, &d.join("m8.mbtiles")), want_mb, "8 shards, MBTiles");
    // Nothing but the parts and archives is left: no partial files, no checkpoints.
    let stray = stray_files(d);
    assert!(stray.is_empty(), "{stray:?}");

    // Shard 1 of 3 again, killed with SIGKILL at three moments, then run to the end.
    let again = d.join("again");
    std::fs::create_dir(&again).unwrap();
    let (args, part) = shard("16", 1, 3, &again);
    let checkpoint = again.join("w16-1of3.part.partial.checkpoint");
    let tiles_done = || -> u64 {
        let text = std::fs::read_to_string(&checkpoint).unwrap_or_default();
        serde_json::from_str::<serde_json::Value>(&text).ok().and_then(|v| v["tiles"].as_u64()).unwrap_or(0)
    };
    let mut resumed = 0;
    for extra_ms in [0u64, 170, 430] {
        let before = tiles_done();
        let mut c = Command::new(binary()).args(&args).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
        // Killed a while after its next checkpoint: mid-chunk, at a different point each time.
        for _ in 0..3000 {
            if tiles_done() > before || c.try_wait().unwrap().is_some() {
                break;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        std::thread::sleep(Duration::from_millis(extra_ms));
        let _ = c.kill();
        let out = c.wait_with_output().unwrap();
        resumed += usize::from(String::from_utf8_lossy(&out.stderr).contains("resuming after"));
        // Killed at any moment (also between its last rename and its exit), a shard leaves
        // under its name nothing or the whole part.
        if part.exists() {
            assert_eq!(std::fs::read(&part).unwrap(), std::fs::read(&three[1]).unwrap(), "a whole part or none");
        }
    }
    assert!(resumed >= 2, "the shard resumed from its checkpoint after each kill");
    run_ok(&args);
    let mixed = vec![three[0].clone(), part.clone(), three[2].clone()];
    assert_eq!(merged(&mixed, &d.join("resumed.pmtiles")), want_pm, "resumed after SIGKILL");
    // Run once more with the same arguments: nothing to do.
    assert!(run_ok(&args).contains("already complete"));
    // A damaged part in the way is named, with what to do (not "run it again" in a loop).
    let whole = std::fs::read(&part).unwrap();
    let mut damaged = whole.clone();
    damaged[30] ^= 0x02;
    std::fs::write(&part, &damaged).unwrap();
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, err) = textile(&a);
    assert_ne!(code, 0);
    assert!(err.contains("header is damaged") && err.contains("remove it and run shard 1/3 again"), "{err}");
    std::fs::write(&part, &whole).unwrap();

    // Bad merges name the problem.
    let (code, text) = merge(&[three[0].clone(), three[2].clone()], &d.join("gap.pmtiles"));
    assert_ne!(code, 0);
    assert!(text.contains("are in no part") && text.contains("a shard is missing"), "{text}");
    let (code, text) =
        merge(&[three[0].clone(), three[1].clone(), three[2].clone(), eight[0].clone()], &d.join("x.pmtiles"));
    assert_ne!(code, 0);
    assert!(text.contains("both hold tiles"), "{text}");
    let other = shards("8", 1, d);
    let (code, text) = merge(&[three[0].clone(), three[1].clone(), other[0].clone()], &d.join("y.pmtiles"));
    assert_ne!(code, 0);
    assert!(text.contains("a part of another export") && text.contains("world 8 against 16"), "{text}");
    for bad in ["3/2", "0/0", "1", "2/2", "a/b"] {
        let mut a = export_args("16", &d.join("bad.part"));
        a.extend(["--shard".into(), bad.into()]);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let (code, _, err) = textile(&a);
        assert_ne!(code, 0, "--shard {bad}");
        assert!(err.contains("must be I/N with 0 ≤ I < N"), "--shard {bad}: {err}");
    }
    for p in ["gap.pmtiles", "x.pmtiles", "y.pmtiles", "bad.part"] {
        assert!(!d.join(p).exists(), "{p} was not written");
    }

    if !reader_available() {
        return skip("shards_merge_into_the_single_process_archive (readers)", "python3 with the pmtiles package");
    }
    // Every tile of every merged archive, read back by the independent readers, is the server's.
    let s = Server::builder().start();
    for n in [1, 3, 8] {
        for ext in ["pmtiles", "mbtiles"] {
            check(&d.join(format!("m{n}.{ext}")), &s, 341);
        }
    }
}

/// A part's records as the documented format lays them out (`export/part.rs`): the offset of
/// each record, its tile, and where its bytes are.
struct Record {
    at: usize,
    tile: (u8, u32, u32),
    data: usize,
    len: usize,
}

fn records(part: &[u8]) -> Vec<Record> {
    let mut at = 0;
    for _ in 0..3 {
        at += part[at..].iter().position(|b| *b == b'\n').unwrap() + 1;
    }
    let le = |i: usize| u32::from_le_bytes(part[i..i + 4].try_into().unwrap());
    let mut out = Vec::new();
    while at < part.len() {
        let len = le(at + 9) as usize;
        out.push(Record { at, tile: (part[at], le(at + 1), le(at + 5)), data: at + 17, len });
        at += 17 + len;
    }
    out
}

fn name(t: (u8, u32, u32)) -> String {
    format!("tile {}/{}/{}", t.0, t.1, t.2)
}

#[test]
fn merge_proves_every_record_and_keeps_its_output_safe() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let three = shards("16", 3, d);
    let want = merged(&three, &d.join("clean.pmtiles"));
    let middle = std::fs::read(&three[1]).unwrap();
    let recs = records(&middle);
    assert_eq!(recs.len(), 114, "shard 1/3 of 341 tiles");
    let (mid, last) = (&recs[recs.len() / 2], recs.last().unwrap());

    // Each damage makes merge exit non-zero, naming the part and the tile, and write nothing.
    let damaged = |label: &str, bytes: Vec<u8>, says: &[String]| {
        let part = d.join(format!("{label}.part"));
        std::fs::write(&part, bytes).unwrap();
        let out = d.join(format!("{label}.pmtiles"));
        let (code, text) = merge(&[three[0].clone(), part.clone(), three[2].clone()], &out);
        assert_ne!(code, 0, "{label}: {text}");
        assert!(text.contains(part.to_str().unwrap()), "{label} names the part: {text}");
        for s in says {
            assert!(text.contains(s.as_str()), "{label} says {s}: {text}");
        }
        assert!(!out.exists(), "{label}: no archive");
        std::fs::remove_file(&part).unwrap();
    };
    let edit = |f: &dyn Fn(&mut Vec<u8>)| {
        let mut b = middle.clone();
        f(&mut b);
        b
    };
    damaged("bit", edit(&|b| b[mid.data + mid.len / 2] ^= 0x10), &[name(mid.tile), "checksum mismatch".into()]);
    damaged("header", edit(&|b| b[30] ^= 0x02), &["header is damaged".into()]);
    damaged("zoom", edit(&|b| b[last.at] = 9), &[name(last.tile), "record 114 of 114".into()]);
    damaged("column", edit(&|b| b[mid.at + 1] ^= 1), &[name(mid.tile)]);
    damaged("row", edit(&|b| b[mid.at + 5] ^= 1), &[name(mid.tile)]);
    let (a, b) = (&recs[10], &recs[11]);
    let swapped =
        [&middle[..a.at], &middle[b.at..b.data + b.len], &middle[a.at..b.at], &middle[b.data + b.len..]].concat();
    damaged("swapped", swapped, &[name(a.tile), format!("holds {}", name(b.tile))]);
    let mut data_swapped = middle.clone();
    let n = a.len.min(b.len);
    let (x, y) = (middle[a.data..a.data + n].to_vec(), middle[b.data..b.data + n].to_vec());
    data_swapped[a.data..a.data + n].copy_from_slice(&y);
    data_swapped[b.data..b.data + n].copy_from_slice(&x);
    damaged("swapped-data", data_swapped, &[name(a.tile), "checksum mismatch".into()]);
    damaged("cut-at-record", middle[..last.at].to_vec(), &[name(last.tile), "truncated".into()]);
    damaged("cut-mid-record", middle[..mid.data + 5].to_vec(), &[name(mid.tile), "truncated".into()]);
    assert!(middle.starts_with(b"TEXTILE-PART 2\n"));
    damaged("version-1", edit(&|b| b[13] = b'1'), &["version-1 part".into(), "run its shard again".into()]);

    // The output: never an input, an existing file only with --force, no temporary file left.
    let as_archive = d.join("p1.pmtiles");
    std::fs::copy(&three[1], &as_archive).unwrap();
    for force in [false, true] {
        let mut args = vec!["merge", three[0].to_str().unwrap(), as_archive.to_str().unwrap()];
        args.extend([three[2].to_str().unwrap(), "-o", as_archive.to_str().unwrap()]);
        if force {
            args.push("--force");
        }
        let (code, _, err) = textile(&args);
        assert_ne!(code, 0, "an input as the output (force {force})");
        assert!(err.contains("is one of the parts being merged"), "{err}");
        assert_eq!(std::fs::read(&as_archive).unwrap(), middle, "the input is untouched");
    }
    let existing = d.join("existing.pmtiles");
    std::fs::write(&existing, b"keep me").unwrap();
    let (code, text) = merge(&three, &existing);
    assert_ne!(code, 0);
    assert!(text.contains("exists: give --force"), "{text}");
    assert_eq!(std::fs::read(&existing).unwrap(), b"keep me");
    let mut args: Vec<&str> = vec!["merge"];
    args.extend(three.iter().map(|p| p.to_str().unwrap()));
    args.extend(["-o", existing.to_str().unwrap(), "--force"]);
    let (code, _, err) = textile(&args);
    assert_eq!(code, 0, "{err}");
    assert_eq!(std::fs::read(&existing).unwrap(), want, "replaced with --force");
    let directory = d.join("directory.pmtiles");
    std::fs::create_dir(&directory).unwrap();
    let (code, text) = merge(&three, &directory);
    assert_ne!(code, 0);
    assert!(text.contains("is a directory"), "{text}");
    let stray = stray_files(d);
    assert!(stray.is_empty(), "no temporary file is left: {stray:?}");
}

#[test]
fn one_shard_has_one_writer() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let clean_dir = d.join("clean");
    std::fs::create_dir(&clean_dir).unwrap();
    let clean = shards("16", 1, &clean_dir);
    let (args, part) = shard("16", 0, 1, d);
    let partial = d.join("w16-0of1.part.partial");
    let first = Command::new(binary()).args(&args).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
    for _ in 0..3000 {
        if partial.exists() {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, _, err) = textile(&a);
    let out = first.wait_with_output().unwrap();
    let first_err = String::from_utf8_lossy(&out.stderr).into_owned();
    // One of the two was refused at once, naming the other; the other finished.
    assert!((code == 0) != out.status.success(), "exactly one run finished: {err}{first_err}");
    let refused = if code != 0 { err } else { first_err };
    assert!(
        refused.contains("is being written by process") && refused.contains("another run of this shard"),
        "{refused}"
    );
    assert_eq!(std::fs::read(&part).unwrap(), std::fs::read(&clean[0]).unwrap(), "byte-identical to a clean run");
    let names: Vec<String> =
        std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(names.len(), 2, "the part and the clean run's folder, nothing stale: {names:?}");
}

#[test]
fn kubernetes_manifests_validate_against_the_schema() {
    let ok = Command::new("kubernetes-validate").arg("--version").output().is_ok_and(|o| o.status.success());
    if !ok {
        return skip(
            "kubernetes_manifests_validate_against_the_schema",
            "kubernetes-validate (pip install -r tests/export/requirements.txt)",
        );
    }
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../deploy/kubernetes");
    let files: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(files.len() >= 3, "{files:?}");
    let out = Command::new("kubernetes-validate").args(["--strict", "-k", "1.30.0"]).args(&files).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    assert!(text.matches("passed").count() >= 3, "{text}");
    let job = std::fs::read_to_string(dir.join("export-job.yaml")).unwrap();
    assert!(job.contains("completionMode: Indexed") && job.contains("--shard \"${JOB_COMPLETION_INDEX}/8\""));
}
