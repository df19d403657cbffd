//! Arbitrary bytes as a config: parsing and validation must never panic, and a config that
//! validates must survive a TOML round trip unchanged.

#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common/round_trip.rs"]
mod round_trip;

fuzz_target!(|data: &[u8]| {
    // The CLI refuses non-UTF-8 files before parsing; lossy decoding still exercises the
    // parser on the rest of the bytes.
    let text = String::from_utf8_lossy(data);
    round_trip::check(&text);
});
