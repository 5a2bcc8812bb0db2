fn main() -> std::process::ExitCode {
    xylem::cli::main()
}
