//! # lut-core
//!
//! CPU panorama rendering with a **scanline-coherent look-up table** (US 5,748,194), and
//! an exact per-pixel renderer every fast path is measured against. No window code.
//!
//! ## Pipeline
//! The modules follow the stages, dependencies pointing one way (`docs/ARCHITECTURE.md`
//! has the map): `geom` (projections, camera, fixed point, coverage, view limit, the
//! exact mapping, the error metric) ← `map` ([`EnvMap`], crops, samplers, pyramid, tone)
//! ← `lut` (the tables) ← `render` ([`Frame`], [`Renderer::render`], the kernels, the
//! exact and cube renderers) ← `panorama` ([`Panorama`]: the one panorama type, a map
//! with its renderer, a cube map or a tiled pyramid (`tiles`), and the one dispatch to
//! their renderers) ← `io`
//! (loading, partial placement, GPano, cube files) at the edge; `cube` and `light` are
//! siblings. The modules are private; every item is exported here, at the crate root.
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
//! A [`Panorama`] owns what is drawn (a map with its [`Renderer`] and tables, a cube map,
//! or a tiled pyramid; room for more kinds: [`PanoramaKind`] is `#[non_exhaustive]`) and
//! [`Panorama::render`] is the one call that draws any of them:
//! ```
//! use lut_core::{grid_map, Frame, Panorama, Projection, RenderOptions, View};
//! let mut pano = Panorama::map(grid_map(512, 256, Projection::Equirect)?);
//! let mut pixels = vec![0u32; 320 * 200];
//! let mut frame = Frame::new(&mut pixels, 320, 200)?; // size and length checked once
//! let view = View::new(30.0, 10.0, 90.0)?;
//! let opts = RenderOptions::default(); // LUT, bilinear, adaptive step, threads
//! let report = pano.render(view, &opts, &mut frame)?;
//! assert_eq!(report.pixels, 320 * 200);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//! A cube map is `Panorama::cube(cube)`, drawn by the same call. A borrowed map can be
//! drawn by a [`Renderer`] directly (`renderer.render(&map, view, &opts, &mut frame)`).
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
mod guard;
mod io;
mod jpeg;
mod light;
mod lut;
mod map;
mod named;
mod panorama;
mod render;
mod tiles;

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
/// Every limit on a number that sizes work or memory (docs/reliability.md, "Limits").
pub mod limits {
    pub use crate::cube::MAX_FACE_SIZE;
    pub use crate::geom::limits::*;
    pub use crate::io::load::DEFAULT_MAX_PIXELS;
    pub use crate::light::MAX_FILE_BYTES as MAX_LIGHT_FILE_BYTES;
    pub use crate::tiles::config::{
        MAX_BASE_TILES, MAX_CONFIG_BYTES as MAX_TILE_CONFIG_BYTES, MAX_CUBE_RESOLUTION,
        MAX_LEVELS as MAX_TILE_LEVELS, MAX_MISSING_TILES, MAX_TILE_RESOLUTION, MIN_TILE_RESOLUTION,
    };
    pub use crate::tiles::decode::MAX_TILE_FILE_BYTES;
}

// The guards every input path shares (docs/reliability.md): decoder containment, echoed
// text, limit checks.
pub use geom::mapping::{exact_uv, exact_uv_at};
pub use geom::projection::{wrap_pi, Projection};
pub use geom::view_projection::{ViewProjection, PANNINI_D_DEFAULT, PANNINI_D_MAX};
pub use geom::viewlimit::{frame_extent, limit_view, view_inside, FrameExtent};
pub use guard::{
    catch_quiet, check_limit, contain, escape_controls, fault_point, one_line, panic_message,
    shown, shown_path, DecoderPanic, LimitError, ECHO_MAX_CHARS, FAULT_ENV, MESSAGE_MAX_CHARS,
};

// Maps.
pub use map::envmap::{check_map_size, EnvMap};
pub use map::level::{bilinear_f64, equirect_uv, horizon_rotation, level_horizon};
pub use map::pyramid::{lod_q8, LOD_BIAS};
pub use map::sample::{lerp_px, Sampler};
pub use map::synth::{grid_map, scene_color};
pub use map::tone::{tone_map, Tone};

// Tables.
pub use lut::{LutTable, Surface, TableKind, TableSpec, TABLE_ERROR_BUDGET};

