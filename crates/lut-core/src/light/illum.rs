//! The illuminance map: E computed once per lighting change over the room's faces, so a
//! frame only samples it (docs/lights.md, "Lighting at frame rate").
//!
//! Illuminance on the room's surfaces does not depend on the view. Each of the six faces
//! is cut into tiles of about half a metre; each tile holds a grid of nodes, corners
//! included, at a spacing chosen from the distance between the tile and the nearest
//! luminaire: E from a source at distance R varies on the scale of R (its inverse-square
//! and cosine falloff has a curvature about 3E/R² under the source), so bilinear
//! interpolation between nodes s apart is off by about (3/8)(s/R)² of E. The default
//! spacing 0.15 R, clamped to 5 mm … 30 mm, keeps that below 1 %, and a tile far from
//! every light costs a 13 × 13 grid. Nodes lie exactly on the faces and tiles end exactly
//! at the room's edges, so a frame that picks the face by the exact ray/box intersection
//! keeps the room's edges sharp: E is never interpolated across a corner.
//!
//! Building evaluates [`LightScene::illuminance`] (the per-pixel computation) at every
//! node, tiles in parallel on rayon; the result does not depend on the number of threads.

use super::room::{Room, RoomFace};
use super::shade::LightScene;
use super::LightError;
use glam::DVec3;
use rayon::prelude::*;

/// How finely [`IlluminanceMap::build`] samples the faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapOptions {
    /// Node spacing as a fraction of the distance from a tile to the nearest luminaire.
    pub relative_spacing: f64,
    /// The finest node spacing in metres (tiles right next to a light).
    pub min_spacing: f64,
    /// The coarsest node spacing in metres (tiles far from every light).
    pub max_spacing: f64,
    /// Tile side in metres (each face is cut into equal tiles no larger than this).
    pub tile: f64,
}

impl Default for MapOptions {
    fn default() -> Self {
        MapOptions {
            relative_spacing: 0.15,
            min_spacing: 0.005,
            max_spacing: 0.03,
            tile: 0.5,
        }
    }
}

impl MapOptions {
    /// A coarse map for immediate feedback while a light is being dragged (about a tenth
    /// of the nodes of the default), to be refined with the default options afterwards.
    pub fn preview() -> MapOptions {
        MapOptions {
            relative_spacing: 0.4,
            min_spacing: 0.02,
            max_spacing: 0.15,
            tile: 0.5,
        }
    }

    fn check(&self) -> Result<(), LightError> {
        for (name, value) in [
            ("map relative spacing", self.relative_spacing),
            ("map minimum spacing", self.min_spacing),
            ("map maximum spacing", self.max_spacing),
            ("map tile size", self.tile),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(LightError::BadOption {
                    name,
                    expected: "a positive number",
                    value,
                });
            }
        }
        if self.min_spacing > self.max_spacing {
            return Err(LightError::BadOption {
                name: "map minimum spacing",
                expected: "at most the maximum spacing",
                value: self.min_spacing,
            });
        }
        Ok(())
    }
}

/// One tile's grid of nodes.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tile {
    /// Nodes along u and v (≥ 2 each).
    pub(crate) nu: u32,
    pub(crate) nv: u32,
    /// Node intervals per metre: (nu − 1) / tile width, (nv − 1) / tile height.
    pub(crate) su: f32,
    pub(crate) sv: f32,
    /// Node spacing in metres (the larger of the two).
    pub(crate) spacing: f32,
    /// The longest straight stretch, in metres, over which E here (and in the
    /// neighbouring tiles) is linear within [`SPAN_TOLERANCE`]: frames interpolate E
    /// linearly between two points of the face at most this far apart.
    pub(crate) max_len: f32,
    /// First node in [`IlluminanceMap::values`], row-major (v rows of nu nodes).
    pub(crate) offset: u32,
}

