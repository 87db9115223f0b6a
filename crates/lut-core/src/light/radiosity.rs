//! Inter-reflections in the box room: radiosity over patches of the six faces.
//!
//! Each face has a diffuse reflectance ρ ([`Reflectances`]: floor, walls, ceiling). The
//! faces are cut into rectangular patches of about equal size (about [`DEFAULT_PATCHES`]
//! in all, at most [`MAX_PATCHES`]). The form factor F_ij (the fraction of the light
//! leaving patch i that reaches patch j) between two axis-aligned rectangles of a box has
//! a closed form: for rectangles in parallel planes and for rectangles in perpendicular
//! planes (Howell's catalogue of configuration factors, "rectangle to rectangle" in
//! parallel and perpendicular planes, general position: a sum of 16 values of one
//! primitive function); patches of one face see nothing of each other. In a closed box
//! every row sums to 1 and A_i F_ij = A_j F_ji (tested).
//!
//! The direct light: the illuminance of [`LightScene::direct`] averaged over each patch
//! (midpoint rule on sub-cells no larger than 7 % of the patch's distance from the
//! nearest luminaire, so a patch right by a light is sampled finely and the flux onto the
//! faces adds up to the luminaires' flux within about 0.1 %). The exitance B_i of each
//! patch then satisfies B_i = ρ_i (E_i + Σ_j F_ij B_j), solved by Gauss-Seidel iteration
//! (it converges for every ρ < 1, as ρ^k; 1 would never converge, so it is refused).
//!
//! The indirect illuminance at a point p with normal n is Σ_j B_j F(p → j), the point-to-
//! patch form factor by Lambert's contour formula, exact for a polygon: each patch is
//! clipped to the half-space in front of the point and F = |Σ_edges θ_k n·ĝ_k| / 2π
//! ([`Radiosity::indirect_at`]). For the illuminance map (millions of points on the faces)
//! [`Radiosity::indirect_on_face`] interpolates the patches' mean indirect illuminance
//! Σ_j F_ij B_j bilinearly between patch centres (held constant in the half patch along
//! the edges), which keeps every face's mean exactly.
//!
//! Form factors depend only on the box (not the lights), so the last set computed is kept
//! and reused while only the lights change.

use super::room::{Room, RoomFace};
use super::LightError;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};

/// About this many patches over the whole box by default.
pub const DEFAULT_PATCHES: usize = 600;
/// The most patches a solve may use (its form-factor matrix holds the square of this).
pub const MAX_PATCHES: usize = 2500;
/// Gauss-Seidel iterations before giving up (reached only for ρ very close to 1).
const MAX_ITERATIONS: usize = 20_000;

/// The diffuse reflectances of the room's surfaces, each in [0, 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reflectances {
    /// The floor.
    pub floor: f64,
    /// The four walls.
    pub walls: f64,
    /// The ceiling.
    pub ceiling: f64,
}

impl Default for Reflectances {
    /// Floor 0.2, walls 0.5, ceiling 0.7 (EN 12464-1's usual ranges: floor 0.2–0.4,
    /// walls 0.5–0.8, ceiling 0.7–0.9; their lower ends).
    fn default() -> Self {
        Reflectances {
            floor: 0.2,
            walls: 0.5,
            ceiling: 0.7,
        }
    }
}

impl Reflectances {
    /// All surfaces black: direct light only.
    pub const ZERO: Reflectances = Reflectances {
        floor: 0.0,
        walls: 0.0,
        ceiling: 0.0,
    };

    /// The same reflectance everywhere.
    pub fn uniform(rho: f64) -> Reflectances {
        Reflectances {
            floor: rho,
            walls: rho,
            ceiling: rho,
        }
    }

    /// The reflectance of `face`.
    pub fn of(&self, face: RoomFace) -> f64 {
        match face {
            RoomFace::Floor => self.floor,
            RoomFace::Ceiling => self.ceiling,
            _ => self.walls,
        }
    }

    /// Whether every surface is black.
    pub fn is_zero(&self) -> bool {
        self.floor == 0.0 && self.walls == 0.0 && self.ceiling == 0.0
    }

