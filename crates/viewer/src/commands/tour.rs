//! `viewer tour`: check a tour (every link, file and scene id, one line per problem with
//! its place in the file) and convert one to a Pannellum config.

use crate::tour::{self, check::check, pannellum};
use crate::{outln, usage};
use anyhow::{anyhow, Result};
use clap::{Args, Subcommand};
use std::path::PathBuf;

/// Arguments of `viewer tour`.
#[derive(Args, Debug)]
pub struct TourArgs {
    /// What to do.
    #[command(subcommand)]
    pub command: TourCommand,
}

/// The `viewer tour` subcommands.
#[derive(Subcommand, Debug)]
pub enum TourCommand {
    /// Check every link, file and scene id of a Pannellum config or Marzipano data.js:
    /// each problem one line (file:line: place: what), exit 1 if there is any.
    Check {
        /// The tour: a Pannellum JSON config or a Marzipano data.js.
        tour: PathBuf,
    },
    /// Save a tour (Pannellum or Marzipano) as a Pannellum tour config, in the tour's
    /// folder (its paths are relative to it).
    Convert {
        /// The tour: a Pannellum JSON config or a Marzipano data.js.
        tour: PathBuf,
        /// The Pannellum config to write (.json), in the same folder as the tour.
        #[arg(short, long)]
        output: PathBuf,
        /// Marzipano tile scenes whose levels Pannellum's multires cannot describe:
        /// write a Pannellum pyramid of each (`viewer tile` on its tile folder, into
        /// `tiles/<id>-pannellum`) and save the scene reading it, instead of leaving it
        /// out.
        #[arg(long)]
        tile: bool,
    },
}

/// Run `viewer tour`.
pub fn run(a: TourArgs) -> Result<()> {
    match a.command {
        TourCommand::Check { tour } => run_check(&tour),
        TourCommand::Convert { tour, output, tile } => run_convert(&tour, &output, tile),
    }
}

fn run_check(path: &std::path::Path) -> Result<()> {
    let loaded = tour::load(path)?;
    let mut problems = loaded.problems;
    problems.extend(check(&loaded.tour, path));
    problems.sort_by_key(|p| p.line);
    for p in &problems {
        outln!("{p}")?;
    }
    let t = &loaded.tour;
    let hotspots: usize = t.scenes.iter().map(|s| s.hotspots.len()).sum();
    if problems.is_empty() {
        outln!(
            "{}",
            lut_core::one_line(&format!(
                "{}: {} scenes, {} hotspots, first scene \"{}\": no problems",
                path.display(),
                t.scenes.len(),
                hotspots,
                t.first_scene
            ))
        )?;
        Ok(())
    } else {
        Err(anyhow!(
            "{}: {} problem{} ({} scenes, {} hotspots open)",
            path.display(),
            problems.len(),
            if problems.len() == 1 { "" } else { "s" },
            t.scenes.len(),
            hotspots
        ))
    }
}

fn run_convert(path: &std::path::Path, output: &std::path::Path, tile: bool) -> Result<()> {
    if output.extension().and_then(|e| e.to_str()) != Some("json") {
        return Err(usage!(
            "{}: a Pannellum config is written as .json",
            output.display()
        ));
    }
    let out_dir = output
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let loaded = tour::load(path)?;
    let same = match (
        std::fs::canonicalize(out_dir),
        std::fs::canonicalize(if loaded.tour.dir.as_os_str().is_empty() {
            std::path::Path::new(".")
        } else {
            &loaded.tour.dir
        }),
    ) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    };
    if !same {
        return Err(usage!(
            "{}: write the Pannellum config in the tour's folder ({}): its paths are relative to it",
            output.display(),
            loaded.tour.dir.display()
        ));
    }
    if std::fs::canonicalize(output).ok() == std::fs::canonicalize(path).ok() && output.exists() {
        return Err(usage!(
            "{}: is the tour being read; choose another name",
            output.display()
        ));
    }
    for p in &loaded.problems {
        crate::errln!("{p}");
    }
    let mut t = loaded.tour;
    if tile {
        tile_unfit(&mut t, path)?;
    }
    let left_out = pannellum::save(&t, output)?;
    // One line per Marzipano scene whose levels Pannellum's multires cannot describe.
    for entry in &left_out {
        crate::errln!(
            "{}",
            lut_core::one_line(&format!(
                "{}: scene {entry}: left out (`--tile` writes a Pannellum pyramid for it)",
                path.display()
            ))
        );
    }
    Ok(())
}

/// `convert --tile`: each Marzipano scene of `t` whose levels do not fit Pannellum's
/// multires re-tiled as a Pannellum pyramid (`viewer tile`, its finest level texel for
/// texel, the tile side of that level) into `<its tile folder>-pannellum`, and made a
/// multires scene reading it (the pyramid's `multiRes` numbers inline, as Pannellum
/// reads a tour's scene). One line per scene on stderr.
///
/// # Errors
/// A tile folder that cannot be re-tiled (its error, naming the scene).
fn tile_unfit(t: &mut tour::Tour, path: &std::path::Path) -> Result<()> {
    for i in 0..t.scenes.len() {
        let tour::Source::MarzipanoTiles { dir, levels, .. } = &t.scenes[i].source else {
            continue;
        };
        let Err(why) = pannellum::marzipano_multires(dir, levels) else {
            continue;
        };
        let id = t.scenes[i].id.clone();
        let rel = format!("{}-pannellum", dir.trim_end_matches('/'));
        let (from, to) = (
            t.resolve(dir).map_err(anyhow::Error::msg)?,
            t.resolve(&rel).map_err(anyhow::Error::msg)?,
        );
        let side = levels.iter().max_by_key(|l| l.1).map_or(512, |l| l.0);
        let args = [
            "viewer".to_string(),
            "tile".into(),
            from.display().to_string(),
            "-o".into(),
            to.display().to_string(),
            "-q".into(),
            "--tile-size".into(),
            side.to_string(),
        ];
        let cli = <crate::cli::Cli as clap::Parser>::try_parse_from(&args)
            .map_err(|e| anyhow!("{}: scene \"{id}\": {e}", path.display()))?;
        let Some(crate::cli::Command::Tile(a)) = cli.command else {
            anyhow::bail!("{}: scene \"{id}\": cannot run tile", path.display());
        };
        crate::commands::tile::run(*a)
            .map_err(|e| anyhow!("{}: scene \"{id}\": {e:#}", path.display()))?;
        let cfg: serde_json::Value = serde_json::from_slice(
            &std::fs::read(to.join("config.json"))
                .map_err(|e| anyhow!("{}: {e}", to.join("config.json").display()))?,
        )?;
        let mut m = cfg
            .get("multiRes")
            .cloned()
            .ok_or_else(|| anyhow!("{}: no multiRes", to.join("config.json").display()))?;
        m["basePath"] = serde_json::Value::String(rel.clone());
        t.scenes[i].source = tour::Source::Multires(m);
        crate::errln!(
            "{}",
            lut_core::one_line(&format!(
                "{}: scene {id}: {why}: written as a Pannellum pyramid in {rel}",
                path.display()
            ))
        );
    }
    Ok(())
}
