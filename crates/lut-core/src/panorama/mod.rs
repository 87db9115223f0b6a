//! The one panorama type: [`Panorama`] owns what is drawn — an equirect-family map
//! ([`EnvMap`], any [`crate::Projection`], full or partial) with its LUT [`Renderer`]
//! (tables, scratch, pyramid-level renderer), a cube map ([`CubeMap`]), or a tiled
//! multiresolution pyramid ([`TiledPanorama`]) — and is the one dispatch from "which kind
//! of panorama" to its renderer.
//!
//! Every method that depends on the kind is written here, each as one `match` on the
//! private representation ([`Repr`]); callers outside never match on the kind (a
//! [`PanoramaKind`], `#[non_exhaustive]`, says what it is, for readouts). A new kind is
//! one more variant of [`Repr`] and of [`PanoramaKind`] and one more arm in each method
//! of this file, as the tiled pyramid was.
//!
//! The pixels are shared (`Arc`), not copied: [`Panorama::share`] gives another handle on
//! the same pixels and tables (with its own per-frame scratch) for another thread, e.g.
//! the viewer's lighting bake. A lit copy (`IlluminanceMap::bake_panorama`) is a
//! `Panorama` too, sharing the tables of the panorama it was lit from (same geometry).

use crate::cube::CubeMap;
use crate::error::ViewError;
use crate::geom::camera::{check_size, View};
use crate::lut::{Surface, TableKind};
use crate::map::envmap::EnvMap;
use crate::map::sample::Sampler;
use crate::render::cube::cube_frame;
use crate::render::frame::Frame;
use crate::render::heat::ErrorMap;
use crate::render::{BandHook, RenderOptions, RenderReport, Renderer};
use crate::tiles::{frame_level, trilinear_levels, TiledPanorama};
use std::sync::{Arc, Mutex};

/// What kind of panorama a [`Panorama`] is (readouts, messages). More kinds may be added,
/// so a `match` on it needs a wildcard arm.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PanoramaKind {
    /// An equirect-family map on a surface of revolution (full or partial), drawn by the
    /// LUT, grid or exact renderer.
    Map,
    /// A cube map, drawn by one of the cube renderers.
    Cube,
    /// A tiled multiresolution pyramid read from disk (Pannellum's `multires`).
    Tiled,
}

impl PanoramaKind {
    /// Short name: "map", "cube", "tiled".
    pub fn name(self) -> &'static str {
        match self {
            PanoramaKind::Map => "map",
            PanoramaKind::Cube => "cube",
            PanoramaKind::Tiled => "tiled",
        }
    }

    /// What a reader calls it: "map", "cube", "tiled pyramid".
    pub fn noun(self) -> &'static str {
        match self {
            PanoramaKind::Tiled => "tiled pyramid",
            other => other.name(),
        }
    }
}

/// A panorama ready to draw, owning its pixels (shared by `Arc`) and its renderer's
/// state: the one map-or-cube type, and the one dispatch to its renderer
/// ([`Panorama::render`]).
///
/// ```
/// use lut_core::{grid_map, Frame, Panorama, Projection, RenderOptions, View};
/// let mut pano = Panorama::map(grid_map(512, 256, Projection::Equirect)?);
/// let mut pixels = vec![0u32; 320 * 200];
/// let mut frame = Frame::new(&mut pixels, 320, 200)?;
/// let report = pano.render(View::new(30.0, 10.0, 90.0)?, &RenderOptions::default(), &mut frame)?;
/// assert_eq!(report.pixels, 320 * 200);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug)]
pub struct Panorama {
    repr: Repr,
    /// A cube's bilinear frames read the face pyramid level of each region's footprint
    /// ([`Panorama::set_region_lod`]; a map's renderer keeps its own flag).
    cube_region_lod: bool,
}

/// The kinds, with what each owns. Private: only this file matches on it.
#[derive(Debug)]
enum Repr {
    /// A map and its LUT renderer (tables built on first use, or by
    /// [`Panorama::prepare`]).
    Map {
        map: Arc<EnvMap>,
        renderer: Renderer,
    },
    /// A cube map (its renderers keep no state between frames).
    Cube(Arc<CubeMap>),
    /// A tiled pyramid: its cache and decode pool (shared by handles, locked per frame),
    /// and its level 1 as a cube (what lighting and size readouts use).
    Tiled(Tiled),
}

