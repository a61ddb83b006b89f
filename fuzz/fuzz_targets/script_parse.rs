#![no_main]
//! Script text (lossily UTF-8, as a script file or the prompt gives it),
//! parsed line by line as `rtgi script` does and as one string: nothing may
//! panic, and a refused line names its command. The same property runs on
//! stable as `crates/script/tests/parse_never_panics.rs`.

use libfuzzer_sys::fuzz_target;
use rtgi_script::parse;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    for line in text.lines().chain(std::iter::once(text.as_ref())) {
        if let Err(error) = parse(line) {
            assert_eq!(error.command(), line.split_whitespace().next().unwrap_or(""));
        }
    }
});
