//! Fuzz target: `textile_server::robustness::analysis_file` must return for any bytes.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| textile_server::robustness::analysis_file(data));