/// A tiled pyramid's handle.
#[derive(Debug, Clone)]
struct Tiled {
    pano: Arc<Mutex<TiledPanorama>>,
    base: Arc<CubeMap>,
    /// Frames wait for their tiles (the CLI) instead of drawing ancestors (the window).
    wait: bool,
    /// Still frames: the level no pixel is magnified by more than √2 on; moving: the
    /// level of the centre's footprint.
    still: bool,
}

impl From<EnvMap> for Panorama {
    fn from(map: EnvMap) -> Panorama {
        Panorama::map(map)
    }
}

impl From<CubeMap> for Panorama {
    fn from(cube: CubeMap) -> Panorama {
        Panorama::cube(cube)
    }
}

impl Panorama {
    /// A map (owned or already shared), with a new renderer for its geometry; the tables
    /// are built on the first frame that needs them (or by [`Panorama::prepare`]).
    pub fn map(map: impl Into<Arc<EnvMap>>) -> Panorama {
        let map = map.into();
        let renderer = Renderer::new(&map);
        Panorama {
            repr: Repr::Map { map, renderer },
            cube_region_lod: false,
        }
    }

    /// A cube map (owned or already shared).
    pub fn cube(cube: impl Into<Arc<CubeMap>>) -> Panorama {
        Panorama {
            repr: Repr::Cube(cube.into()),
            cube_region_lod: false,
        }
    }

    /// A tiled pyramid (opened by [`TiledPanorama::open`]). Frames draw what is decoded
    /// and request the rest (the window) or, with `wait`, wait for every tile they read
    /// (the same bytes whatever the timing: `viewer render`).
    pub fn tiled(pano: TiledPanorama, wait: bool) -> Panorama {
        let base = Arc::new(pano.base_cube());
        Panorama {
            repr: Repr::Tiled(Tiled {
                pano: Arc::new(Mutex::new(pano)),
                base,
                wait,
                still: true,
            }),
            cube_region_lod: false,
        }
    }

    /// A tiled pyramid's cache counters, tiles pending and notices since the last call
    /// (`None` for other kinds).
    pub fn tiles_status(&self) -> Option<(crate::tiles::CacheStats, usize, Vec<String>)> {
        match &self.repr {
            Repr::Tiled(t) => {
                let mut p = t.pano.lock().unwrap_or_else(|e| e.into_inner());
                p.pump();
                let s = p.store().stats();
                Some((s, p.pending(), p.take_notices()))
            }
            _ => None,
        }
    }

    /// Change a tiled pyramid's cache budget (no effect on other kinds).
    pub fn set_tile_cache_bytes(&mut self, bytes: usize) {
        if let Repr::Tiled(t) = &self.repr {
            let mut p = t.pano.lock().unwrap_or_else(|e| e.into_inner());
            p.store_mut().set_budget(bytes);
        }
    }

    /// What kind of panorama this is.
    pub fn kind(&self) -> PanoramaKind {
        match &self.repr {
            Repr::Map { .. } => PanoramaKind::Map,
            Repr::Cube(_) => PanoramaKind::Cube,
            Repr::Tiled(_) => PanoramaKind::Tiled,
        }
    }

    /// The map, when this is one (its projection, size, crop, pyramid).
    pub fn as_map(&self) -> Option<&EnvMap> {
        match &self.repr {
            Repr::Map { map, .. } => Some(map),
            Repr::Cube(_) | Repr::Tiled(_) => None,
        }
    }

    /// The cube map, when this is one.
    pub fn as_cube(&self) -> Option<&CubeMap> {
        match &self.repr {
            Repr::Cube(cube) => Some(cube),
            Repr::Map { .. } | Repr::Tiled(_) => None,
        }
    }

    /// The map's LUT renderer, when this is a map (its tables: [`Renderer::table`]).
    pub fn renderer_mut(&mut self) -> Option<&mut Renderer> {
        match &mut self.repr {
            Repr::Map { renderer, .. } => Some(renderer),
            Repr::Cube(_) | Repr::Tiled(_) => None,
        }
    }

    /// The stored pixels' size: a map's width and height, a cube's face size (twice).
    pub fn size(&self) -> (u32, u32) {
        match &self.repr {
            Repr::Map { map, .. } => (map.width(), map.height()),
            Repr::Cube(cube) => (cube.face_size(), cube.face_size()),
            Repr::Tiled(t) => {
                let c = t
                    .pano
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .config()
                    .cube;
                (c, c)
            }
        }
    }

