//! `viewer ies`: summarize an IES LM-63 or EULUMDAT file (chosen by content) and sample its
//! candela distribution; and the `--light ...` options that `viewer render` flattens in to
//! light a room panorama.

use anyhow::{anyhow, Context, Result};
use clap::Args;
use lut_core::{
    shade_frame, LightScene, LightTable, Luminaire, Photometry, PhotometrySource, Room,
    ShadeOptions, TableOptions,
};
use lut_core::{Camera, View};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

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
        t.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{s}': '{t}' is not a finite number of degrees"))
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
        println!("{obj}");
        return Ok(());
    }
    println!("file:               {}", a.file.display());
    println!("format:             {}", file.format_name());
    if let Some(l) = file.luminaire() {
        println!("luminaire:          {l}");
    }
    println!("photometric type:   {}", file.photometric_type.letter());
    println!("symmetry:           {}", table.symmetry().name());
    println!("tilt:               {tilt}");
    println!(
        "vertical angles:    {} ({} to {})",
        v.len(),
        v[0],
        v[v.len() - 1]
    );
    println!(
        "horizontal angles:  {} ({} to {})",
        h.len(),
        h[0],
        h[h.len() - 1]
    );
    if let Some(l) = ldt {
        println!(
            "EULUMDAT:           Ityp {} ({}), Isym {}, {} lamp set(s), LORL {} %, tilt during \
             measurement {}°",
            l.type_indicator.code(),
            l.type_indicator.name(),
            l.symmetry.code(),
            l.lamp_sets.len(),
            l.light_output_ratio,
            l.measurement_tilt
        );
        println!(
            "candela scale:      {} (cd/klm × first lamp set's {} lm / 1000 × conversion factor {})",
            file.candela_scale(),
            l.lamp_flux(),
            l.conversion_factor
        );
    } else {
        println!("candela multiplier: {}", file.candela_scale());
    }
    match rated {
        Some(r) => println!("rated lumens:       {r}"),
        None => println!("rated lumens:       absolute photometry"),
    }
    println!("lumens:             {flux:.1} (integrated from the distribution)");
    println!("max candela:        {}", file.max_candela());
    for (sv, sh, c) in samples {
        println!("candela at vertical {sv}, horizontal {sh}: {c}");
    }
    Ok(())
}

/// Options that light a rendered room panorama (flattened into `viewer render`).
#[derive(Args, Debug, Default, Clone)]
pub struct LightArgs {
    /// Place a luminaire: FILE@X,Y,Z[:YAW,PITCH] in metres and degrees (repeatable); FILE is
    /// an IES or EULUMDAT (.ldt) file, recognized by content.
    /// World frame: X right, Y up from the floor, Z forward at yaw 0; the camera is at
    /// (0, camera height, 0). Aim defaults to straight down (yaw 0, pitch -90).
    // The brackets are the option's grammar (shown as is by --help), not a doc link.
    #[allow(rustdoc::broken_intra_doc_links)]
    #[arg(long = "light", value_parser = parse_light, allow_hyphen_values = true)]
    pub lights: Vec<LightSpec>,
    /// Room size WIDTHxDEPTHxHEIGHT in metres, centred on the camera (default 5x5x2.7).
    /// For a cube panorama give a cube.
    #[arg(long, value_parser = parse_room)]
    pub room: Option<(f64, f64, f64)>,
    /// Camera height above the floor in metres (default 1.6).
    #[arg(long)]
    pub camera_height: Option<f64>,
    /// Illuminance in lux that reproduces the panorama's own brightness (default 300).
    #[arg(long)]
    pub exposure_lux: Option<f64>,
    /// Light factor with no luminaire (0 = black, 1 = as photographed; default 0.15).
    #[arg(long)]
    pub ambient: Option<f64>,
    /// Multiply every luminaire's intensity (default 1).
    #[arg(long)]
    pub light_multiplier: Option<f64>,
    /// Overlay a false-colour illuminance map (log scale, 3 decades).
    #[arg(long)]
    pub false_color: bool,
    /// Illuminance at the top (red) of the false-colour scale in lux (default 1000).
    #[arg(long)]
    pub false_color_max: Option<f64>,
}

/// One `--light FILE.ies@X,Y,Z[:YAW,PITCH]`.
#[derive(Debug, Clone, PartialEq)]
pub struct LightSpec {
    /// The IES or EULUMDAT (.ldt) file; the format is recognized by content.
    pub file: PathBuf,
    /// Position in metres.
    pub position: [f64; 3],
    /// Aim (yaw, pitch) in degrees.
    pub aim: (f64, f64),
}