    /// Check each value is in [0, 1).
    ///
    /// # Errors
    /// [`LightError::BadOption`] naming the surface.
    pub fn check(&self) -> Result<(), LightError> {
        for (name, value) in [
            ("floor reflectance", self.floor),
            ("wall reflectance", self.walls),
            ("ceiling reflectance", self.ceiling),
        ] {
            if !(value.is_finite() && (0.0..1.0).contains(&value)) {
                return Err(LightError::BadOption {
                    name,
                    expected: "a number in [0, 1) (a reflectance of 1 would reflect light \
                               forever: the inter-reflections never converge)",
                    value,
                });
            }
        }
        Ok(())
    }
}

/// One patch: a rectangle of a face, `u` and `v` its ranges along the face's
/// [`RoomFace::plane_axes`], room coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Patch {
    /// The face it lies on.
    pub face: RoomFace,
    /// Its range along the face's first axis.
    pub u: [f64; 2],
    /// Its range along the face's second axis.
    pub v: [f64; 2],
    /// The plane's coordinate along the face's axis.
    pub plane: f64,
}

impl Patch {
    /// Area in m².
    pub fn area(&self) -> f64 {
        (self.u[1] - self.u[0]) * (self.v[1] - self.v[0])
    }

    /// The point of the face at (`a`, `b`) along its axes.
    fn point(&self, a: f64, b: f64) -> DVec3 {
        let (ua, va) = self.face.plane_axes();
        let mut p = DVec3::ZERO;
        p[self.face.axis()] = self.plane;
        p[ua] = a;
        p[va] = b;
        p
    }

    /// The centre.
    pub fn center(&self) -> DVec3 {
        self.point(0.5 * (self.u[0] + self.u[1]), 0.5 * (self.v[0] + self.v[1]))
    }

    /// The four corners in order round the rectangle.
    fn corners(&self) -> [DVec3; 4] {
        [
            self.point(self.u[0], self.v[0]),
            self.point(self.u[1], self.v[0]),
            self.point(self.u[1], self.v[1]),
            self.point(self.u[0], self.v[1]),
        ]
    }
}

/// How one face is cut: `nu × nv` patches from `offset` in the patch list, row-major
/// (v rows of nu).
#[derive(Debug, Clone, Copy, PartialEq)]
struct FaceCut {
    nu: usize,
    nv: usize,
    offset: usize,
    u0: f64,
    v0: f64,
    du: f64,
    dv: f64,
}

/// The patches of a box and their form factors.
#[derive(Debug)]
pub struct FormFactors {
    lo: DVec3,
    hi: DVec3,
    target: usize,
    patches: Vec<Patch>,
    cuts: [FaceCut; 6],
    /// F_ij row-major.
    f: Vec<f64>,
}

/// The primitive of the parallel-rectangle form factor (u, w the offsets along the
/// planes, z their distance), times 2π.
fn g_parallel(u: f64, w: f64, z: f64) -> f64 {
    let a = (w * w + z * z).sqrt();
    let b = (u * u + z * z).sqrt();
    let r2 = u * u + w * w + z * z;
    let mut g = 0.0;
    if a > 0.0 {
        g += u * a * (u / a).atan();
    }
    if b > 0.0 {
        g += w * b * (w / b).atan();
    }
    if r2 > 0.0 {
        g -= 0.5 * z * z * r2.ln();
    }
    g
}

/// The primitive of the perpendicular-rectangle form factor (u the offset along the
/// common direction, y and e the distances from the planes' common line), times 2π.
fn g_perpendicular(u: f64, y: f64, e: f64) -> f64 {
    let s2 = y * y + e * e;
    let s = s2.sqrt();
    let r2 = u * u + s2;
    let mut g = 0.0;
    if s > 0.0 {
        g += u * s * (u / s).atan();
    }
    if r2 > 0.0 {
        g += 0.25 * (u * u - s2) * r2.ln();
    }
    g
}

