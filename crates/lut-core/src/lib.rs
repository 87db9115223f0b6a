//! # lut-core
//!
//! CPU panorama rendering with a **scanline-coherent look-up table** (US 5,748,194), and
//! an exact per-pixel renderer every fast path is measured against. No window code.
//!
//! ## Pipeline
//! The modules follow the stages, dependencies pointing one way (`docs/ARCHITECTURE.md`
//! has the map): `geom` (projections, camera, fixed point, coverage, view limit, the
//! exact mapping, the error metric) ← `map` ([`EnvMap`], crops, samplers, pyramid, tone)
//! ← `lut` (the tables) ← `render` ([`Frame`], [`Scene`], [`Renderer::render`], the
//! kernels, the exact and cube renderers) ← `io` (loading, partial placement, GPano, cube
//! files) at the edge; `cube` and `light` are siblings. The modules are private; every
//! item is exported here, at the crate root.
//!
//! 1. An [`EnvMap`] holds the panorama (0RGB `u32`, padded for branch-free bilinear) and
//!    its [`Projection`] (equirectangular, cylindrical, sine, elliptical, diamond).
//! 2. A [`Renderer`] owns two look-up tables on a cylinder whose axis is parallel to the
//!    screen scanlines (the patent's FIGS. 5-7): a wide-FOV one and a high-resolution one,
//!    chosen by hfov (60° threshold) or forced. Each stores only the one-eighth region
//!    (FIG. 6E, region 681) and recovers the rest by sign and reflection.
//! 3. Per frame: pitch picks the table rows of each scanline (two rows blended), zoom is
//!    one scale factor per scanline, yaw is a column offset added to u with wrap-around.
//! 4. Per scanline: the table is read every Nth pixel and map coordinates are interpolated
//!    in fixed point between; the step is chosen per region of each scanline from an
//!    analytic error bound (shorter near a pole, where longitude changes fast, with exact
//!    evaluation in a small zone); the ±180° seam is unwrapped per span, never smeared.
//! 5. Nearest or bilinear sampling (FIG. 10), or trilinear from a pyramid of the map
//!    when zoomed out ([`EnvMap::pyramid`]), writes 0RGB pixels into the caller's
//!    [`Frame`], optionally in row bands across threads (byte-identical to one thread).
//!
//! Loading ([`load_map`], [`LoadOptions`]): a pixel limit checked from the file header
//! before decoding, 8-bit images decoded straight into the map's buffer, progress reports.
//!
//! Partial panoramas ([`load_partial`], [`Coverage`], [`Crop`], [`GPano`]): a map may
//! store only the pixels of the area it covers plus their place in the full panorama
//! (GPano XMP or an explicit [`Coverage`]); renderers keep the full geometry and sampling
//! returns the background outside the crop; [`limit_view`] keeps a view inside the
//! covered area.
//!
//! Cube maps ([`CubeMap`], [`load_cube`]) and goniometric lights ([`LightTable`],
//! [`shade_frame`]) are siblings of the map pipeline.
//!
//! ## One render entry
//! ```
//! use lut_core::{grid_map, Frame, Projection, RenderOptions, Renderer, Scene, View};
//! let map = grid_map(512, 256, Projection::Equirect)?;
//! let mut renderer = Renderer::new(&map);
//! let mut pixels = vec![0u32; 320 * 200];
//! let mut frame = Frame::new(&mut pixels, 320, 200)?; // size and length checked once
//! let view = View::new(30.0, 10.0, 90.0)?;
//! let opts = RenderOptions::default(); // LUT, bilinear, adaptive step, threads
//! let report = renderer.render(Scene::Map(&map), view, &opts, &mut frame)?;
//! assert_eq!(report.pixels, 320 * 200);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//! A cube map goes through the same call as `Scene::Cube(&cube)`.
//!
//! ## Conventions (`docs/conventions.md`, followed exactly)
//! * yaw ψ positive turns right (toward increasing longitude), any real value, reduced
//!   mod 360°; pitch θ positive looks up, clamped to [−90°, 90°]; hfov is the horizontal
//!   field of view of the output, in (0°, 180°). No roll.
//! * Pixel (i, j) covers [i, i+1) × [j, j+1), center (i + ½, j + ½); row 0 is the top.
//! * Camera ray of output pixel (x, y): d = (x + ½ − W/2, H/2 − (y + ½), f),
//!   f = (W/2)/tan(hfov/2), rotated by pitch about X then yaw about Y;
//!   λ = atan2(X', Z'), φ = atan2(Y', √(X'² + Z'²)).
//! * Equirect: u = (λ + π)/2π · W, v = (π/2 − φ)/π · H; other projections in
//!   [`Projection`].
//! * Colors are 8-bit sRGB filtered as stored; `u32` pixels are 0RGB.
//!
//! ## Accuracy
//! The LUT renderer's *sampling-position error* is the distance between its (u, v) and
//! the exact (u, v), in source pixels, with the u part scaled by cos φ (so it measures
//! the angular error in units of the map's pixel pitch and stays well defined at the
//! poles, where a whole map row is one direction). The budget is 0.05 px everywhere;
//! see `docs/ARCHITECTURE.md` and the property tests for the bound reached.

