//! `viewer`: the CPU panorama viewer (see the library's docs for what each command does).
//! Parse the command line, run the command, print its error in one line, exit nonzero.

use clap::Parser;
use std::process::ExitCode;
use viewer::cli::{Cli, Command};
use viewer::commands::{bench, bench_load, convert, ies, lux, render};

fn main() -> ExitCode {
    let cli = Cli::parse();
    // A bad LUTPANO_KERNEL (the span kernel override) is refused up front.
    if let Err(e) = lut_core::kernel_from_env() {
        eprintln!("viewer: {e}");
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Some(Command::Render(a)) => render::run(*a),
        Some(Command::Convert(a)) => convert::run(a),
        Some(Command::Ies(a)) => ies::run(a),
        Some(Command::Lux(a)) => lux::run(a),
        Some(Command::Bench(a)) => bench::run(a),
        Some(Command::BenchLoad(a)) => bench_load::run(a),
        None => viewer::window::run(cli.open),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("viewer: {e:#}");
            ExitCode::FAILURE
        }
    }
}