/// A_i F_ij between two patches of the box (0 on one face).
fn area_form_factor(a: &Patch, b: &Patch) -> f64 {
    let (fa, fb) = (a.face, b.face);
    if fa == fb {
        return 0.0;
    }
    let mut t = 0.0;
    if fa.axis() == fb.axis() {
        // Parallel: the same plane axes.
        let z = (a.plane - b.plane).abs();
        for (i, x) in a.u.iter().enumerate() {
            for (j, y) in a.v.iter().enumerate() {
                for (k, xi) in b.u.iter().enumerate() {
                    for (l, eta) in b.v.iter().enumerate() {
                        let sign = if (i + j + k + l) % 2 == 0 { 1.0 } else { -1.0 };
                        t += sign * g_parallel(x - xi, y - eta, z);
                    }
                }
            }
        }
    } else {
        // Perpendicular: the common direction s is the axis neither face is normal to;
        // a spans s and b's normal axis, b spans s and a's normal axis.
        let (aa, ba) = (fa.axis(), fb.axis());
        let s = 3 - aa - ba;
        let range = |p: &Patch, axis: usize| -> [f64; 2] {
            let (ua, _) = p.face.plane_axes();
            if ua == axis {
                p.u
            } else {
                p.v
            }
        };
        let (xs, ys) = (range(a, s), range(a, ba));
        let (xis, es) = (range(b, s), range(b, aa));
        // Distances from the common line (a's plane meets b's plane).
        let ys = ys.map(|y| (y - b.plane).abs());
        let es = es.map(|e| (e - a.plane).abs());
        for (i, x) in xs.iter().enumerate() {
            for (j, y) in ys.iter().enumerate() {
                for (k, xi) in xis.iter().enumerate() {
                    for (l, e) in es.iter().enumerate() {
                        let sign = if (i + j + k + l) % 2 == 0 { 1.0 } else { -1.0 };
                        t += sign * g_perpendicular(x - xi, *y, *e);
                    }
                }
            }
        }
        // The distances were folded with abs: a range that runs away from the common
        // line reversed the order of its ends, which flips the sign.
        t = t.abs();
    }
    (t / (2.0 * PI)).max(0.0)
}

fn ff_cache() -> &'static Mutex<Option<Arc<FormFactors>>> {
    static CACHE: Mutex<Option<Arc<FormFactors>>> = Mutex::new(None);
    &CACHE
}

impl FormFactors {
    /// The patches of `room`'s faces (about `target` in all, each face cut into equal
    /// patches as close to square as the face allows) and their form factors, computed
    /// in parallel; the last set is kept and returned again for the same box and target.
    ///
    /// # Errors
    /// [`LightError::TooMany`] when the cut needs more than [`MAX_PATCHES`] patches
    /// (`target` too large), [`LightError::BadOption`] for a zero target.
    pub fn for_room(room: &Room, target: usize) -> Result<Arc<FormFactors>, LightError> {
        let (lo, hi) = room.bounds();
        {
            let cache = ff_cache().lock().unwrap_or_else(|e| e.into_inner());
            if let Some(ff) = cache.as_ref() {
                if ff.lo == lo && ff.hi == hi && ff.target == target {
                    return Ok(ff.clone());
                }
            }
        }
        let ff = Arc::new(FormFactors::new(room, target)?);
        *ff_cache().lock().unwrap_or_else(|e| e.into_inner()) = Some(ff.clone());
        Ok(ff)
    }

