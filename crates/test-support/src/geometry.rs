//! Geometry the tests compute on their own, independently of the library.

use glam::DVec3;

/// Ray/box intersection: the hit point and the inward wall normal of the ray from `o`
/// along `d` inside a room spanning x ±w/2, y 0..ht, z ±dep/2.
pub fn room_hit(o: DVec3, d: DVec3, w: f64, dep: f64, ht: f64) -> (DVec3, DVec3) {
    let cands = [
        ((w / 2.0 - o.x) / d.x, DVec3::NEG_X),
        ((-w / 2.0 - o.x) / d.x, DVec3::X),
        ((ht - o.y) / d.y, DVec3::NEG_Y),
        ((0.0 - o.y) / d.y, DVec3::Y),
        ((dep / 2.0 - o.z) / d.z, DVec3::NEG_Z),
        ((-dep / 2.0 - o.z) / d.z, DVec3::Z),
    ];
    let (t, n) = cands
        .iter()
        .filter(|(t, _)| t.is_finite() && *t > 0.0)
        .fold((f64::INFINITY, DVec3::ZERO), |a, &(t, n)| {
            if t < a.0 {
                (t, n)
            } else {
                a
            }
        });
    (o + d * t, n)
}
