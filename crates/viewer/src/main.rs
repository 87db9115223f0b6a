//! `viewer`: the CPU panorama viewer.
//!
//! * `viewer [PANORAMA]` opens the interactive window (see `window`).
//! * `viewer render ...` renders one view to a PNG (headless).
//! * `viewer convert ...` converts between equirectangular and cube maps.
//! * `viewer ies ...` summarizes and samples an IES photometric file.
//! * `viewer bench ...` measures speed against error.
//! * `viewer bench-load ...` measures loading and panning huge (8k-32k) maps.

use clap::{Parser, Subcommand};
use std::process::ExitCode;

mod assets;
mod bench_cmd;
mod bench_load;
mod cli_common;
mod convert_cmd;
mod cube_cmd;
mod ies_cmd;
mod max_pixels;
mod partial;
mod render_cmd;
mod window;

/// CPU panorama viewer: scanline-coherent LUT rendering (US 5,748,194).
#[derive(Parser, Debug)]
#[command(
    name = "viewer",
    version,
    about,
    args_conflicts_with_subcommands = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Open the window (the default when no subcommand is given).
    #[command(flatten)]
    open: window::OpenArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render one view of a panorama to a PNG file.
    Render(Box<render_cmd::RenderArgs>),
    /// Convert equirect <-> cube maps.
    Convert(convert_cmd::ConvertArgs),
    /// Summarize an IES LM-63 file and sample its candela distribution.
    Ies(ies_cmd::IesArgs),
    /// Measure speed against error for every renderer configuration.
    Bench(bench_cmd::BenchArgs),
    /// Huge panoramas: load time, table build, frame time and peak memory for generated
    /// 8k, 16k and 32k equirectangular JPEGs (each in a fresh process).
    BenchLoad(bench_load::BenchLoadArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // A bad LUTPANO_KERNEL (the span kernel override) is refused up front.
    if let Err(e) = lut_core::kernel_from_env() {
        eprintln!("viewer: {e}");
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Some(Command::Render(a)) => render_cmd::run(*a),
        Some(Command::Convert(a)) => convert_cmd::run(a),
        Some(Command::Ies(a)) => ies_cmd::run(a),
        Some(Command::Bench(a)) => bench_cmd::run(a),
        Some(Command::BenchLoad(a)) => bench_load::run(a),
        None => window::run(cli.open),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("viewer: {e:#}");
            ExitCode::FAILURE
        }
    }
}