#![warn(missing_docs)]

mod cube;
mod error;
mod file;
mod geom;
mod io;
mod light;
mod lut;
mod map;
mod named;
mod render;

pub use error::{
    AngleProblem, CoverageError, CropProblem, GPanoError, MapError, SizeProblem, SyntaxProblem,
    ViewError,
};

// Names of the option enums (one list each, for the CLI, a panel, JSON and messages).
pub use named::{name_list, parse_name, Named};

// Geometry.
pub use geom::accuracy::{
    compare_positions, position_error, position_errors, raw_error, ErrorStats,
};
pub use geom::camera::{check_size, dir_to_lat_long, lat_long_to_dir, wrap_deg, Camera, View};
pub use geom::coverage::{compass_heading, compass_point, Coverage, Crop, StartView};
pub use geom::fixed::{from_fx, to_fx, Fx, FX_BITS, FX_HALF, FX_ONE};
pub use geom::limits::{MAX_MAP_HEIGHT, MAX_MAP_PIXELS, MAX_MAP_WIDTH, MAX_OUTPUT_SIDE};
pub use geom::mapping::{exact_uv, exact_uv_at};
pub use geom::projection::{wrap_pi, Projection};
pub use geom::view_projection::{ViewProjection, PANNINI_D_DEFAULT, PANNINI_D_MAX};
pub use geom::viewlimit::{frame_extent, limit_view, view_inside, FrameExtent};

// Maps.
pub use map::envmap::{check_map_size, EnvMap};
pub use map::pyramid::{lod_q8, LOD_BIAS};
pub use map::sample::{lerp_px, Sampler};
pub use map::synth::{grid_map, scene_color};
pub use map::tone::{tone_map, Tone};

// Tables.
pub use lut::{LutTable, Surface, TableKind, TableSpec, TABLE_ERROR_BUDGET};

// Rendering.
pub use render::cube::{scanline_runs, CubeRenderer};
pub use render::exact::{render_exact, render_exact_supersampled, sample_at, sample_at_lod};
pub use render::frame::Frame;
pub use render::grid::{GRID_CELL, GRID_CELL_BUDGET, GRID_MIN_CELL};
pub use render::heat::{
    heat_color, heat_scale, ErrorMap, HEAT_BACKGROUND, HEAT_MAX, HEAT_MIN, HEAT_MISMATCH,
};
pub use render::kernel::{
    active_kernel, cpu_features, kernel_from_env, kernel_info, parse_kernel, set_kernel, Kernel,
    KernelError, KernelInfo, KernelSource, SpanJob, Texels, Window, KERNEL_ENV, MAX_JOBS,
    MAX_LEVELS, TRILINEAR_CHUNK,
};
pub use render::steps::{ADAPTIVE_MAX_STEP, SPAN_ERROR_BUDGET};
pub use render::{
    build_frame_levels, BandHook, IndexStep, LutChoice, Positions, RenderOptions, RenderPath,
    RenderReport, Renderer, RendererKind, Scene, HOOK_BAND_ROWS, LUT_SWITCH_HFOV,
};

// Input.
pub use file::open_regular;
pub use io::cube::{
    cube_face_files, decode_layout_image, load_cube, load_face_files, load_layout_image,
};
pub use io::gpano::{insert_xmp, jpeg_xmp, read_gpano, xmp_packet, GPano, GPANO_NS, XMP_SIGNATURE};
pub use io::jpeg::jpeg_max_pixels;
pub use io::load::{
    check_pixel_limit, decode_map, load_map, map_from_image, resolve_projection, LoadOptions,
    LoadPhase, LoadProgress, DEFAULT_MAX_PIXELS,
};
pub use io::partial::{decode_partial, load_partial, CoverageSource};

// Cube maps.
pub use cube::layout::{layout_dimensions, Layout, Naming, Transform};
pub use cube::{
    check_face_size, face_axes, face_dir, face_of, face_uv, CubeError, CubeMap, Face, FacesProblem,
    LayoutProblem, UsageProblem, MAX_FACE_SIZE,
};

// Lights.
pub use light::{
    detect_format, false_color, false_color_position, lit_cube_bytes, lit_map_bytes, lux_at,
    shade_frame, FrameShader, IesError, IesFile, IesFormat, IlluminanceMap, Interpolation, LampSet,
    LdtError, LdtFile, LdtSymmetry, LdtType, LightError, LightFileFormat, LightScene, LightTable,
    Luminaire, MapOptions, PhotometricType, Photometry, PhotometrySource, Room, RoomFace,
    ShadeOptions, Symmetry, TableOptions, Tilt, TiltData, BAKE_MAX_BYTES, MAP_SHADE_BLOCK,
    MAX_FILE_BYTES as MAX_LIGHT_FILE_BYTES,
};

/// The module layout's rules, checked from the source: dependencies between the stages
/// (read from `crate::` paths in non-test code) point one way, with no circle.
#[cfg(test)]
mod layout {
    use std::collections::{BTreeMap, BTreeSet};
    use std::path::Path;

