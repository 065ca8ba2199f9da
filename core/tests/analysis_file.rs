//! A stored analysis reloads to the very same bytes. Its hash is part of every ETag and cache
//! key, so a replica that loaded an analysis from disk must agree with the one that computed it
//! — including the header's floating-point fields, which must survive the JSON round trip.

mod common;

use textile_core::{Analysis, Exemplar, ExemplarOptions, NoProgress};

#[test]
fn reloaded_analyses_have_the_same_bytes_and_hash() {
    for name in ["gravel.png", "grass.png", "brick.png"] {
        let bytes = std::fs::read(common::embedded_exemplar(name)).expect("read exemplar");
        let ex = Exemplar::from_bytes(&bytes, &ExemplarOptions::default()).expect("decode exemplar");
        let built = Analysis::build(&ex, &NoProgress);
        let stored = built.to_bytes();
        let loaded = Analysis::from_bytes(&stored).expect("parse");
        assert_eq!(loaded.header, built.header, "{name}: header after the round trip");
        assert!(loaded.to_bytes() == stored, "{name}: bytes after the round trip");
        assert_eq!(loaded.file_hash(), built.file_hash(), "{name}");
    }
}
