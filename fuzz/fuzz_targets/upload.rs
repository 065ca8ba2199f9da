//! Fuzz target: `textile_server::robustness::upload` must return for any bytes.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| textile_server::robustness::upload(data));