// Rendering.
pub use render::cube::{scanline_runs, CubeRenderer, ScanlineRun};
pub use render::exact::{render_exact, render_exact_supersampled, sample_at, sample_at_lod};
pub use render::frame::Frame;
pub use render::grid::{GRID_CELL, GRID_CELL_BUDGET, GRID_MIN_CELL};
pub use render::heat::{
    heat_color, heat_scale, ErrorMap, HEAT_BACKGROUND, HEAT_MAX, HEAT_MIN, HEAT_MISMATCH,
};
pub use render::kernel::{
    active_kernel, cpu_features, kernel_from_env, kernel_info, parse_kernel, set_kernel, Kernel,
    KernelError, KernelInfo, KernelSource, SelectedKernel, SpanJob, Steps, Texels, Window,
    KERNEL_ENV, MAX_JOBS, MAX_LEVELS, TRILINEAR_CHUNK,
};
pub use render::steps::{ADAPTIVE_MAX_STEP, SPAN_ERROR_BUDGET};
pub use render::{
    build_frame_levels, BandHook, IndexStep, LutChoice, MapGeometry, Positions, RenderOptions,
    RenderPath, RenderReport, Renderer, RendererKind, HOOK_BAND_ROWS, LUT_SWITCH_HFOV,
};

// The one panorama type (a map with its renderer, a cube map) and its one dispatch.
pub use panorama::{Panorama, PanoramaKind};

// Input.
pub use file::{open_regular, read_regular};
pub use io::cube::{
    cube_face_files, decode_layout_image, load_cube, load_face_files, load_layout_image,
};
pub use io::gpano::{insert_xmp, jpeg_xmp, read_gpano, xmp_packet, GPano, GPANO_NS, XMP_SIGNATURE};
pub use io::load::{
    check_pixel_limit, decode_map, load_map, map_from_image, resolve_projection, LoadOptions,
    LoadPhase, LoadProgress, DEFAULT_MAX_PIXELS,
};
pub use io::partial::{decode_partial, load_partial, CoverageSource};
pub use jpeg::jpeg_max_pixels;

// Cube maps.
pub use cube::layout::{layout_dimensions, Layout, Naming, Transform};
pub use cube::level::level_cube_horizon;
pub use cube::{
    check_face_size, face_axes, face_dir, face_of, face_uv, CubeError, CubeMap, Face, FacesProblem,
    LayoutProblem, UsageProblem, MAX_FACE_SIZE,
};
pub use tiles::store::DEFAULT_CACHE_BYTES as DEFAULT_TILE_CACHE_BYTES;
pub use tiles::{
    decode_bytes as decode_tile_bytes, generator_levels, write_marzipano, write_pyramid,
};
pub use tiles::{
    frame_level as tile_frame_level, render_tiles, trilinear_levels as tile_trilinear_levels,
    CacheStats, DecodeStats, LevelInfo, MultiresConfig, TileFrame, TileId, TileLoader, TileStore,
    TiledPanorama, TilesError, MARZIPANO_PREVIEW_ORDER,
};

