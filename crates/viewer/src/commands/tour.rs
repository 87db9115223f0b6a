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
    },
}

/// Run `viewer tour`.
pub fn run(a: TourArgs) -> Result<()> {
    match a.command {
        TourCommand::Check { tour } => run_check(&tour),
        TourCommand::Convert { tour, output } => run_convert(&tour, &output),
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

fn run_convert(path: &std::path::Path, output: &std::path::Path) -> Result<()> {
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
    let left_out = pannellum::save(&loaded.tour, output)?;
    // One line per Marzipano scene whose levels Pannellum's multires cannot describe.
    for entry in &left_out {
        crate::errln!(
            "{}",
            lut_core::one_line(&format!(
                "{}: scene {entry}: left out (`viewer tile` on its tile folder writes a Pannellum pyramid for it)",
                path.display()
            ))
        );
    }
    Ok(())
}