/// One face: its place in the room and its tiles.
#[derive(Debug, Clone)]
pub(crate) struct FaceGrid {
    pub(crate) face: RoomFace,
    /// The face's axes in room coordinates, u and v.
    pub(crate) u_axis: usize,
    pub(crate) v_axis: usize,
    /// The face's low corner along u and v.
    pub(crate) u0: f64,
    pub(crate) v0: f64,
    /// The same relative to the camera.
    pub(crate) u0_rel: f64,
    pub(crate) v0_rel: f64,
    pub(crate) tiles_u: usize,
    pub(crate) tiles_v: usize,
    /// Tiles per metre along u and v.
    pub(crate) inv_tile_u: f64,
    pub(crate) inv_tile_v: f64,
    pub(crate) tile_u: f64,
    pub(crate) tile_v: f64,
    pub(crate) tiles: Vec<Tile>,
}

/// Illuminance (lux, lights only) over the six faces of a room, sampled on grids of
/// nodes; see the module docs.
#[derive(Debug, Clone)]
pub struct IlluminanceMap {
    room: Room,
    /// The box's low and high corners relative to the camera.
    pub(crate) rel_lo: DVec3,
    pub(crate) rel_hi: DVec3,
    pub(crate) faces: Vec<FaceGrid>,
    pub(crate) values: Vec<f32>,
}