// Lights.
pub use light::{
    border_band, en12464_spacing, ugr, AreaStats, CalcGrid, DirectLight, FormFactors, GlareTerm,
    LuminousArea, Patch, Radiosity, Reflectances, Ugr, DEFAULT_PATCHES, MAX_GRID_POINTS,
    MAX_PATCHES,
};
pub use light::{
    detect_format, false_color, false_color_position, lit_cube_bytes, lit_map_bytes,
    lit_panorama_bytes, lux_at, shade_frame, FrameShader, IesError, IesFile, IesFormat,
    IlluminanceMap, Interpolation, LampSet, LdtError, LdtFile, LdtSymmetry, LdtType, LightError,
    LightFileFormat, LightScene, LightTable, Luminaire, MapOptions, PhotometricType, Photometry,
    PhotometrySource, Room, RoomFace, ShadeOptions, Symmetry, TableOptions, Tilt, TiltData,
    BAKE_MAX_BYTES, MAP_SHADE_BLOCK, MAX_FILE_BYTES as MAX_LIGHT_FILE_BYTES,
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
        (
            "panorama",
            &[
                "geom", "map", "lut", "cube", "render", "tiles", "error", "named",
            ],
        ),
        ("file", &[]),
        ("guard", &[]),
        ("jpeg", &["error", "guard"]),
        (
            "light",
            &[
                "geom", "map", "cube", "render", "panorama", "error", "named", "file", "guard",
            ],
        ),
        (
            "tiles",
            &[
                "geom", "map", "cube", "render", "error", "named", "file", "guard", "jpeg",
            ],
        ),
        (
            "io",
            &[
                "geom", "map", "lut", "cube", "render", "panorama", "error", "file", "guard",
                "jpeg",
            ],
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

    // ---- Files: inside `render/` (its kernels included) and `light/` ----------------

    /// The folders whose files must import one way, file by file.
    const FILE_DIRS: &[&str] = &["render", "light"];

    /// A token of Rust source, as much as following paths needs.
    #[derive(Debug, Clone, PartialEq)]
    enum Tok {
        /// An identifier or keyword.
        Id(String),
        /// `::`.
        Sep,
        /// Any other punctuation character.
        P(char),
    }

    /// The tokens of `text`: comments, string and character literals and numbers dropped.
    fn tokens(text: &str) -> Vec<Tok> {
        let c: Vec<char> = text.chars().collect();
        let at = |i: usize| c.get(i).copied().unwrap_or(' ');
        let mut out = Vec::new();
        let mut i = 0;
        while i < c.len() {
            let ch = c[i];
            if ch == '/' && at(i + 1) == '/' {
                while i < c.len() && c[i] != '\n' {
                    i += 1;
                }
            } else if ch == '/' && at(i + 1) == '*' {
                let mut depth = 0;
                while i < c.len() {
                    if c[i] == '/' && at(i + 1) == '*' {
                        depth += 1;
                        i += 2;
                    } else if c[i] == '*' && at(i + 1) == '/' {
                        depth -= 1;
                        i += 2;
                        if depth == 0 {
                            break;
                        }
                    } else {
                        i += 1;
                    }
                }
            } else if ch == '"' {
                i += 1;
                while i < c.len() && c[i] != '"' {
                    i += if c[i] == '\\' { 2 } else { 1 };
                }
                i += 1;
            } else if ch == '\'' {
                // A character literal ('x', '\n', '\''), else a lifetime ('a).
                if at(i + 1) == '\\' {
                    i += 2;
                    while i < c.len() && c[i] != '\'' {
                        i += 1;
                    }
                    i += 1;
                } else if at(i + 2) == '\'' {
                    i += 3;
                } else {
                    i += 1;
                }
            } else if ch.is_ascii_digit() {
                while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                    i += 1;
                }
            } else if ch.is_alphabetic() || ch == '_' {
                let start = i;
                while i < c.len() && (c[i].is_alphanumeric() || c[i] == '_') {
                    i += 1;
                }
                let id: String = c[start..i].iter().collect();
                if (id == "r" || id == "br") && (at(i) == '"' || at(i) == '#') {
                    // A raw string: r#"…"#.
                    let hashes = c[i..].iter().take_while(|&&x| x == '#').count();
                    i += hashes + 1;
                    while i < c.len()
                        && !(c[i] == '"' && c[i + 1..].iter().take(hashes).all(|&x| x == '#'))
                    {
                        i += 1;
                    }
                    i += 1 + hashes;
                } else {
                    out.push(Tok::Id(id));
                }
            } else if ch == ':' && at(i + 1) == ':' {
                out.push(Tok::Sep);
                i += 2;
            } else {
                if !ch.is_whitespace() {
                    out.push(Tok::P(ch));
                }
                i += 1;
            }
        }
        out
    }

    /// What one file says about paths: per module scope (the file's module, or an
    /// inline `mod name { … }` in it), the names its `use` items bring in (name → path
    /// as written) and every path it mentions (in `use` items and in code, as written).
    #[derive(Debug, Default)]
    struct Mentions {
        imports: Vec<(Vec<String>, String, Vec<String>)>,
        paths: Vec<(Vec<String>, Vec<String>)>,
        inline: Vec<Vec<String>>,
    }

    /// The path segments starting at `t[*i]` (`a::b::c`), advancing `*i` past them.
    fn path_at(t: &[Tok], i: &mut usize) -> Vec<String> {
        let mut p = Vec::new();
        while let Some(Tok::Id(s)) = t.get(*i) {
            p.push(s.clone());
            *i += 1;
            if t.get(*i) == Some(&Tok::Sep) && matches!(t.get(*i + 1), Some(Tok::Id(_))) {
                *i += 1;
            } else {
                break;
            }
        }
        p
    }

    /// One `use` tree from `t[*i]` under `prefix`: its leaves (local name, path) and its
    /// globs (the path before `*`).
    fn use_tree(
        t: &[Tok],
        i: &mut usize,
        mut prefix: Vec<String>,
        leaves: &mut Vec<(String, Vec<String>)>,
        globs: &mut Vec<Vec<String>>,
    ) {
        loop {
            match t.get(*i) {
                Some(Tok::Sep) => *i += 1,
                Some(Tok::Id(s)) => {
                    prefix.push(s.clone());
                    *i += 1;
                    if t.get(*i) == Some(&Tok::Sep) {
                        *i += 1;
                        continue;
                    }
                    let mut name = s.clone();
                    if t.get(*i) == Some(&Tok::Id("as".into())) {
                        if let Some(Tok::Id(n)) = t.get(*i + 1) {
                            name = n.clone();
                        }
                        *i += 2;
                    }
                    if name == "self" {
                        prefix.pop();
                        name = prefix.last().cloned().unwrap_or_default();
                    }
                    leaves.push((name, prefix));
                    return;
                }
                Some(Tok::P('*')) => {
                    *i += 1;
                    globs.push(prefix);
                    return;
                }
                Some(Tok::P('{')) => {
                    *i += 1;
                    while !matches!(t.get(*i), None | Some(Tok::P('}'))) {
                        use_tree(t, i, prefix.clone(), leaves, globs);
                        if t.get(*i) == Some(&Tok::P(',')) {
                            *i += 1;
                        }
                    }
                    *i += 1;
                    return;
                }
                _ => return,
            }
        }
    }

    /// The index just past the item starting at `t[i]` (through its `;` or its closing
    /// `}` at depth 0, attributes before it included).
    fn item_end(t: &[Tok], mut i: usize) -> usize {
        let mut depth = 0i32;
        while i < t.len() {
            match t[i] {
                Tok::P('(' | '[' | '{') => depth += 1,
                Tok::P(')' | ']') => depth -= 1,
                Tok::P('}') => {
                    depth -= 1;
                    if depth == 0 {
                        return i + 1;
                    }
                }
                Tok::P(';') if depth == 0 => return i + 1,
                _ => {}
            }
            i += 1;
        }
        i
    }

    /// The paths of the non-test code of a file whose module is `module` (items under
    /// `#[cfg(test)]` skipped; visibility paths `pub(in …)` are not uses).
    fn mentions(module: &[String], text: &str) -> Mentions {
        let t = tokens(text);
        let mut m = Mentions::default();
        // Inline modules: (their path, the brace depth outside them).
        let mut scopes: Vec<(Vec<String>, i32)> = vec![(module.to_vec(), -1)];
        let mut depth = 0i32;
        let id = |i: usize, s: &str| t.get(i) == Some(&Tok::Id(s.into()));
        let p = |i: usize, c: char| t.get(i) == Some(&Tok::P(c));
        let mut i = 0;
        while i < t.len() {
            let scope = scopes.last().expect("the file's scope").0.clone();
            if p(i, '#')
                && p(i + 1, '[')
                && id(i + 2, "cfg")
                && p(i + 3, '(')
                && id(i + 4, "test")
                && p(i + 5, ')')
                && p(i + 6, ']')
            {
                i = item_end(&t, i + 7);
                continue;
            }
            match &t[i] {
                Tok::Id(k) if k == "mod" && p(i + 2, '{') => {
                    if let Some(Tok::Id(name)) = t.get(i + 1) {
                        let mut path = scope.clone();
                        path.push(name.clone());
                        m.inline.push(path.clone());
                        scopes.push((path, depth));
                    }
                    depth += 1;
                    i += 3;
                }
                Tok::Id(k) if k == "use" => {
                    i += 1;
                    let (mut leaves, mut globs) = (Vec::new(), Vec::new());
                    use_tree(&t, &mut i, Vec::new(), &mut leaves, &mut globs);
                    for (name, path) in leaves {
                        m.paths.push((scope.clone(), path.clone()));
                        m.imports.push((scope.clone(), name, path));
                    }
                    m.paths
                        .extend(globs.into_iter().map(|g| (scope.clone(), g)));
                }
                Tok::Id(k) if k == "in" && i > 0 && p(i - 1, '(') => {
                    i += 1;
                    path_at(&t, &mut i);
                }
                Tok::Id(_) if t.get(i + 1) == Some(&Tok::Sep) => {
                    let path = path_at(&t, &mut i);
                    if path.len() > 1 {
                        m.paths.push((scope, path));
                    }
                }
                Tok::P('{') => {
                    depth += 1;
                    i += 1;
                }
                Tok::P('}') => {
                    depth -= 1;
                    if scopes.len() > 1 && scopes.last().is_some_and(|s| s.1 == depth) {
                        scopes.pop();
                    }
                    i += 1;
                }
                _ => i += 1,
            }
        }
        m
    }

    /// The file-level import graph of source files (path relative to `src/`, text):
    /// an edge `a → b` when file a's non-test code names a path into file b's module (a
    /// `use`, or a path in code), following re-exports (`pub use x::Item` in a module
    /// makes `module::Item` a path into x). Only files under [`FILE_DIRS`] are nodes.
    /// A file naming its own ancestors (`super::Type` for a type a `mod.rs` defines) is
    /// not an edge: a parent holds its children, which may use what it declares; what it
    /// re-exports from a sibling is followed to that sibling.
    fn file_graph(files: &[(String, String)]) -> BTreeMap<String, BTreeSet<String>> {
        type Path = Vec<String>;
        let module_of = |rel: &str| -> Path {
            let mut p: Path = rel
                .trim_end_matches(".rs")
                .split('/')
                .map(String::from)
                .collect();
            if p.last().is_some_and(|l| l == "mod") {
                p.pop();
            }
            p
        };
        let file_of: BTreeMap<Path, String> = files
            .iter()
            .map(|(rel, _)| (module_of(rel), rel.clone()))
            .collect();
        let all: Vec<(Path, Mentions)> = files
            .iter()
            .map(|(rel, text)| (module_of(rel), mentions(&module_of(rel), text)))
            .collect();
        let mut known: BTreeSet<Path> = file_of.keys().cloned().collect();
        let mut imports: BTreeMap<Path, BTreeMap<String, Path>> = BTreeMap::new();
        for (_, m) in &all {
            known.extend(m.inline.iter().cloned());
            for (scope, name, path) in &m.imports {
                imports
                    .entry(scope.clone())
                    .or_default()
                    .insert(name.clone(), path.clone());
            }
        }
        // A path as written in `scope`, from the crate root (None: another crate, or
        // a local item).
        fn absolute(
            scope: &[String],
            raw: &[String],
            known: &BTreeSet<Vec<String>>,
            imports: &BTreeMap<Vec<String>, BTreeMap<String, Vec<String>>>,
            depth: usize,
        ) -> Option<Vec<String>> {
            let first = raw.first()?;
            let mut base: Vec<String> = match first.as_str() {
                "crate" => Vec::new(),
                "self" => scope.to_vec(),
                "super" => {
                    let mut b = scope.to_vec();
                    for s in raw.iter().take_while(|s| *s == "super") {
                        let _ = s;
                        b.pop()?;
                    }
                    b.extend(raw.iter().skip_while(|s| *s == "super").cloned());
                    return Some(b);
                }
                name => {
                    let mut child = scope.to_vec();
                    child.push(name.to_string());
                    if known.contains(&child) {
                        child.extend(raw[1..].iter().cloned());
                        return Some(child);
                    }
                    let target = imports.get(scope)?.get(name)?;
                    if depth > 8 || target == raw {
                        return None;
                    }
                    let mut a = absolute(scope, target, known, imports, depth + 1)?;
                    a.extend(raw[1..].iter().cloned());
                    return Some(a);
                }
            };
            base.extend(raw[1..].iter().cloned());
            Some(base)
        }
        // The deepest module an absolute path reaches, re-exports followed.
        fn reach(
            abs: &[String],
            known: &BTreeSet<Vec<String>>,
            imports: &BTreeMap<Vec<String>, BTreeMap<String, Vec<String>>>,
            depth: usize,
        ) -> Vec<String> {
            let mut cur: Vec<String> = Vec::new();
            for (k, seg) in abs.iter().enumerate() {
                let mut next = cur.clone();
                next.push(seg.clone());
                if known.contains(&next) {
                    cur = next;
                    continue;
                }
                if depth < 8 {
                    let again = imports
                        .get(&cur)
                        .and_then(|m| m.get(seg))
                        .and_then(|raw| absolute(&cur, raw, known, imports, 0));
                    if let Some(mut a) = again {
                        a.extend(abs[k + 1..].iter().cloned());
                        return reach(&a, known, imports, depth + 1);
                    }
                }
                break;
            }
            cur
        }
        let inside = |p: &Path| p.first().is_some_and(|f| FILE_DIRS.contains(&f.as_str()));
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (from, m) in &all {
            if !inside(from) {
                continue;
            }
            let edges = g.entry(file_of[from].clone()).or_default();
            for (scope, raw) in &m.paths {
                let Some(abs) = absolute(scope, raw, &known, &imports, 0) else {
                    continue;
                };
                let mut to = reach(&abs, &known, &imports, 0);
                while !to.is_empty() && !file_of.contains_key(&to) {
                    to.pop();
                }
                let ancestor = to.len() < from.len() && from.starts_with(&to);
                if inside(&to) && &to != from && !ancestor {
                    edges.insert(file_of[&to].clone());
                }
            }
        }
        g
    }

    /// The source files of the crate (relative to `src/`, with `/`), test-only folders
    /// (`tests/`) left out.
    fn sources() -> Vec<(String, String)> {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut todo = vec![src.clone()];
        let mut out = Vec::new();
        while let Some(p) = todo.pop() {
            if p.is_dir() {
                if p.file_name().is_some_and(|n| n == "tests") {
                    continue;
                }
                for e in std::fs::read_dir(&p).expect("read src") {
                    todo.push(e.expect("dir entry").path());
                }
            } else if p.extension().is_some_and(|e| e == "rs") {
                let rel = p.strip_prefix(&src).expect("under src");
                let rel: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                let text = std::fs::read_to_string(&p).expect("read source");
                out.push((rel.join("/"), text));
            }
        }
        out.sort();
        out
    }

    #[test]
    fn files_in_render_and_light_import_one_way() {
        let g = file_graph(&sources());
        assert!(
            g.contains_key("render/kernel/span/mod.rs") && g.contains_key("light/shade_table.rs"),
            "the graph has the files: {:?}",
            g.keys().collect::<Vec<_>>()
        );
        assert_eq!(circle(&g), None, "file circle inside render/ or light/");
    }

    #[test]
    fn the_file_graph_follows_paths_and_finds_a_planted_circle() {
        let files = |v: &[(&str, &str)]| -> Vec<(String, String)> {
            v.iter()
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .collect()
        };
        let tree = [
            ("render/mod.rs", "mod a; mod b; mod c; mod k;\npub(crate) use k::Thing;\n"),
            // A child naming its parent's own item: no edge; a re-export: followed.
            ("render/a.rs", "use super::Thing;\nuse super::{b::{self, f as g}, Local};\n"),
            ("render/b.rs", "// crate::render::a in a comment\nfn f() { let s = \"super::a::x\"; }\n\
              #[cfg(test)]\nmod tests { use crate::render::c::x; }\nmod inner { fn h() { super::super::c::y(); } }\n"),
            ("render/c.rs", "pub(in crate::render) fn y() {}\n"),
            ("render/k/mod.rs", "mod x86;\npub struct Local;\n"),
            ("render/k/x86.rs", "use super::Local;\nuse $crate::render::c::y;\n"),
            ("light/l.rs", "use crate::render::a::f;\nuse std::sync::OnceLock;\n"),
        ];
        let g = file_graph(&files(&tree));
        let edges = |f: &str| -> Vec<&str> { g[f].iter().map(String::as_str).collect() };
        assert_eq!(edges("render/mod.rs"), ["render/k/mod.rs"]);
        assert_eq!(edges("render/a.rs"), ["render/b.rs", "render/k/mod.rs"]);
        assert_eq!(edges("render/b.rs"), ["render/c.rs"]);
        assert!(edges("render/c.rs").is_empty());
        assert_eq!(edges("render/k/x86.rs"), ["render/c.rs"]);
        assert_eq!(edges("light/l.rs"), ["render/a.rs"]);
        assert_eq!(circle(&g), None);
        // Plant a circle: c uses a (a → b → c → a).
        let mut planted = tree.to_vec();
        planted[3] = ("render/c.rs", "fn y() { crate::render::a::z(); }\n");
        let g = file_graph(&files(&planted));
        assert_eq!(
            circle(&g),
            Some(
                ["render/a.rs", "render/b.rs", "render/c.rs", "render/a.rs"]
                    .map(String::from)
                    .to_vec()
            )
        );
    }
}
