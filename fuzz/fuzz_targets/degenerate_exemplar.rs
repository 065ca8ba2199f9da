//! Fuzz target: `textile_server::robustness::degenerate_exemplar` must return, in bounded time,
//! for any bytes.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| textile_server::robustness::degenerate_exemplar(data));
