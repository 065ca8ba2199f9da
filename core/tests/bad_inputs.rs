//! Bad exemplars and damaged analysis files give the right typed error, never a panic.

mod common;

use textile_core::{Analysis, AnalysisFileProblem, CoreError, Exemplar, ExemplarOptions};

fn crc32(data: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

/// A valid 1×1 PNG whose IHDR is rewritten to claim `w × h` (with a correct CRC).
fn png_claiming(w: u32, h: u32) -> Vec<u8> {
    let mut buf = Vec::new();
    image::RgbImage::new(1, 1).write_to(&mut std::io::Cursor::new(&mut buf), image::ImageFormat::Png).unwrap();
    buf[16..20].copy_from_slice(&w.to_be_bytes());
    buf[20..24].copy_from_slice(&h.to_be_bytes());
    let crc = crc32(&buf[12..29]);
    buf[29..33].copy_from_slice(&crc.to_be_bytes());
    buf
}

#[test]
fn bad_exemplars_are_typed_errors() {
    let opts = ExemplarOptions::default();
    assert!(matches!(Exemplar::from_bytes(b"", &opts), Err(CoreError::ExemplarUndecodable(_))));
    assert!(matches!(Exemplar::from_bytes(b"hello, I am text\n", &opts), Err(CoreError::ExemplarUndecodable(_))));
    assert!(matches!(
        Exemplar::from_bytes(&png_claiming(1, 1), &opts),
        Err(CoreError::ExemplarSize { width: 1, height: 1, .. })
    ));
    assert!(matches!(
        Exemplar::from_bytes(&png_claiming(20000, 20000), &opts),
        Err(CoreError::ExemplarSize { width: 20000, height: 20000, .. })
    ));
    // A valid header with a body cut short.
    let good = std::fs::read(common::embedded_exemplar("grass.png")).unwrap();
    let cut = &good[..good.len() / 2];
    assert!(matches!(Exemplar::from_bytes(cut, &opts), Err(CoreError::ExemplarUndecodable(_))));
}

fn problem(bytes: &[u8]) -> AnalysisFileProblem {
    match Analysis::from_bytes(bytes) {
        Err(CoreError::AnalysisFile { problem, .. }) => problem,
        other => panic!("expected an analysis file error, got {:?}", other.map(|a| a.header)),
    }
}

#[test]
fn damaged_analysis_files_are_typed_errors() {
    let good = common::small().to_bytes();
    assert!(Analysis::from_bytes(&good).is_ok());
    assert!(matches!(problem(&good[..good.len() - 1000]), AnalysisFileProblem::Truncated { .. }));
    assert!(matches!(problem(&good[..10]), AnalysisFileProblem::Truncated { .. }));
    assert_eq!(problem(b""), AnalysisFileProblem::BadMagic);
    let mut magic = good.clone();
    magic[0] = b'X';
    assert_eq!(problem(&magic), AnalysisFileProblem::BadMagic);
    let mut version = good.clone();
    version[8] = 99;
    assert!(matches!(problem(&version), AnalysisFileProblem::UnsupportedVersion { found: 99, .. }));
    for pos in [200, good.len() / 2, good.len() - 40] {
        let mut flipped = good.clone();
        flipped[pos] ^= 0x10;
        assert_eq!(problem(&flipped), AnalysisFileProblem::ChecksumMismatch, "flip at {pos}");
    }
}

#[test]
fn load_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("broken.tex");
    std::fs::write(&path, b"TXTLANA\0garbage").unwrap();
    let err = Analysis::load(&path).unwrap_err();
    assert!(err.to_string().contains("broken.tex"), "{err}");
    let missing = Analysis::load(&dir.path().join("none.tex")).unwrap_err();
    assert!(matches!(missing, CoreError::Io { .. }));
}