    /// What each stage may use. `io` is the edge: it may use anything below it, and
    /// nothing uses it.
    const ALLOWED: &[(&str, &[&str])] = &[
        ("error", &[]),
        ("named", &[]),
        ("geom", &["error", "named"]),
        ("map", &["geom", "error", "named"]),
        ("lut", &["geom", "error", "named"]),
        ("cube", &["geom", "map", "error", "named"]),
        ("render", &["geom", "map", "lut", "cube", "error", "named"]),
        ("file", &[]),
        (
            "light",
            &["geom", "map", "cube", "render", "error", "named", "file"],
        ),
        (
            "io",
            &["geom", "map", "lut", "cube", "render", "error", "file"],
        ),
    ];

    /// The stage a source file belongs to: its first folder, or its stem at the root.
    fn stage(rel: &Path) -> String {
        let first = rel.components().next().expect("a path");
        let s = first.as_os_str().to_string_lossy();
        s.trim_end_matches(".rs").to_string()
    }

    /// `crate::NAME` stages used by the non-test code of `text` (lines before the first
    /// `#[cfg(test)]`, comments skipped).
    fn uses(text: &str) -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        for line in text.lines().take_while(|l| l.trim() != "#[cfg(test)]") {
            let code = line.split("//").next().unwrap_or("");
            assert!(
                !code.contains("crate::{"),
                "grouped `crate::{{` paths are not parsed: {line}"
            );
            for (i, _) in code.match_indices("crate::") {
                if i > 0 && code[..i].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
                    continue; // e.g. `pub(crate)` is not followed by `::`, but be safe
                }
                let name: String = code[i + 7..]
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    out.insert(name);
                }
            }
        }
        out
    }

    fn graph() -> BTreeMap<String, BTreeSet<String>> {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut files = vec![src.clone()];
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        while let Some(p) = files.pop() {
            if p.is_dir() {
                for e in std::fs::read_dir(&p).expect("read src") {
                    files.push(e.expect("dir entry").path());
                }
                continue;
            }
            if p.extension().is_none_or(|e| e != "rs") || p.ends_with("src/lib.rs") {
                continue;
            }
            let rel = p.strip_prefix(&src).expect("under src");
            let from = stage(rel);
            let text = std::fs::read_to_string(&p).expect("read source");
            let to = g.entry(from.clone()).or_default();
            for u in uses(&text) {
                if u != from {
                    to.insert(u);
                }
            }
        }
        g
    }

    /// A circle of `g` as the path that closes it (`a -> b -> … -> a`), if there is one
    /// (depth-first search for a back edge).
    fn circle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
        fn visit(
            n: &str,
            g: &BTreeMap<String, BTreeSet<String>>,
            done: &mut BTreeSet<String>,
            path: &mut Vec<String>,
        ) -> Option<Vec<String>> {
            if let Some(i) = path.iter().position(|p| p == n) {
                let mut c = path[i..].to_vec();
                c.push(n.to_string());
                return Some(c);
            }
            if done.contains(n) {
                return None;
            }
            path.push(n.to_string());
            for m in g.get(n).into_iter().flatten() {
                if let Some(c) = visit(m, g, done, path) {
                    return Some(c);
                }
            }
            path.pop();
            done.insert(n.to_string());
            None
        }
        let mut done = BTreeSet::new();
        g.keys()
            .find_map(|n| visit(n, g, &mut done, &mut Vec::new()))
    }

    #[test]
    fn stages_depend_one_way() {
        let g = graph();
        let allowed: BTreeMap<&str, &[&str]> = ALLOWED.iter().copied().collect();
        for (from, tos) in &g {
            let ok = allowed
                .get(from.as_str())
                .unwrap_or_else(|| panic!("module {from} is not in the layout's list"));
            for to in tos {
                assert!(
                    ok.contains(&to.as_str()),
                    "{from} uses crate::{to}, which the layout does not allow ({from} may use {ok:?})"
                );
            }
        }
        // No circle, whatever the list above says.
        assert_eq!(circle(&g), None, "module circle");
        // The edge really is the edge.
        for (from, tos) in &g {
            assert!(!tos.contains("io"), "{from} uses io");
        }
    }

    #[test]
    fn the_parser_sees_paths_and_skips_tests_and_comments() {
        let text = "use crate::geom::camera::View;\n\
                    // crate::io in a comment\n\
                    fn f() { crate::map::x(); }\n\
                    #[cfg(test)]\n\
                    use crate::io::load;\n";
        let got: Vec<String> = uses(text).into_iter().collect();
        assert_eq!(got, ["geom", "map"]);
        // A circle is found.
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        g.entry("a".into()).or_default().insert("b".into());
        g.entry("b".into()).or_default().insert("c".into());
        g.entry("c".into()).or_default().insert("a".into());
        assert_eq!(
            circle(&g),
            Some(vec!["a".into(), "b".into(), "c".into(), "a".into()])
        );
        g.get_mut("c").unwrap().clear();
        assert_eq!(circle(&g), None);
    }
}