fn parse_light(s: &str) -> Result<LightSpec, String> {
    let (file, rest) = s
        .rsplit_once('@')
        .ok_or_else(|| format!("light '{s}' must look like FILE.ies@X,Y,Z[:YAW,PITCH]"))?;
    if file.is_empty() {
        return Err(format!(
            "light '{s}': the IES file name is missing before '@'"
        ));
    }
    let (pos, aim) = match rest.split_once(':') {
        Some((p, a)) => (p, Some(a)),
        None => (rest, None),
    };
    let nums = |t: &str, n: usize, what: &str| -> Result<Vec<f64>, String> {
        let v: Vec<f64> = t
            .split(',')
            .map(|x| x.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(|| format!("light '{s}': {what} '{t}' must be {n} numbers"))?;
        if v.len() != n {
            return Err(format!("light '{s}': {what} '{t}' must be {n} numbers"));
        }
        Ok(v)
    };
    let p = nums(pos, 3, "position X,Y,Z")?;
    let aim = match aim {
        Some(a) => {
            let a = nums(a, 2, "aim YAW,PITCH")?;
            (a[0], a[1])
        }
        None => (0.0, -90.0),
    };
    Ok(LightSpec {
        file: PathBuf::from(file),
        position: [p[0], p[1], p[2]],
        aim,
    })
}

fn parse_room(s: &str) -> Result<(f64, f64, f64), String> {
    let v: Vec<f64> = s
        .split(['x', 'X'])
        .map(|x| {
            x.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v > 0.0)
        })
        .collect::<Option<_>>()
        .ok_or_else(|| format!("room '{s}' must be WIDTHxDEPTHxHEIGHT in metres, e.g. 5x4x2.7"))?;
    if v.len() != 3 {
        return Err(format!(
            "room '{s}' must be WIDTHxDEPTHxHEIGHT in metres, e.g. 5x4x2.7"
        ));
    }
    Ok((v[0], v[1], v[2]))
}

/// Build the scene the arguments describe; `None` when no light is given.
///
/// # Errors
/// An unreadable or malformed IES file, a light outside the room, a bad room size.
pub fn build_scene(args: &LightArgs) -> Result<Option<LightScene>> {
    if args.lights.is_empty() {
        return Ok(None);
    }
    let (w, d, h) = args.room.unwrap_or((5.0, 5.0, 2.7));
    let room =
        Room::new(w, d, h, args.camera_height.unwrap_or(1.6)).context("--room/--camera-height")?;
    let mut tables: HashMap<&Path, Arc<LightTable>> = HashMap::new();
    let mut lights = Vec::with_capacity(args.lights.len());
    for spec in &args.lights {
        let table = match tables.get(spec.file.as_path()) {
            Some(t) => t.clone(),
            None => {
                let t = Arc::new(LightTable::load(&spec.file)?);
                tables.insert(spec.file.as_path(), t.clone());
                t
            }
        };
        let mut l = Luminaire::new(table, spec.position.into());
        l.yaw_deg = spec.aim.0;
        l.pitch_deg = spec.aim.1;
        l.multiplier = args.light_multiplier.unwrap_or(1.0);
        lights.push(l);
    }
    Ok(Some(LightScene::new(room, lights)?))
}

/// The shading options the arguments describe.
///
/// # Errors
/// A non-positive `--exposure-lux`.
pub fn shade_options(args: &LightArgs) -> Result<ShadeOptions> {
    let lux = args.exposure_lux.unwrap_or(300.0);
    if !(lux.is_finite() && lux > 0.0) {
        return Err(anyhow!(
            "--exposure-lux must be a positive number of lux, got {lux}"
        ));
    }
    let d = ShadeOptions::default();
    Ok(ShadeOptions {
        ambient: args.ambient.unwrap_or(d.ambient),
        exposure: 1.0 / lux,
        false_color: args.false_color,
        false_color_max_lux: args.false_color_max.unwrap_or(d.false_color_max_lux),
    })
}

/// Light a rendered frame of `view` in place; a no-op when no `--light` is given.
///
/// # Errors
/// As [`build_scene`] and [`shade_options`], or a frame that is not `w × h`.
pub fn apply_lights(args: &LightArgs, view: View, frame: &mut [u32], w: u32, h: u32) -> Result<()> {
    let Some(scene) = build_scene(args)? else {
        return Ok(());
    };
    let opts = shade_options(args)?;
    let cam = Camera::new(view, w, h);
    shade_frame(&scene, &cam, frame, w, h, &opts)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_spec_parses() {
        let l = parse_light("C:/lamps/a.ies@1,2.5,-3:45,-60").unwrap();
        assert_eq!(l.file, PathBuf::from("C:/lamps/a.ies"));
        assert_eq!(l.position, [1.0, 2.5, -3.0]);
        assert_eq!(l.aim, (45.0, -60.0));
        let l = parse_light("a.ies@0,2.7,0").unwrap();
        assert_eq!(l.aim, (0.0, -90.0));
        assert!(parse_light("a.ies").is_err());
        assert!(parse_light("a.ies@1,2").is_err());
        assert!(parse_light("a.ies@1,2,x").is_err());
        assert!(parse_light("@1,2,3").is_err());
        assert!(parse_light("a.ies@1,2,3:5").is_err());
    }

    #[test]
    fn room_parses() {
        assert_eq!(parse_room("5x4x2.7").unwrap(), (5.0, 4.0, 2.7));
        assert!(parse_room("5x4").is_err());
        assert!(parse_room("5x-4x2").is_err());
    }

    #[test]
    fn no_light_is_a_no_op() {
        let mut f = vec![0x123456u32; 4];
        apply_lights(&LightArgs::default(), View::default(), &mut f, 2, 2).unwrap();
        assert_eq!(f, vec![0x123456u32; 4]);
    }
}
