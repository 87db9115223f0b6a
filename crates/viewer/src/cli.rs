//! The command line: `viewer [PANORAMA]` opens the window; the subcommands render,
//! convert, summarize IES files and measure.

use crate::commands::{
    bench, bench_load, bench_tiles, convert, ies, lux, render, report, tile, tour,
};
use clap::{Parser, Subcommand};

/// CPU panorama viewer: scanline-coherent LUT rendering (US 5,748,194).
#[derive(Parser, Debug)]
#[command(
    name = "viewer",
    version,
    about,
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    /// The subcommand; none opens the window.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Open the window (the default when no subcommand is given).
    #[command(flatten)]
    pub open: crate::window::OpenArgs,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render one view of a panorama to a PNG file.
    Render(Box<render::RenderArgs>),
    /// Convert equirect <-> cube maps.
    Convert(convert::ConvertArgs),
    /// Summarize an IES LM-63 file and sample its candela distribution.
    Ies(ies::IesArgs),
    /// Illuminance in lux at points of the room from its luminaires.
    Lux(lux::LuxArgs),
    /// Lighting report against EN 12464-1: grids, Em/Emin/U0 per area, UGR; text, JSON,
    /// PNG and HTML.
    Report(Box<report::ReportArgs>),
    /// Measure speed against error for every renderer configuration.
    Bench(bench::BenchArgs),
    /// Huge panoramas: load time, table build, frame time and peak memory for generated
    /// 8k, 16k and 32k equirectangular JPEGs (each in a fresh process).
    BenchLoad(bench_load::BenchLoadArgs),
    /// Gigapixel panoramas from tiles: first picture, time to sharp, pan frame times,
    /// peak memory and decode rates for synthetic 16k, 64k and 256k pyramids (each in a
    /// fresh process, cold).
    BenchTiles(Box<bench_tiles::BenchTilesArgs>),
    /// Gigapixel panoramas: write a Pannellum multires pyramid (tiled cube faces) of a
    /// panorama, read in row bands, memory bounded whatever its size.
    Tile(Box<tile::TileArgs>),
    /// Tours (Pannellum configs, Marzipano data.js): check, convert to Pannellum.
    Tour(tour::TourArgs),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_command_line_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }

    #[test]
    fn no_subcommand_opens_the_window() {
        let cli = Cli::try_parse_from(["viewer", "a.jpg", "--size", "800x500"]).unwrap();
        assert!(cli.command.is_none());
        assert_eq!(cli.open.size, (800, 500));
        assert_eq!(cli.open.panorama, [std::path::PathBuf::from("a.jpg")]);
        let cli = Cli::try_parse_from(["viewer", "ies", "x.ies", "--sample", "1,2"]).unwrap();
        assert!(matches!(cli.command, Some(Command::Ies(_))));
    }

    #[test]
    fn the_window_takes_a_start_view() {
        let cli = Cli::try_parse_from([
            "viewer", "a.jpg", "--yaw", "-30", "--pitch", "12.5", "--hfov", "60",
        ])
        .unwrap();
        let o = cli.open;
        assert_eq!(
            (o.yaw, o.pitch, o.hfov),
            (Some(-30.0), Some(12.5), Some(60.0))
        );
        let o = Cli::try_parse_from(["viewer"]).unwrap().open;
        assert_eq!(
            (o.yaw, o.pitch, o.hfov),
            (None, None, None),
            "the file's own view"
        );
        for (flag, bad, says) in [
            ("--hfov", "180", "must be in (0, 180)"),
            ("--hfov", "0", "must be in (0, 180)"),
            ("--yaw", "nan", "not a finite number"),
            ("--pitch", "up", "not a number"),
        ] {
            let e = Cli::try_parse_from(["viewer", flag, bad])
                .unwrap_err()
                .to_string();
            assert!(e.contains(bad) && e.contains(says), "{flag} {bad}: {e}");
        }
    }
}
