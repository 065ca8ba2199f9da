//! The `textile` binary: everything lives in the `textile_server` library; this only runs it.

fn main() -> std::process::ExitCode {
    textile_server::run()
}