    /// Bytes of pixels in memory: the map's padded buffer, or the cube's six faces with
    /// their borders (pyramids not counted).
    pub fn bytes(&self) -> usize {
        match &self.repr {
            Repr::Map { map, .. } => map.bytes(),
            Repr::Cube(cube) => cube.bytes(),
            Repr::Tiled(t) => {
                let p = t.pano.lock().unwrap_or_else(|e| e.into_inner());
                p.store().stats().bytes + t.base.bytes()
            }
        }
    }

    /// Another handle on the same panorama for another thread: the same pixels (the
    /// `Arc`s) and the same tables, its own per-frame scratch. Cheap: nothing is copied
    /// but the map's per-row scale (elliptical and diamond maps, one `i64` a row).
    pub fn share(&self) -> Panorama {
        let repr = match &self.repr {
            Repr::Map { map, renderer } => Repr::Map {
                map: map.clone(),
                renderer: renderer.share(),
            },
            Repr::Cube(cube) => Repr::Cube(cube.clone()),
            Repr::Tiled(t) => Repr::Tiled(t.clone()),
        };
        Panorama {
            repr,
            cube_region_lod: self.cube_region_lod,
        }
    }

    /// Build now what the first frames would otherwise build: for a map both tables on
    /// `surface` and the pyramids of zoomed-out frames ([`crate::build_frame_levels`]); for a
    /// cube the face pyramid. `progress` gets fractions from 0 to 1 as the work goes.
    pub fn prepare(&mut self, surface: Surface, progress: &mut dyn FnMut(f32)) {
        progress(0.0);
        match &mut self.repr {
            Repr::Map { map, renderer } => {
                // A renderer made by `Renderer::new` has a geometry: the tables are built.
                let _ = renderer.table(surface, TableKind::Wide);
                progress(0.3);
                let _ = renderer.table(surface, TableKind::High);
                progress(0.5);
                crate::render::build_frame_levels(map);
            }
            Repr::Cube(cube) => {
                cube.pyramid();
            }
            Repr::Tiled(_) => {}
        }
        progress(1.0);
    }

    /// Draw still frames of a map from the pyramid level that matches the frame
    /// ([`Renderer::set_still_level`]); no effect on a cube (its renderers pick the face
    /// level per pixel).
    pub fn set_still_level(&mut self, on: bool) {
        match &mut self.repr {
            Repr::Map { renderer, .. } => renderer.set_still_level(on),
            Repr::Tiled(t) => t.still = on,
            Repr::Cube(_) => {}
        }
    }

    /// Draw bilinear frames of a map from the pyramid level that matches the screen
    /// ([`Renderer::set_bilinear_level`]); no effect on a cube.
    pub fn set_bilinear_level(&mut self, on: bool) {
        if let Repr::Map { renderer, .. } = &mut self.repr {
            renderer.set_bilinear_level(on);
        }
    }

    /// Bilinear frames choose their pyramid level per region: a map's
    /// ([`Renderer::set_region_lod`]) and a cube's (the face pyramid level nearest each
    /// 16 pixels' footprint, `render/cube.rs`); no effect on a tiled panorama.
    pub fn set_region_lod(&mut self, on: bool) {
        self.cube_region_lod = on;
        if let Repr::Map { renderer, .. } = &mut self.repr {
            renderer.set_region_lod(on);
        }
    }

    /// Render `view` into `frame` with `opts`: a map with its renderer (LUT, grid or
    /// exact, as `opts.renderer` says), a cube map with `opts.cube` (rectilinear views;
    /// other output projections per pixel).
    ///
    /// # Errors
    /// [`ViewError::BadIndexStep`] for an index step not in {1, 2, 4, 8, 16} (the frame's
    /// size was checked when it was made).
    pub fn render(
        &mut self,
        view: View,
        opts: &RenderOptions,
        frame: &mut Frame<'_>,
    ) -> Result<RenderReport, ViewError> {
        self.render_hooked(view, opts, frame, None)
    }

    /// [`Panorama::render`], then `hook` on every band of rows of the frame
    /// ([`BandHook`], [`Renderer::render_with`]): fused into the row bands where the
    /// renderer can (a map's LUT bilinear, nearest and trilinear frames), after the frame
    /// otherwise. The pixels are the same either way.
    ///
    /// # Errors
    /// As [`Panorama::render`].
    pub fn render_with(
        &mut self,
        view: View,
        opts: &RenderOptions,
        frame: &mut Frame<'_>,
        hook: BandHook<'_>,
    ) -> Result<RenderReport, ViewError> {
        self.render_hooked(view, opts, frame, Some(hook))
    }

