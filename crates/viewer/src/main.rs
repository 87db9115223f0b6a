//! `viewer`: the CPU panorama viewer (see the library's docs for what each command does).
//! Parse the command line, run the command, print its error in one line, exit with the
//! status `viewer::exit` documents (0 done, 1 a file or device failed, 2 a usage error).

use clap::Parser;
use std::process::ExitCode;
use viewer::cli::{Cli, Command};
use viewer::commands::{
    bench, bench_load, bench_tiles, convert, ies, lux, render, report, tile, tour,
};

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return clap_error(&e),
    };
    if cli.command.is_none() {
        // The window: one heap arena, which its trims reach whole (glibc; see
        // `viewer::window::heap`). Before any other thread exists: glibc fixes its arena
        // limit at the first allocation of a second thread (the signal thread's, next).
        viewer::window::heap::one_arena();
    }
    viewer::signals::install();
    // A bad LUTPANO_KERNEL (the span kernel override) is refused up front.
    if let Err(e) = lut_core::kernel_from_env() {
        viewer::errln!("viewer: {e}");
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Some(Command::Render(a)) => render::run(*a),
        Some(Command::Convert(a)) => convert::run(a),
        Some(Command::Ies(a)) => ies::run(a),
        Some(Command::Lux(a)) => lux::run(a),
        Some(Command::Report(a)) => report::run(*a),
        Some(Command::Bench(a)) => bench::run(a),
        Some(Command::BenchLoad(a)) => bench_load::run(a),
        Some(Command::BenchTiles(a)) => bench_tiles::run(*a),
        Some(Command::Tile(a)) => tile::run(*a),
        Some(Command::Tour(a)) => tour::run(a),
        None => viewer::window::run(cli.open),
    };
    // Lines still in standard output's buffer: a full disk shows here.
    let result = result.and_then(|()| viewer::exit::flush());
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of our output went away: nothing is wrong with the command.
        Err(e) if viewer::exit::is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            // Every message path echoes input the same way: control characters escaped,
            // long names and numbers shortened (lut_core::one_line).
            viewer::errln!("{}", lut_core::one_line(&format!("viewer: {e:#}")));
            ExitCode::from(viewer::exit::code(&e))
        }
    }
}

/// Clap's own message (help and version to standard output as they are; errors to
/// standard error, each line escaped and shortened like every message, exit 2).
fn clap_error(e: &clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
        let _ = e.print();
        return ExitCode::SUCCESS;
    }
    let text = e.render().to_string();
    for line in text.trim_end().lines() {
        viewer::errln!("{}", lut_core::one_line(line));
    }
    ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2))
}
