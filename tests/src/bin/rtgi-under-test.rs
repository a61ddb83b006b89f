//! The `rtgi` command, built inside the tests package so that its
//! integration tests can run it (`env!("CARGO_BIN_EXE_rtgi-under-test")`).

fn main() -> std::process::ExitCode {
    rtgi::main()
}