    /// As [`FormFactors::for_room`], without the cache.
    ///
    /// # Errors
    /// As [`FormFactors::for_room`].
    pub fn new(room: &Room, target: usize) -> Result<FormFactors, LightError> {
        if target == 0 {
            return Err(LightError::BadOption {
                name: "patch count",
                expected: "at least 1",
                value: 0.0,
            });
        }
        let (lo, hi) = room.bounds();
        let size = hi - lo;
        let surface = 2.0 * (size.x * size.y + size.y * size.z + size.x * size.z);
        let side = (surface / target as f64).sqrt();
        let mut patches = Vec::new();
        let mut cuts = [FaceCut {
            nu: 0,
            nv: 0,
            offset: 0,
            u0: 0.0,
            v0: 0.0,
            du: 0.0,
            dv: 0.0,
        }; 6];
        for face in RoomFace::ALL {
            let (ua, va) = face.plane_axes();
            let (su, sv) = (size[ua], size[va]);
            let nu = (su / side).round().max(1.0);
            let nv = (sv / side).round().max(1.0);
            let count = nu * nv + patches.len() as f64;
            if count > MAX_PATCHES as f64 {
                return Err(LightError::TooMany {
                    what: "radiosity patches",
                    count: count.min(usize::MAX as f64) as usize,
                    max: MAX_PATCHES,
                });
            }
            let (nu, nv) = (nu as usize, nv as usize);
            let (du, dv) = (su / nu as f64, sv / nv as f64);
            cuts[face.index()] = FaceCut {
                nu,
                nv,
                offset: patches.len(),
                u0: lo[ua],
                v0: lo[va],
                du,
                dv,
            };
            let plane = room.plane(face);
            for j in 0..nv {
                for i in 0..nu {
                    let (a0, b0) = (lo[ua] + i as f64 * du, lo[va] + j as f64 * dv);
                    // The last patch ends exactly on the edge.
                    let a1 = if i + 1 == nu { hi[ua] } else { a0 + du };
                    let b1 = if j + 1 == nv { hi[va] } else { b0 + dv };
                    patches.push(Patch {
                        face,
                        u: [a0, a1],
                        v: [b0, b1],
                        plane,
                    });
                }
            }
        }
        let n = patches.len();
        // A_i F_ij for i < j, then both entries by reciprocity.
        let rows: Vec<Vec<f64>> = (0..n)
            .into_par_iter()
            .map(|i| {
                (i + 1..n)
                    .map(|j| area_form_factor(&patches[i], &patches[j]))
                    .collect()
            })
            .collect();
        let mut f = vec![0.0; n * n];
        for (i, row) in rows.iter().enumerate() {
            let ai = patches[i].area();
            for (k, &af) in row.iter().enumerate() {
                let j = i + 1 + k;
                f[i * n + j] = af / ai;
                f[j * n + i] = af / patches[j].area();
            }
        }
        Ok(FormFactors {
            lo,
            hi,
            target,
            patches,
            cuts,
            f,
        })
    }

    /// The patches.
    pub fn patches(&self) -> &[Patch] {
        &self.patches
    }

    /// How many patches.
    pub fn len(&self) -> usize {
        self.patches.len()
    }

    /// Whether there is no patch (never: every face has one at least).
    pub fn is_empty(&self) -> bool {
        self.patches.is_empty()
    }

    /// F_ij: the fraction of the light leaving patch i that reaches patch j.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.f[i * self.patches.len() + j]
    }

    /// The patches of `face` as (first index, count along u, count along v).
    pub fn face_patches(&self, face: RoomFace) -> (usize, usize, usize) {
        let c = &self.cuts[face.index()];
        (c.offset, c.nu, c.nv)
    }
}

/// The inter-reflected light of a lit room: each patch's direct illuminance, exitance and
/// indirect illuminance.
#[derive(Debug, Clone)]
pub struct Radiosity {
    ff: Arc<FormFactors>,
    reflectances: Reflectances,
    /// Mean direct illuminance per patch, lux.
    direct: Vec<f64>,
    /// Exitance of the reflected light per patch, lm/m².
    exitance: Vec<f64>,
    /// Mean indirect illuminance per patch, lux (Σ_j F_ij B_j).
    indirect: Vec<f64>,
    iterations: usize,
}

/// A light source the radiosity solve gathers from: the room it lights, its direct
/// illuminance at any point, and the luminaires' positions (to size the sub-cells that
/// average it over a patch). [`super::LightScene`] is one; the solve names only this
/// trait, so the scene can hold its solve without the two files importing each other.
pub trait DirectLight: Sync {
    /// The room whose surfaces reflect.
    fn room(&self) -> &Room;
    /// The direct illuminance (lx) at `p` on a surface with unit normal `n`.
    fn direct(&self, p: DVec3, n: DVec3) -> f64;
    /// The positions (m) of the luminaires that give light (multiplier above 0).
    fn lit_positions(&self) -> Vec<DVec3>;
    /// What identifies the lighting for the solve's cache: per luminaire its table's
    /// identity, position, yaw, pitch and multiplier.
    fn cache_key(&self) -> Vec<(usize, [f64; 3], f64, f64, f64)>;
}

