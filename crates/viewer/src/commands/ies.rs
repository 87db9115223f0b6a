//! `viewer ies`: summarize an IES LM-63 or EULUMDAT file (chosen by content) and sample its
//! candela distribution. (The `--light ...` options that light a rendered room are in
//! [`crate::lighting`].)

use crate::args::values::finite;
use anyhow::Result;
use clap::Args;
use lut_core::{LightTable, Photometry, PhotometrySource, TableOptions};
use std::path::PathBuf;

/// Arguments of `viewer ies`.
#[derive(Args, Debug)]
pub struct IesArgs {
    /// The IES or EULUMDAT (.ldt) file; the format is recognized by content.
    pub file: PathBuf,
    /// Print the interpolated candela at VERTICAL,HORIZONTAL degrees (repeatable). Type C:
    /// vertical γ from nadir, horizontal C.
    #[arg(long = "sample", value_parser = parse_pair, allow_hyphen_values = true)]
    pub samples: Vec<(f64, f64)>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Parse "A,B" into two finite numbers.
fn parse_pair(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(',')
        .ok_or_else(|| format!("'{s}' must look like VERTICAL,HORIZONTAL, e.g. 30,90"))?;
    let num = |t: &str| -> Result<f64, String> {
        finite(t).ok_or_else(|| format!("'{s}': '{t}' is not a finite number of degrees"))
    };
    Ok((num(a)?, num(b)?))
}

/// Run `viewer ies`.
pub fn run(a: IesArgs) -> Result<()> {
    let file = Photometry::load(&a.file)?;
    let table = LightTable::from_photometry(&file, &TableOptions::default())?;
    let rated = file.rated_lumens();
    let flux = table.luminous_flux();
    let tilt = match &file.tilt {
        None => "none".to_string(),
        Some(t) => format!(
            "include ({} angles, geometry {})",
            t.angles.len(),
            t.geometry
        ),
    };
    let ldt = match &file.source {
        PhotometrySource::Ldt(l) => Some(l),
        PhotometrySource::Ies(_) => None,
    };
    let (v, h) = (&file.vertical_angles, &file.horizontal_angles);
    let samples: Vec<(f64, f64, f64)> = a
        .samples
        .iter()
        .map(|&(sv, sh)| (sv, sh, table.candela(sv, sh)))
        .collect();
    if a.json {
        let obj = serde_json::json!({
            "file": a.file.display().to_string(),
            "format": file.format_name(),
            "photometric_type": file.photometric_type.letter(),
            "symmetry": table.symmetry().name(),
            "tilt": tilt,
            "vertical_angles": v.len(),
            "horizontal_angles": h.len(),
            "vertical_range": [v[0], v[v.len() - 1]],
            "horizontal_range": [h[0], h[h.len() - 1]],
            "candela_multiplier": file.candela_scale(),
            "rated_lumens": rated,
            "lumens": flux,
            "max_candela": file.max_candela(),
            "distance_tables": table.level_count(),
            "samples": samples.iter().map(|&(sv, sh, c)| serde_json::json!({
                "vertical": sv, "horizontal": sh, "candela": c
            })).collect::<Vec<_>>(),
        });
        let mut obj = obj;
        if let Some(l) = ldt {
            obj["eulumdat"] = serde_json::json!({
                "type_indicator": l.type_indicator.code(),
                "symmetry_indicator": l.symmetry.code(),
                "absolute_photometry": l.is_absolute(),
                "lamp_flux": l.lamp_flux(),
                "light_output_ratio": l.light_output_ratio,
                "conversion_factor": l.conversion_factor,
                "measurement_tilt": l.measurement_tilt,
                "lamp_sets": l.lamp_sets.len(),
            });
        }
        crate::outln!("{obj}")?;
        return Ok(());
    }
    crate::outln!("file:               {}", a.file.display())?;
    crate::outln!("format:             {}", file.format_name())?;
    if let Some(l) = file.luminaire() {
        crate::outln!("luminaire:          {l}")?;
    }
    crate::outln!("photometric type:   {}", file.photometric_type.letter())?;
    crate::outln!("symmetry:           {}", table.symmetry().name())?;
    crate::outln!("tilt:               {tilt}")?;
    crate::outln!(
        "vertical angles:    {} ({} to {})",
        v.len(),
        v[0],
        v[v.len() - 1]
    )?;
    crate::outln!(
        "horizontal angles:  {} ({} to {})",
        h.len(),
        h[0],
        h[h.len() - 1]
    )?;
    if let Some(l) = ldt {
        crate::outln!(
            "EULUMDAT:           Ityp {} ({}), Isym {}, {} lamp set(s), LORL {} %, tilt during \
             measurement {}°",
            l.type_indicator.code(),
            l.type_indicator.name(),
            l.symmetry.code(),
            l.lamp_sets.len(),
            l.light_output_ratio,
            l.measurement_tilt
        )?;
        crate::outln!(
            "candela scale:      {} (cd/klm × first lamp set's {} lm / 1000 × conversion factor {})",
            file.candela_scale(),
            l.lamp_flux(),
            l.conversion_factor
        )?;
    } else {
        crate::outln!("candela multiplier: {}", file.candela_scale())?;
    }
    match rated {
        Some(r) => crate::outln!("rated lumens:       {r}")?,
        None => crate::outln!("rated lumens:       absolute photometry")?,
    }
    crate::outln!("lumens:             {flux:.1} (integrated from the distribution)")?;
    crate::outln!("max candela:        {}", file.max_candela())?;
    for (sv, sh, c) in samples {
        crate::outln!("candela at vertical {sv}, horizontal {sh}: {c}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_pairs_parse() {
        assert_eq!(parse_pair("30,90"), Ok((30.0, 90.0)));
        assert_eq!(parse_pair(" -5 , 1e2 "), Ok((-5.0, 100.0)));
        for bad in ["30", "30,x", "nan,1", "1,inf", ""] {
            assert!(parse_pair(bad).unwrap_err().contains(bad), "{bad}");
        }
    }
}