impl IlluminanceMap {
    /// Compute the map of `scene` (every luminaire in it) with `opts`, tiles in parallel.
    ///
    /// # Errors
    /// [`LightError::BadOption`] for a non-positive or non-finite option, or a minimum
    /// spacing above the maximum.
    pub fn build(scene: &LightScene, opts: &MapOptions) -> Result<IlluminanceMap, LightError> {
        opts.check()?;
        let room = *scene.room();
        let (lo, hi) = room.bounds();
        // Per light: position, aim, the cosine of its lit cone, and the spacing per metre
        // of distance: the relative spacing, or half the file's finest angular step.
        let lights: Vec<(DVec3, DVec3, f64, f64)> = scene
            .luminaires()
            .iter()
            .filter(|l| l.multiplier > 0.0)
            .map(|l| {
                let step = 0.4 * l.table.finest_step_deg().to_radians();
                let cone = l.table.lit_cone_deg();
                (
                    l.position,
                    l.frame().2,
                    cone,
                    opts.relative_spacing.min(step),
                )
            })
            .collect();
        // The nodes' memory and the work (nodes × luminaires) are bounded whatever the
        // room's size (limits::MAX_ILLUM_NODES, MAX_ILLUM_WORK): past the budget the
        // tiles and spacings grow together until the map fits it.
        let budget = crate::geom::limits::MAX_ILLUM_NODES
            .min(crate::geom::limits::MAX_ILLUM_WORK / lights.len().max(1));
        let layout = |o: &MapOptions| -> (Vec<FaceGrid>, usize) {
            let mut faces = Vec::with_capacity(6);
            let mut total = 0usize;
            for face in RoomFace::ALL {
                let (ua, va) = face.plane_axes();
                let (size_u, size_v) = (hi[ua] - lo[ua], hi[va] - lo[va]);
                let tiles_u = (size_u / o.tile).ceil().max(1.0) as usize;
                let tiles_v = (size_v / o.tile).ceil().max(1.0) as usize;
                let (tile_u, tile_v) = (size_u / tiles_u as f64, size_v / tiles_v as f64);
                let plane = room.plane(face);
                // The lights that can reach this face: the directions toward its plane are the
                // half-space around −n; a lit cone of half-angle c around the aim misses it
                // when the aim is more than 90° + c from −n.
                let toward = -face.inward_normal();
                let reach: Vec<_> = lights
                    .iter()
                    .filter(|(_, aim, cone, _)| {
                        let angle = aim.dot(toward).clamp(-1.0, 1.0).acos().to_degrees();
                        angle < 90.0 + cone + 1.0
                    })
                    .collect();
                let mut tiles = Vec::with_capacity(tiles_u * tiles_v);
                for tv in 0..tiles_v {
                    for tu in 0..tiles_u {
                        let (a0, b0) = (lo[ua] + tu as f64 * tile_u, lo[va] + tv as f64 * tile_v);
                        // The distance from the tile's rectangle to each light that reaches
                        // the face, times that light's spacing per metre.
                        let s = reach
                            .iter()
                            .map(|(l, _, _, per_metre)| {
                                let du = l[ua] - l[ua].clamp(a0, a0 + tile_u);
                                let dv = l[va] - l[va].clamp(b0, b0 + tile_v);
                                let dn = l[face.axis()] - plane;
                                per_metre * (du * du + dv * dv + dn * dn).sqrt()
                            })
                            .fold(f64::INFINITY, f64::min)
                            .clamp(o.min_spacing, o.max_spacing);
                        let nu = (tile_u / s).ceil().max(1.0) as usize + 1;
                        let nv = (tile_v / s).ceil().max(1.0) as usize + 1;
                        let spacing = (tile_u / (nu - 1) as f64).max(tile_v / (nv - 1) as f64);
                        tiles.push(Tile {
                            nu: nu as u32,
                            nv: nv as u32,
                            su: ((nu - 1) as f64 / tile_u) as f32,
                            sv: ((nv - 1) as f64 / tile_v) as f32,
                            spacing: spacing as f32,
                            max_len: spacing as f32,
                            offset: total as u32,
                        });
                        total += nu * nv;
                    }
                }
                faces.push(FaceGrid {
                    face,
                    u_axis: ua,
                    v_axis: va,
                    u0: lo[ua],
                    v0: lo[va],
                    u0_rel: lo[ua] - room.camera_position()[ua],
                    v0_rel: lo[va] - room.camera_position()[va],
                    tiles_u,
                    tiles_v,
                    inv_tile_u: 1.0 / tile_u,
                    inv_tile_v: 1.0 / tile_v,
                    tile_u,
                    tile_v,
                    tiles,
                });
            }
            (faces, total)
        };
        let mut o = *opts;
        let (mut faces, total) = loop {
            let (faces, total) = layout(&o);
            if total <= budget {
                break (faces, total);
            }
            let grow = ((total as f64 / budget as f64).sqrt() * 1.05).max(1.05);
            o.tile *= grow;
            o.min_spacing *= grow;
            o.max_spacing *= grow;
        };
        // Split the values into one slice per tile, then fill the tiles in parallel.
        let mut values = vec![0f32; total];
        let mut jobs = Vec::new();
        let mut rest: &mut [f32] = &mut values;
        for f in &faces {
            for (i, t) in f.tiles.iter().enumerate() {
                let (mine, tail) = rest.split_at_mut((t.nu * t.nv) as usize);
                rest = tail;
                jobs.push((f, i % f.tiles_u, i / f.tiles_u, *t, mine));
            }
        }
        jobs.into_par_iter().for_each(|(f, tu, tv, t, out)| {
            let n = f.face.inward_normal();
            let mut p = DVec3::ZERO;
            p[f.face.axis()] = room.plane(f.face);
            let a0 = f.u0 + tu as f64 * f.tile_u;
            let b0 = f.v0 + tv as f64 * f.tile_v;
            let (nu, nv) = (t.nu as usize, t.nv as usize);
            for j in 0..nv {
                // The last node sits exactly on the tile's (and at the end the face's) edge.
                p[f.v_axis] = if j + 1 == nv {
                    b0 + f.tile_v
                } else {
                    b0 + j as f64 * f.tile_v / (nv - 1) as f64
                };
                for i in 0..nu {
                    p[f.u_axis] = if i + 1 == nu {
                        a0 + f.tile_u
                    } else {
                        a0 + i as f64 * f.tile_u / (nu - 1) as f64
                    };
                    out[j * nu + i] = scene.illuminance(p, n) as f32;
                }
            }
        });
        for f in &mut faces {
            f.set_max_len(&values);
        }
        let o = room.camera_position();
        Ok(IlluminanceMap {
            room,
            rel_lo: lo - o,
            rel_hi: hi - o,
            faces,
            values,
        })
    }

