//! A level horizon for a cube map: each face texel of a new cube map of the same size is
//! the original sampled (bilinear, across face edges) in the direction the horizon
//! rotation gives for the texel centre's direction. The same rotation as the
//! equirectangular `level_horizon` (Pannellum's `horizonPitch`/`horizonRoll`), so a
//! cube scene and an equirectangular one of the same tilted camera come out level alike.

use crate::cube::{face_dir, CubeError, CubeMap, Face};
use crate::map::level::horizon_rotation;
use crate::map::sample::Sampler;
use rayon::prelude::*;

/// `cube` re-levelled by the horizon pitch and roll (degrees): the cube a level camera
/// would have taken, same face size.
///
/// # Errors
/// None for a valid cube map in practice (the faces are rebuilt at the size they had).
pub fn level_cube_horizon(
    cube: &CubeMap,
    pitch_deg: f64,
    roll_deg: f64,
) -> Result<CubeMap, CubeError> {
    let m = horizon_rotation(pitch_deg, roll_deg);
    let n = cube.face_size() as usize;
    let half = n as f64 / 2.0;
    let faces: Vec<Vec<u32>> = Face::ALL
        .iter()
        .map(|&face| {
            let mut px = vec![0u32; n * n];
            px.par_chunks_mut(n).enumerate().for_each(|(y, row)| {
                // The texel centre's face coordinates (face_uv's inverse).
                let t = 1.0 - (y as f64 + 0.5) / half;
                for (x, out) in row.iter_mut().enumerate() {
                    let s = (x as f64 + 0.5) / half - 1.0;
                    *out = cube.sample_dir(Sampler::Bilinear, m * face_dir(face, s, t));
                }
            });
            px
        })
        .collect();
    let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
    CubeMap::from_faces(n as u32, refs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cube::face_of;
    use glam::{DMat3, DVec3};

    /// A smooth colour of a direction: each channel linear in one coordinate.
    fn colour(d: DVec3) -> [f64; 3] {
        let d = d.normalize();
        [
            127.5 + 120.0 * d.x,
            127.5 + 120.0 * d.y,
            127.5 + 120.0 * d.z,
        ]
    }

    fn pack(c: [f64; 3]) -> u32 {
        let q = |x: f64| x.round().clamp(0.0, 255.0) as u32;
        (q(c[0]) << 16) | (q(c[1]) << 8) | q(c[2])
    }

    fn cube_of(n: u32, f: impl Fn(DVec3) -> [f64; 3]) -> CubeMap {
        let half = n as f64 / 2.0;
        let faces: Vec<Vec<u32>> = Face::ALL
            .iter()
            .map(|&face| {
                let mut px = Vec::new();
                for y in 0..n {
                    for x in 0..n {
                        let s = (x as f64 + 0.5) / half - 1.0;
                        let t = 1.0 - (y as f64 + 0.5) / half;
                        px.push(pack(f(face_dir(face, s, t))));
                    }
                }
                px
            })
            .collect();
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        CubeMap::from_faces(n, refs).unwrap()
    }

    /// Largest channel difference between `got` and the colour at each texel's
    /// direction rotated by `m` (the exact rotated reference).
    fn worst(got: &CubeMap, m: DMat3) -> f64 {
        let n = got.face_size();
        let half = n as f64 / 2.0;
        let mut worst: f64 = 0.0;
        for &face in &Face::ALL {
            for y in 0..n {
                for x in 0..n {
                    let s = (x as f64 + 0.5) / half - 1.0;
                    let t = 1.0 - (y as f64 + 0.5) / half;
                    let d = face_dir(face, s, t);
                    assert_eq!(face_of(d), face);
                    let want = colour(m * d);
                    let p = got.pixel(face, x, y);
                    let have = [(p >> 16) & 0xFF, (p >> 8) & 0xFF, p & 0xFF];
                    for c in 0..3 {
                        worst = worst.max((have[c] as f64 - want[c]).abs());
                    }
                }
            }
        }
        worst
    }

    #[test]
    fn a_levelled_cube_matches_the_exact_rotated_reference() {
        let cube = cube_of(64, colour);
        for (p, r) in [(8.0, -12.0), (-5.0, 3.0), (0.0, 20.0)] {
            let m = horizon_rotation(p, r);
            let level = level_cube_horizon(&cube, p, r).unwrap();
            // Bilinear between texels of a smooth colour, two roundings: within 2 levels.
            let e = worst(&level, m);
            assert!(e <= 2.0, "pitch {p} roll {r}: off by {e}");
            // The inverse rotation (a sign error) is far off.
            let wrong = worst(&level, m.transpose());
            assert!(
                wrong > 10.0,
                "pitch {p} roll {r}: the inverse is only {wrong} off"
            );
        }
        // No correction: the cube as it was.
        let same = level_cube_horizon(&cube, 0.0, 0.0).unwrap();
        for &face in &Face::ALL {
            assert_eq!(same.face_pixels(face), cube.face_pixels(face));
        }
    }
}
