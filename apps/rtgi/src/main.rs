fn main() -> std::process::ExitCode {
    rtgi::main()
}