    /// The room the map covers.
    pub fn room(&self) -> &Room {
        &self.room
    }

    /// Number of nodes (stored values).
    pub fn nodes(&self) -> usize {
        self.values.len()
    }

    /// Memory held by the values and the tile records, in bytes.
    pub fn bytes(&self) -> usize {
        self.values.len() * std::mem::size_of::<f32>()
            + self
                .faces
                .iter()
                .map(|f| f.tiles.len() * std::mem::size_of::<Tile>())
                .sum::<usize>()
    }

    /// Node spacing range (finest, coarsest) in metres.
    pub fn spacing_range(&self) -> (f64, f64) {
        self.faces
            .iter()
            .flat_map(|f| f.tiles.iter().map(|t| t.spacing as f64))
            .fold((f64::INFINITY, 0.0), |(a, b), s| (a.min(s), b.max(s)))
    }

    /// Interpolated illuminance in lux at point `p` (room coordinates) of `face`; the
    /// point is clamped onto the face.
    pub fn illuminance_at(&self, face: RoomFace, p: DVec3) -> f64 {
        let f = &self.faces[face.index()];
        let (e, _) = f.sample(&self.values, p[f.u_axis] - f.u0, p[f.v_axis] - f.v0);
        e as f64
    }

    /// Interpolated illuminance where the panorama direction `dir` (the camera's world
    /// frame) meets the room, as [`super::lux_at`] computes it exactly.
    pub fn illuminance_toward(&self, dir: DVec3) -> f64 {
        let (p, face) = self
            .room
            .hit_face(self.room.camera_position(), self.room.to_room(dir));
        self.illuminance_at(face, p)
    }

    /// The area-weighted `q`-quantile (0..=1) of the illuminance over all faces (each
    /// node weighted by the area of its share of its tile): e.g. 0.95 gives the lux that
    /// 95 % of the room's surface stays below.
    pub fn quantile(&self, q: f64) -> f64 {
        let mut pairs: Vec<(f32, f64)> = Vec::with_capacity(self.values.len());
        for f in &self.faces {
            let cell = f.tile_u * f.tile_v;
            for t in &f.tiles {
                let w = cell / (t.nu * t.nv) as f64;
                let vals = &self.values[t.offset as usize..(t.offset + t.nu * t.nv) as usize];
                pairs.extend(vals.iter().map(|&e| (e, w)));
            }
        }
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let total: f64 = pairs.iter().map(|p| p.1).sum();
        let target = q.clamp(0.0, 1.0) * total;
        let mut acc = 0.0;
        for (e, w) in &pairs {
            acc += w;
            if acc >= target {
                return *e as f64;
            }
        }
        pairs.last().map_or(0.0, |p| p.0 as f64)
    }
}

/// How far linear interpolation of E across a frame's block may stray from the map, by
/// the curvature bound: 5 % of the largest E in the tile, plus 10 mlx. (The bound is
/// pessimistic: it takes the worst second difference of the tile in every direction;
/// the errors measured against the per-pixel computation are far smaller, see
/// `tests/illum_map.rs`.)
pub const SPAN_TOLERANCE: (f64, f64) = (0.05, 0.01);