/// The mean of `scene`'s direct illuminance over `p`, by the midpoint rule on sub-cells
/// at most 7 % of the patch's distance from the nearest luminaire.
fn patch_direct<S: DirectLight + ?Sized>(scene: &S, p: &Patch) -> f64 {
    let (ua, va) = p.face.plane_axes();
    let axis = p.face.axis();
    let n = p.face.inward_normal();
    let mut dmin = f64::INFINITY;
    for q in scene.lit_positions() {
        if n.dot(q) - n[axis] * p.plane <= 0.0 {
            continue; // behind or on the patch's plane: no light reaches it
        }
        let du = q[ua] - q[ua].clamp(p.u[0], p.u[1]);
        let dv = q[va] - q[va].clamp(p.v[0], p.v[1]);
        let dn = q[axis] - p.plane;
        dmin = dmin.min((du * du + dv * dv + dn * dn).sqrt());
    }
    if !dmin.is_finite() {
        return 0.0;
    }
    let h = (0.07 * dmin).max(1e-4);
    let (su, sv) = (p.u[1] - p.u[0], p.v[1] - p.v[0]);
    let nu = (su / h).ceil().clamp(2.0, 192.0) as usize;
    let nv = (sv / h).ceil().clamp(2.0, 192.0) as usize;
    let (hu, hv) = (su / nu as f64, sv / nv as f64);
    let mut sum = 0.0;
    for j in 0..nv {
        let b = p.v[0] + (j as f64 + 0.5) * hv;
        for i in 0..nu {
            let a = p.u[0] + (i as f64 + 0.5) * hu;
            sum += scene.direct(p.point(a, b), n);
        }
    }
    sum / (nu * nv) as f64
}

/// The form factor from a point `p` with unit normal `n` to the convex polygon `poly`
/// (Lambert's contour formula on the part in front of the point's plane).
fn point_polygon_ff(p: DVec3, n: DVec3, poly: &[DVec3; 4]) -> f64 {
    // Clip to n·(x − p) ≥ 0 (Sutherland–Hodgman against one plane).
    let mut clipped = [DVec3::ZERO; 8];
    let mut m = 0;
    let d: [f64; 4] = std::array::from_fn(|k| n.dot(poly[k] - p));
    if d.iter().all(|&x| x <= 1e-12) {
        return 0.0;
    }
    for k in 0..4 {
        let (a, b) = (poly[k], poly[(k + 1) % 4]);
        let (da, db) = (d[k], d[(k + 1) % 4]);
        if da >= 0.0 {
            clipped[m] = a;
            m += 1;
        }
        if (da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0) {
            clipped[m] = a + (b - a) * (da / (da - db));
            m += 1;
        }
    }
    let mut sum = 0.0;
    for k in 0..m {
        let a = clipped[k] - p;
        let b = clipped[(k + 1) % m] - p;
        let (la, lb) = (a.length(), b.length());
        if la < 1e-12 || lb < 1e-12 {
            continue;
        }
        let (a, b) = (a / la, b / lb);
        let c = a.cross(b);
        let lc = c.length();
        if lc < 1e-15 {
            continue;
        }
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        sum += theta * n.dot(c) / lc;
    }
    sum.abs() / (2.0 * PI)
}

impl Radiosity {
    /// Solve the inter-reflections of `scene`'s luminaires in its room with
    /// `reflectances`, on about [`DEFAULT_PATCHES`] patches.
    ///
    /// # Errors
    /// [`LightError::BadOption`] for a reflectance outside [0, 1).
    pub fn solve<S: DirectLight + ?Sized>(
        scene: &S,
        reflectances: Reflectances,
    ) -> Result<Radiosity, LightError> {
        Radiosity::solve_with(scene, reflectances, DEFAULT_PATCHES)
    }