    /// The one dispatch of a frame to the renderer of the panorama's kind.
    fn render_hooked(
        &mut self,
        view: View,
        opts: &RenderOptions,
        frame: &mut Frame<'_>,
        hook: Option<BandHook<'_>>,
    ) -> Result<RenderReport, ViewError> {
        let cube_region_lod = self.cube_region_lod;
        match &mut self.repr {
            Repr::Map { map, renderer } => match hook {
                Some(hook) => renderer.render_with(map, view, opts, frame, hook),
                None => renderer.render(map, view, opts, frame),
            },
            Repr::Cube(cube) => {
                let report = cube_frame(cube, view, opts, frame, cube_region_lod)?;
                if let Some(hook) = hook {
                    crate::render::run_hook(frame, opts, hook);
                }
                Ok(report)
            }
            Repr::Tiled(t) => {
                let (w, h) = (frame.width(), frame.height());
                let mut p = t.pano.lock().unwrap_or_else(|e| e.into_inner());
                p.pump();
                // Trilinear: the two levels around the footprint, mixed by its log2;
                // nearest and bilinear: the one level the footprint picks.
                let f = if opts.sampler == Sampler::Trilinear {
                    let (fine, tw) = trilinear_levels(p.store(), view, w, h, t.still);
                    p.render_trilinear(view, fine, tw, frame.pixels_mut(), w, h, t.wait)
                } else {
                    let level = frame_level(p.store(), view, w, h, t.still);
                    if t.wait {
                        p.render_wait(view, opts.sampler, level, frame.pixels_mut(), w, h)
                    } else {
                        p.render(view, opts.sampler, level, frame.pixels_mut(), w, h, true)
                    }
                };
                drop(p);
                if let Some(hook) = hook {
                    crate::render::run_hook(frame, opts, hook);
                }
                Ok(RenderReport {
                    path: crate::render::RenderPath::Tiles {
                        level: f.level,
                        coarser: f.coarser(),
                    },
                    exact_pixels: 0,
                    pixels: w as u64 * h as u64,
                    table_bytes: 0,
                    max_step: 1,
                    min_step: 1,
                })
            }
        }
    }

    /// The per-pixel sampling-position error of the renderer `opts` selects for `view`
    /// on a `width × height` output ([`ErrorMap::measure`] for a map: the frame's
    /// positions against the exact map). A cube's renderers compute every pixel's face
    /// coordinates exactly, so its errors are all 0 (background pixels: none).
    ///
    /// # Errors
    /// A bad output size; as [`Panorama::render`].
    pub fn error_map(
        &mut self,
        view: View,
        opts: &RenderOptions,
        width: u32,
        height: u32,
    ) -> Result<ErrorMap, ViewError> {
        check_size(width, height)?;
        match &mut self.repr {
            Repr::Map { map, renderer } => {
                ErrorMap::measure(renderer, map, view, opts, width, height)
            }
            // Tiles are drawn with the cube kernels' exact positions.
            Repr::Cube(_) | Repr::Tiled(_) => Ok(ErrorMap::exact(view, width, height)),
        }
    }

    /// A panorama of the same kind and geometry whose pixels are `map(the map)` or
    /// `cube(the cube)` (a lit copy), sharing this one's tables.
    pub(crate) fn try_derive<E>(
        &self,
        map: impl FnOnce(&EnvMap) -> Result<EnvMap, E>,
        cube: impl FnOnce(&CubeMap) -> Result<CubeMap, E>,
    ) -> Result<Panorama, E> {
        let repr = match &self.repr {
            Repr::Map { map: m, renderer } => Repr::Map {
                map: Arc::new(map(m)?),
                renderer: renderer.share(),
            },
            Repr::Cube(c) => Repr::Cube(Arc::new(cube(c)?)),
            // A lit copy of gigapixels would not fit in memory: a tiled pyramid's lit
            // copy is its level 1 as a cube map, lit (docs/huge.md).
            Repr::Tiled(t) => Repr::Cube(Arc::new(cube(&t.base)?)),
        };
        Ok(Panorama {
            repr,
            cube_region_lod: self.cube_region_lod,
        })
    }