impl FaceGrid {
    /// Each tile's [`Tile::max_len`]: from the largest second derivative of E over its
    /// nodes (second differences, |E_uu| + 2|E_uv| + |E_vv|, which bounds the second
    /// derivative along any direction), linear interpolation over a length L is off by at
    /// most L²/8 times it; L is kept between one node spacing and a quarter tile, and each
    /// tile takes the smallest L of its 3 × 3 neighbourhood, so a stretch starting in a
    /// tile stays within tiles that allow it.
    fn set_max_len(&mut self, values: &[f32]) {
        let own: Vec<f32> = self
            .tiles
            .iter()
            .map(|t| {
                let (nu, nv) = (t.nu as usize, t.nv as usize);
                let v = &values[t.offset as usize..t.offset as usize + nu * nv];
                let at = |i: usize, j: usize| v[j * nu + i] as f64;
                let du = self.tile_u / (nu - 1) as f64;
                let dv = self.tile_v / (nv - 1) as f64;
                let mut curv: f64 = 0.0;
                let mut emax: f64 = 0.0;
                for j in 0..nv {
                    for i in 0..nu {
                        emax = emax.max(at(i, j));
                        let (il, ih) = (i.saturating_sub(1), (i + 1).min(nu - 1));
                        let (jl, jh) = (j.saturating_sub(1), (j + 1).min(nv - 1));
                        let uu = if ih - il == 2 {
                            (at(ih, j) - 2.0 * at(i, j) + at(il, j)).abs() / (du * du)
                        } else {
                            0.0
                        };
                        let vv = if jh - jl == 2 {
                            (at(i, jh) - 2.0 * at(i, j) + at(i, jl)).abs() / (dv * dv)
                        } else {
                            0.0
                        };
                        let uv = (at(ih, jh) - at(ih, jl) - at(il, jh) + at(il, jl)).abs()
                            / ((ih - il) as f64 * du * (jh - jl) as f64 * dv).max(1e-12);
                        curv = curv.max(uu + 2.0 * uv + vv);
                    }
                }
                let tol = SPAN_TOLERANCE.0 * emax + SPAN_TOLERANCE.1;
                let len = if curv > 0.0 {
                    (8.0 * tol / curv).sqrt()
                } else {
                    f64::INFINITY
                };
                let quarter = 0.25 * self.tile_u.min(self.tile_v);
                len.min(quarter) as f32
            })
            .collect();
        let (tu, tv) = (self.tiles_u, self.tiles_v);
        for j in 0..tv {
            for i in 0..tu {
                let mut m = f32::INFINITY;
                for jj in j.saturating_sub(1)..(j + 2).min(tv) {
                    for ii in i.saturating_sub(1)..(i + 2).min(tu) {
                        m = m.min(own[jj * tu + ii]);
                    }
                }
                self.tiles[j * tu + i].max_len = m;
            }
        }
    }

    /// Bilinear illuminance at face-local (u, v) metres from the face's low corner
    /// (clamped onto the face), and the tile's [`Tile::max_len`].
    #[inline]
    pub(crate) fn sample(&self, values: &[f32], u: f64, v: f64) -> (f32, f32) {
        // Conversions go through i32 (one instruction plus a saturation check; to usize
        // costs several times that); min/max rather than clamp (no assertion).
        let tu = (((u * self.inv_tile_u) as i32).min(self.tiles_u as i32 - 1)).max(0) as usize;
        let tv = (((v * self.inv_tile_v) as i32).min(self.tiles_v as i32 - 1)).max(0) as usize;
        let t = &self.tiles[tv * self.tiles_u + tu];
        let (nu, nv) = (t.nu as usize, t.nv as usize);
        // Node coordinates in the tile, clamped onto it.
        let lu = (((u - tu as f64 * self.tile_u) as f32) * t.su)
            .max(0.0)
            .min((nu - 1) as f32);
        let lv = (((v - tv as f64 * self.tile_v) as f32) * t.sv)
            .max(0.0)
            .min((nv - 1) as f32);
        let i = (lu as i32).min(nu as i32 - 2) as usize;
        let j = (lv as i32).min(nv as i32 - 2) as usize;
        let fu = lu - i as f32;
        let fv = lv - j as f32;
        let base = t.offset as usize + j * nu + i;
        let row0 = &values[base..base + 2];
        let row1 = &values[base + nu..base + nu + 2];
        let a = row0[0] + (row0[1] - row0[0]) * fu;
        let b = row1[0] + (row1[1] - row1[0]) * fu;
        (a + (b - a) * fv, t.max_len)
    }
}