    /// [`Radiosity::solve`] on about `patches` patches.
    ///
    /// # Errors
    /// As [`Radiosity::solve`], and [`LightError::TooMany`] beyond [`MAX_PATCHES`].
    pub fn solve_with<S: DirectLight + ?Sized>(
        scene: &S,
        reflectances: Reflectances,
        patches: usize,
    ) -> Result<Radiosity, LightError> {
        reflectances.check()?;
        let ff = FormFactors::for_room(scene.room(), patches)?;
        let n = ff.len();
        let direct: Vec<f64> = ff
            .patches
            .par_iter()
            .map(|p| patch_direct(scene, p))
            .collect();
        let rho: Vec<f64> = ff.patches.iter().map(|p| reflectances.of(p.face)).collect();
        let mut b: Vec<f64> = (0..n).map(|i| rho[i] * direct[i]).collect();
        let mut iterations = 0;
        if !reflectances.is_zero() {
            let scale = b.iter().fold(0.0f64, |m, &x| m.max(x));
            while iterations < MAX_ITERATIONS {
                iterations += 1;
                let mut change = 0.0f64;
                for i in 0..n {
                    if rho[i] == 0.0 {
                        continue;
                    }
                    let row = &ff.f[i * n..(i + 1) * n];
                    let gathered: f64 = row.iter().zip(&b).map(|(f, b)| f * b).sum();
                    let new = rho[i] * (direct[i] + gathered);
                    change = change.max((new - b[i]).abs());
                    b[i] = new;
                }
                if change <= 1e-10 * scale.max(1e-300) {
                    break;
                }
            }
        }
        let indirect: Vec<f64> = (0..n)
            .into_par_iter()
            .map(|i| {
                ff.f[i * n..(i + 1) * n]
                    .iter()
                    .zip(&b)
                    .map(|(f, b)| f * b)
                    .sum()
            })
            .collect();
        Ok(Radiosity {
            ff,
            reflectances,
            direct,
            exitance: b,
            indirect,
            iterations,
        })
    }

    /// [`Radiosity::solve`], reusing the last solve when the room, the luminaires (their
    /// tables, positions, aims and multipliers) and the reflectances are the same: a
    /// window asks for the scene every frame (the lux at the cursor) and solves only when
    /// the lighting changes.
    ///
    /// # Errors
    /// As [`Radiosity::solve`].
    pub fn solve_cached<S: DirectLight + ?Sized>(
        scene: &S,
        reflectances: Reflectances,
    ) -> Result<Arc<Radiosity>, LightError> {
        type Key = (Vec<(usize, [f64; 3], f64, f64, f64)>, [f64; 6], [f64; 3]);
        static SOLVED: Mutex<Option<(Key, Arc<Radiosity>)>> = Mutex::new(None);
        let (lo, hi) = scene.room().bounds();
        let key: Key = (
            scene.cache_key(),
            [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z],
            [reflectances.floor, reflectances.walls, reflectances.ceiling],
        );
        if let Some((k, r)) = SOLVED.lock().unwrap_or_else(|e| e.into_inner()).as_ref() {
            if *k == key {
                return Ok(r.clone());
            }
        }
        let r = Arc::new(Radiosity::solve(scene, reflectances)?);
        *SOLVED.lock().unwrap_or_else(|e| e.into_inner()) = Some((key, r.clone()));
        Ok(r)
    }

    /// The reflectances solved with.
    pub fn reflectances(&self) -> Reflectances {
        self.reflectances
    }

    /// The patches and their form factors.
    pub fn form_factors(&self) -> &FormFactors {
        &self.ff
    }

    /// Mean direct illuminance of each patch, lux.
    pub fn patch_direct(&self) -> &[f64] {
        &self.direct
    }

    /// Exitance (reflected light leaving) of each patch, lm/m².
    pub fn patch_exitance(&self) -> &[f64] {
        &self.exitance
    }

    /// Mean indirect illuminance of each patch, lux.
    pub fn patch_indirect(&self) -> &[f64] {
        &self.indirect
    }

    /// Gauss-Seidel sweeps the solve took.
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// The direct flux onto all faces, lm (Σ A_i E_i).
    pub fn direct_flux(&self) -> f64 {
        self.ff
            .patches
            .iter()
            .zip(&self.direct)
            .map(|(p, e)| p.area() * e)
            .sum()
    }

    /// The exact indirect illuminance at `p` (room coordinates, inside the box) on a
    /// surface with unit normal `n`: Σ_j B_j F(p → patch j).
    pub fn indirect_at(&self, p: DVec3, n: DVec3) -> f64 {
        self.ff
            .patches
            .iter()
            .zip(&self.exitance)
            .filter(|(_, &b)| b > 0.0)
            .map(|(patch, &b)| b * point_polygon_ff(p, n, &patch.corners()))
            .sum()
    }