    /// `map(the map)` or `cube(the cube)`.
    pub(crate) fn with_pixels<T>(
        &self,
        map: impl FnOnce(&EnvMap) -> T,
        cube: impl FnOnce(&CubeMap) -> T,
    ) -> T {
        match &self.repr {
            Repr::Map { map: m, .. } => map(m),
            Repr::Cube(c) => cube(c),
            Repr::Tiled(t) => cube(&t.base),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::sample::Sampler;
    use crate::map::synth::grid_map;
    use crate::render::cube::CubeRenderer;
    use crate::render::{RenderPath, HOOK_BAND_ROWS};
    use crate::Projection;
    use std::sync::atomic::{AtomicUsize, Ordering};

    fn frame_of(pano: &mut Panorama, view: View, opts: &RenderOptions) -> (Vec<u32>, RenderReport) {
        let (w, h) = (40, 24);
        let mut out = vec![1u32; (w * h) as usize];
        let r = pano
            .render(view, opts, &mut Frame::new(&mut out, w, h).unwrap())
            .unwrap();
        (out, r)
    }

    /// A map panorama draws what its renderer draws of the map; a cube panorama what the
    /// cube renderers draw; a shared handle the same pixels; the hook runs on every row.
    #[test]
    fn one_dispatch_draws_what_the_kinds_renderers_draw() {
        let map = grid_map(128, 64, Projection::Equirect).unwrap();
        let view = View::new(30.0, 10.0, 90.0).unwrap();
        let opts = RenderOptions {
            sampler: Sampler::Nearest,
            ..RenderOptions::default()
        };
        let mut want = vec![0u32; 40 * 24];
        let direct = Renderer::new(&map)
            .render(
                &map,
                view,
                &opts,
                &mut Frame::new(&mut want, 40, 24).unwrap(),
            )
            .unwrap();
        let cube = CubeMap::from_envmap(&map, 16, Sampler::Bilinear).unwrap();
        let mut pano = Panorama::map(map);
        assert_eq!(pano.kind(), PanoramaKind::Map);
        assert_eq!(pano.size(), (128, 64));
        assert!(pano.as_map().is_some() && pano.as_cube().is_none());
        let (got, report) = frame_of(&mut pano, view, &opts);
        assert_eq!((got, report), (want.clone(), direct));
        assert_eq!(report.path, RenderPath::LutWide);
        let mut shared = pano.share();
        assert_eq!(frame_of(&mut shared, view, &opts).0, want);

        for kind in [CubeRenderer::Basic, CubeRenderer::Accelerated] {
            let opts = RenderOptions { cube: kind, ..opts };
            let mut want = vec![0u32; 40 * 24];
            cube_frame(
                &cube,
                view,
                &opts,
                &mut Frame::new(&mut want, 40, 24).unwrap(),
                false,
            )
            .unwrap();
            let mut pano = Panorama::cube(cube.clone());
            assert_eq!(pano.kind(), PanoramaKind::Cube);
            assert!(pano.as_map().is_none() && pano.renderer_mut().is_none());
            let (got, report) = frame_of(&mut pano, view, &opts);
            assert_eq!(report.path, RenderPath::Cube(kind));
            assert_eq!(got, want);
            // The hook runs once on every row, cube or map.
            let rows = AtomicUsize::new(0);
            let hook = |y0: usize, band: &mut [u32]| {
                assert_eq!(y0 % HOOK_BAND_ROWS, 0);
                rows.fetch_add(band.len() / 40, Ordering::Relaxed);
            };
            let mut out = vec![0u32; 40 * 24];
            let mut f = Frame::new(&mut out, 40, 24).unwrap();
            pano.render_with(view, &opts, &mut f, &hook).unwrap();
            assert_eq!(rows.load(Ordering::Relaxed), 24);
            // A cube's error map is all zeros.
            let e = pano.error_map(view, &opts, 40, 24).unwrap();
            assert!(e.errors.iter().all(|e| e.is_none_or(|e| e == 0.0)));
            assert!(pano.error_map(view, &opts, 0, 24).is_err());
        }
    }

    /// A derived copy (a lit copy) shares the tables: its renderer builds none.
    #[test]
    fn derived_copies_share_the_tables() {
        let map = grid_map(256, 128, Projection::Equirect).unwrap();
        let mut pano = Panorama::map(map);
        pano.prepare(Surface::Cylinder, &mut |_| {});
        let wide = pano
            .renderer_mut()
            .and_then(|r| r.table(Surface::Cylinder, TableKind::Wide))
            .map(|t| t as *const _)
            .unwrap();
        let mut copy = pano
            .try_derive(|m| Ok::<_, ()>(m.clone()), |c| Ok(c.clone()))
            .unwrap();
        let copied = copy
            .renderer_mut()
            .and_then(|r| r.table(Surface::Cylinder, TableKind::Wide))
            .map(|t| t as *const _)
            .unwrap();
        assert_eq!(wide, copied, "the same table, not a copy");
        let n = pano.with_pixels(|m| m.width(), |c| c.face_size());
        assert_eq!(n, 256);
    }
}