    /// The indirect illuminance at point `p` of `face`, interpolated bilinearly between
    /// the patches' mean indirect illuminance at their centres (constant in the half
    /// patch along the face's edges): fast, for the illuminance map.
    #[inline]
    pub fn indirect_on_face(&self, face: RoomFace, p: DVec3) -> f64 {
        let c = &self.ff.cuts[face.index()];
        let (ua, va) = face.plane_axes();
        let locate = |x: f64, x0: f64, dx: f64, n: usize| -> (usize, usize, f64) {
            let t = ((x - x0) / dx - 0.5).clamp(0.0, (n - 1) as f64);
            let i = (t as usize).min(n - 1);
            let j = (i + 1).min(n - 1);
            (i, j, t - i as f64)
        };
        let (i0, i1, fu) = locate(p[ua], c.u0, c.du, c.nu);
        let (j0, j1, fv) = locate(p[va], c.v0, c.dv, c.nv);
        let at = |i: usize, j: usize| self.indirect[c.offset + j * c.nu + i];
        let top = at(i0, j0) + (at(i1, j0) - at(i0, j0)) * fu;
        let bottom = at(i0, j1) + (at(i1, j1) - at(i0, j1)) * fu;
        top + (bottom - top) * fv
    }

    /// The indirect illuminance for the illuminance map: [`Radiosity::indirect_on_face`]
    /// when `p` lies on a face and `n` is its inward normal, else
    /// [`Radiosity::indirect_at`].
    #[inline]
    pub fn indirect_fast(&self, p: DVec3, n: DVec3) -> f64 {
        for face in RoomFace::ALL {
            let a = face.axis();
            if n[a] == face.inward_normal()[a] && n.length_squared() == 1.0 {
                let plane = if face.is_high() {
                    self.ff.hi[a]
                } else {
                    self.ff.lo[a]
                };
                if (p[a] - plane).abs() <= 1e-9 {
                    return self.indirect_on_face(face, p);
                }
            }
        }
        self.indirect_at(p, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(a: &Patch, b: &Patch, n: usize) -> f64 {
        // Brute-force midpoint quadrature of A_a F_ab.
        let mut s = 0.0;
        let (na, nb) = (a.face.inward_normal(), b.face.inward_normal());
        let cell = |p: &Patch, i: usize, j: usize| {
            let (hu, hv) = ((p.u[1] - p.u[0]) / n as f64, (p.v[1] - p.v[0]) / n as f64);
            (
                p.point(
                    p.u[0] + (i as f64 + 0.5) * hu,
                    p.v[0] + (j as f64 + 0.5) * hv,
                ),
                hu * hv,
            )
        };
        for i in 0..n {
            for j in 0..n {
                let (x, da) = cell(a, i, j);
                for k in 0..n {
                    for l in 0..n {
                        let (y, db) = cell(b, k, l);
                        let r = y - x;
                        let r2 = r.length_squared();
                        let c1 = na.dot(r).max(0.0);
                        let c2 = (-nb.dot(r)).max(0.0);
                        s += c1 * c2 / (PI * r2 * r2) * da * db;
                    }
                }
            }
        }
        s
    }

    #[test]
    fn closed_forms_match_quadrature() {
        let room = Room::new(3.0, 4.0, 2.5, 1.2).unwrap();
        let ff = FormFactors::new(&room, 40).unwrap();
        let ps = ff.patches();
        let mut checked = (0, 0);
        for (i, a) in ps.iter().enumerate().step_by(3) {
            for b in ps.iter().skip(i + 1).step_by(5) {
                if a.face == b.face {
                    continue;
                }
                // Skip pairs touching along an edge (the quadrature is poor there).
                let touching = (0..3).all(|ax| {
                    let (alo, ahi) = bounds(a, ax);
                    let (blo, bhi) = bounds(b, ax);
                    alo <= bhi + 1e-9 && blo <= ahi + 1e-9
                });
                if touching {
                    continue;
                }
                let exact = area_form_factor(a, b);
                let q = quad(a, b, 10);
                assert!(
                    (exact - q).abs() <= 0.01 * q + 1e-9,
                    "{a:?} {b:?}: {exact} vs {q}"
                );
                if a.face.axis() == b.face.axis() {
                    checked.0 += 1;
                } else {
                    checked.1 += 1;
                }
            }
        }
        assert!(checked.0 > 5 && checked.1 > 5, "{checked:?}");
    }

    fn bounds(p: &Patch, axis: usize) -> (f64, f64) {
        let (ua, va) = p.face.plane_axes();
        if axis == ua {
            (p.u[0], p.u[1])
        } else if axis == va {
            (p.v[0], p.v[1])
        } else {
            (p.plane, p.plane)
        }
    }

    #[test]
    fn reciprocity_and_rows_sum_to_one() {
        for (w, d, h, target) in [
            (3.0, 4.0, 2.5, 200),
            (6.0, 5.0, 2.8, 600),
            (10.0, 2.0, 3.0, 300),
        ] {
            let room = Room::new(w, d, h, 1.0).unwrap();
            let ff = FormFactors::new(&room, target).unwrap();
            let n = ff.len();
            for i in 0..n {
                let row: f64 = (0..n).map(|j| ff.get(i, j)).sum();
                assert!((row - 1.0).abs() < 1e-9, "row {i} of {w}x{d}x{h}: {row}");
                for j in 0..n {
                    let (ai, aj) = (ff.patches()[i].area(), ff.patches()[j].area());
                    let (x, y) = (ai * ff.get(i, j), aj * ff.get(j, i));
                    assert!((x - y).abs() <= 1e-12 * x.max(y) + 1e-15);
                }
            }
        }
    }

    #[test]
    fn point_form_factor_of_a_whole_face_under_a_point() {
        // A point at the centre of the floor sees the rest of the box: the sum of its
        // form factors to all patches is 1.
        let room = Room::new(4.0, 3.0, 2.5, 1.2).unwrap();
        let ff = FormFactors::new(&room, 150).unwrap();
        for (p, n) in [
            (DVec3::new(0.3, 0.0, 0.2), DVec3::Y),
            (DVec3::new(0.3, 0.75, 0.2), DVec3::Y),
            (DVec3::new(-2.0, 1.0, 0.5), DVec3::X),
            (
                DVec3::new(0.1, 1.3, -0.4),
                DVec3::new(0.3, -0.5, 0.8).normalize(),
            ),
        ] {
            let s: f64 = ff
                .patches()
                .iter()
                .map(|q| point_polygon_ff(p, n, &q.corners()))
                .sum();
            assert!((s - 1.0).abs() < 1e-9, "{p}: {s}");
        }
        // A unit square 1 m straight above: F = the known value for a point under the
        // corner of a 1 × 1 rectangle at distance 1, times 4 for the centre of 2 × 2.
        let sq = [
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(1.0, 1.0, -1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(-1.0, 1.0, 1.0),
        ];
        // Corner formula: F = (1/2π)(A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²) atan(A/√(1+B²))).
        let a = 1.0f64;
        let corner =
            (a / (1.0 + a * a).sqrt() * (a / (1.0 + a * a).sqrt()).atan()) * 2.0 / (2.0 * PI);
        let f = point_polygon_ff(DVec3::ZERO, DVec3::Y, &sq);
        assert!((f - 4.0 * corner).abs() < 1e-12, "{f} vs {}", 4.0 * corner);
    }

    #[test]
    fn reflectances_are_checked() {
        assert!(Reflectances::default().check().is_ok());
        for bad in [1.0, -0.1, f64::NAN, 1.5] {
            let e = Reflectances {
                walls: bad,
                ..Reflectances::default()
            }
            .check()
            .unwrap_err();
            assert!(e.to_string().contains("wall reflectance"), "{e}");
        }
    }

    #[test]
    fn too_many_patches_are_refused() {
        let room = Room::new(4.0, 3.0, 2.5, 1.2).unwrap();
        let e = FormFactors::new(&room, 100_000).unwrap_err();
        assert!(e.to_string().contains("2500"), "{e}");
    }
}
