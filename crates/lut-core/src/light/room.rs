//! The room: a box around the camera, turned about the vertical axis and shifted so that
//! its faces sit on the photograph's walls, floor and ceiling.
//!
//! **Room coordinates** (docs/lights.md): metres along the box's edges, X right, Y up,
//! Z forward, with the origin on the floor below the camera, so the camera sits at
//! (0, camera height, 0). The box spans x ∈ [cx − W/2, cx + W/2], y ∈ [0, H],
//! z ∈ [cz − D/2, cz + D/2], (cx, cz) its centre (0, 0 when the camera stands in the
//! middle). Luminaires and the points `viewer lux` reports are placed in these
//! coordinates, so turning or fitting the box to a photograph never changes a lux value.
//!
//! **The panorama's frame** (docs/conventions.md) is the room frame turned by the room's
//! yaw ψ about the vertical axis, in the camera's sense: the room's +Z axis (its front
//! wall's normal, outward) points at panorama yaw ψ. A panorama direction d is the room
//! direction R_y(−ψ)·d.

use super::LightError;
use glam::DVec3;

/// A box-shaped room around the camera, in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Room {
    pub(crate) width: f64,
    pub(crate) depth: f64,
    pub(crate) height: f64,
    pub(crate) camera_height: f64,
    /// Turn about the vertical axis in degrees, (−180, 180].
    yaw_deg: f64,
    /// sin and cos of the yaw.
    sy: f64,
    cy: f64,
    /// The box centre (x, z) in room coordinates.
    center: (f64, f64),
}

/// One face of the room box. [`RoomFace::ALL`] lists them in the order
/// [`RoomFace::index`] numbers them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RoomFace {
    /// y = 0, normal +Y.
    Floor,
    /// y = H, normal −Y.
    Ceiling,
    /// The wall at the low x end (left at room yaw 0), normal +X.
    Left,
    /// The wall at the high x end, normal −X.
    Right,
    /// The wall at the low z end (behind at room yaw 0), normal +Z.
    Back,
    /// The wall at the high z end (ahead at room yaw 0), normal −Z.
    Front,
}

impl RoomFace {
    /// Every face.
    pub const ALL: [RoomFace; 6] = [
        RoomFace::Floor,
        RoomFace::Ceiling,
        RoomFace::Left,
        RoomFace::Right,
        RoomFace::Back,
        RoomFace::Front,
    ];

    /// Position in [`RoomFace::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The face on `axis` (0 = X, 1 = Y, 2 = Z) at its low (`high` false) or high end.
    pub fn on_axis(axis: usize, high: bool) -> RoomFace {
        match (axis, high) {
            (0, false) => RoomFace::Left,
            (0, true) => RoomFace::Right,
            (1, false) => RoomFace::Floor,
            (1, true) => RoomFace::Ceiling,
            (2, false) => RoomFace::Back,
            _ => RoomFace::Front,
        }
    }

    /// The axis the face is normal to (0 = X, 1 = Y, 2 = Z).
    pub fn axis(self) -> usize {
        match self {
            RoomFace::Left | RoomFace::Right => 0,
            RoomFace::Floor | RoomFace::Ceiling => 1,
            RoomFace::Back | RoomFace::Front => 2,
        }
    }

    /// Whether the face is at the high end of its axis.
    pub fn is_high(self) -> bool {
        matches!(self, RoomFace::Right | RoomFace::Ceiling | RoomFace::Front)
    }

    /// The unit normal pointing into the room.
    pub fn inward_normal(self) -> DVec3 {
        let mut n = DVec3::ZERO;
        n[self.axis()] = if self.is_high() { -1.0 } else { 1.0 };
        n
    }

    /// The two axes spanning the face, (u, v): floor and ceiling (X, Z), side walls
    /// (Z, Y), front and back walls (X, Y).
    pub fn plane_axes(self) -> (usize, usize) {
        match self.axis() {
            0 => (2, 1),
            1 => (0, 2),
            _ => (0, 1),
        }
    }

    /// A short name for messages and the window ("floor", "left wall", ...).
    pub fn name(self) -> &'static str {
        match self {
            RoomFace::Floor => "floor",
            RoomFace::Ceiling => "ceiling",
            RoomFace::Left => "left wall",
            RoomFace::Right => "right wall",
            RoomFace::Back => "back wall",
            RoomFace::Front => "front wall",
        }
    }
}

impl Room {
    /// A room `width` (along X) × `depth` (along Z) × `height` (along Y), with the camera
    /// at the horizontal centre, `camera_height` above the floor, not turned.
    ///
    /// # Errors
    /// [`LightError::BadOption`] when a size is not a positive finite number or the camera
    /// is not strictly between floor and ceiling.
    pub fn new(
        width: f64,
        depth: f64,
        height: f64,
        camera_height: f64,
    ) -> Result<Room, LightError> {
        for (name, value) in [
            ("room width", width),
            ("room depth", depth),
            ("room height", height),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(LightError::BadOption {
                    name,
                    expected: "a positive number of metres",
                    value,
                });
            }
            // The limits module: a room typed in millimetres is refused, not built.
            crate::guard::check_limit(name, value, crate::geom::limits::MAX_ROOM_SIDE, " m")?;
        }
        if !(camera_height > 0.0 && camera_height < height) {
            return Err(LightError::BadOption {
                name: "camera height",
                expected: "strictly between the floor (0) and the ceiling",
                value: camera_height,
            });
        }
        Ok(Room {
            width,
            depth,
            height,
            camera_height,
            yaw_deg: 0.0,
            sy: 0.0,
            cy: 1.0,
            center: (0.0, 0.0),
        })
    }

    /// A cube room of side `size` (a cube panorama's room), camera at `camera_height`.
    ///
    /// # Errors
    /// As [`Room::new`].
    pub fn cube(size: f64, camera_height: f64) -> Result<Room, LightError> {
        Room::new(size, size, size, camera_height)
    }

    /// The same room turned by `yaw_deg` about the vertical axis (the camera's sense:
    /// positive turns right): its front wall's outward normal points at panorama yaw
    /// `yaw_deg`. Any finite angle; kept in (−180, 180].
    ///
    /// # Errors
    /// [`LightError::BadOption`] for a non-finite angle.
    pub fn with_yaw(mut self, yaw_deg: f64) -> Result<Room, LightError> {
        if !yaw_deg.is_finite() {
            return Err(LightError::BadOption {
                name: "room yaw",
                expected: "a finite number of degrees",
                value: yaw_deg,
            });
        }
        self.yaw_deg = crate::geom::camera::wrap_deg(yaw_deg);
        (self.sy, self.cy) = self.yaw_deg.to_radians().sin_cos();
        Ok(self)
    }

    /// The same room with its centre at (`x`, `z`) metres from the point below the camera
    /// (the camera is not in the middle of the room).
    ///
    /// # Errors
    /// [`LightError::BadOption`] for a non-finite value or a centre that leaves the camera
    /// outside the box.
    pub fn with_center(mut self, x: f64, z: f64) -> Result<Room, LightError> {
        for (name, value, half) in [
            ("room centre x", x, self.width / 2.0),
            ("room centre z", z, self.depth / 2.0),
        ] {
            if !(value.is_finite() && value.abs() < half) {
                return Err(LightError::BadOption {
                    name,
                    expected:
                        "less than half the room's size from the camera (the camera must be inside)",
                    value,
                });
            }
        }
        self.center = (x, z);
        Ok(self)
    }

    /// Width along X in metres.
    pub fn width(&self) -> f64 {
        self.width
    }
    /// Depth along Z in metres.
    pub fn depth(&self) -> f64 {
        self.depth
    }
    /// Height along Y in metres.
    pub fn height(&self) -> f64 {
        self.height
    }
    /// Camera height above the floor in metres.
    pub fn camera_height(&self) -> f64 {
        self.camera_height
    }
    /// The turn about the vertical axis in degrees, (−180, 180].
    pub fn yaw_deg(&self) -> f64 {
        self.yaw_deg
    }
    /// The box centre (x, z) in room coordinates.
    pub fn center(&self) -> (f64, f64) {
        self.center
    }

    /// The camera's position in room coordinates.
    pub fn camera_position(&self) -> DVec3 {
        DVec3::new(0.0, self.camera_height, 0.0)
    }

    /// The box's low and high corners in room coordinates.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let (cx, cz) = self.center;
        (
            DVec3::new(cx - self.width / 2.0, 0.0, cz - self.depth / 2.0),
            DVec3::new(cx + self.width / 2.0, self.height, cz + self.depth / 2.0),
        )
    }

    /// A direction of the panorama (the camera's world frame) in room coordinates.
    #[inline]
    pub fn to_room(&self, d: DVec3) -> DVec3 {
        // R_y(−ψ): x' = x cos ψ − z sin ψ, z' = z cos ψ + x sin ψ.
        DVec3::new(
            d.x * self.cy - d.z * self.sy,
            d.y,
            d.z * self.cy + d.x * self.sy,
        )
    }

    /// A room-frame vector in the panorama's frame (the inverse of [`Room::to_room`]).
    #[inline]
    pub fn to_world(&self, v: DVec3) -> DVec3 {
        DVec3::new(
            v.x * self.cy + v.z * self.sy,
            v.y,
            v.z * self.cy - v.x * self.sy,
        )
    }

    /// Whether a point (room coordinates) lies in the closed box (with a 1 µm tolerance).
    pub fn contains(&self, p: DVec3) -> bool {
        let e = 1e-6;
        let (lo, hi) = self.bounds();
        (0..3).all(|a| p[a] >= lo[a] - e && p[a] <= hi[a] + e)
    }

    /// The faces a point (room coordinates, inside the box) lies on within `tol` metres.
    pub fn faces_at(&self, p: DVec3, tol: f64) -> Vec<RoomFace> {
        let (lo, hi) = self.bounds();
        let mut out = Vec::new();
        for face in RoomFace::ALL {
            let a = face.axis();
            let plane = if face.is_high() { hi[a] } else { lo[a] };
            if (p[a] - plane).abs() <= tol {
                out.push(face);
            }
        }
        out
    }

    /// The inward unit normal of the face point `p` (room coordinates) lies on, within
    /// `tol` metres: what a lux reading at a surface point means by default.
    ///
    /// # Errors
    /// [`LightError::PointOutsideRoom`] outside the box (beyond `tol`),
    /// [`LightError::PointOffSurface`] when no face is within `tol`,
    /// [`LightError::PointOnEdge`] when two or three are (an edge or a corner).
    pub fn surface_normal(&self, p: DVec3, tol: f64) -> Result<DVec3, LightError> {
        let (lo, hi) = self.bounds();
        let point = p.to_array();
        if !(0..3).all(|a| p[a] >= lo[a] - tol && p[a] <= hi[a] + tol) {
            return Err(LightError::PointOutsideRoom {
                point,
                low: lo.to_array(),
                high: hi.to_array(),
            });
        }
        match self.faces_at(p, tol).as_slice() {
            [face] => Ok(face.inward_normal()),
            [] => Err(LightError::PointOffSurface { point, tol }),
            [a, b, ..] => Err(LightError::PointOnEdge {
                point,
                faces: (a.name(), b.name()),
            }),
        }
    }

    /// The coordinate of `face`'s plane along its axis.
    pub fn plane(&self, face: RoomFace) -> f64 {
        let (lo, hi) = self.bounds();
        if face.is_high() {
            hi[face.axis()]
        } else {
            lo[face.axis()]
        }
    }

    /// Where the ray from `origin` (room coordinates, inside the box) along `dir` (room
    /// frame, any length, not zero) leaves the box, and the face it leaves by.
    #[inline]
    pub fn hit_face(&self, origin: DVec3, dir: DVec3) -> (DVec3, RoomFace) {
        let (lo, hi) = self.bounds();
        let mut t = f64::INFINITY;
        let mut face = RoomFace::Floor;
        for axis in 0..3 {
            let d = dir[axis];
            if d == 0.0 {
                continue;
            }
            let (plane, high) = if d > 0.0 {
                (hi[axis], true)
            } else {
                (lo[axis], false)
            };
            let ta = (plane - origin[axis]) / d;
            if ta < t {
                t = ta;
                face = RoomFace::on_axis(axis, high);
            }
        }
        if !t.is_finite() {
            return (origin, RoomFace::Floor);
        }
        let mut p = origin + dir * t.max(0.0);
        // Put the hit exactly on its face (no drift off the wall from rounding).
        let axis = face.axis();
        p[axis] = if face.is_high() { hi[axis] } else { lo[axis] };
        (p, face)
    }

    /// [`Room::hit_face`] with the face's inward unit normal instead of the face.
    #[inline]
    pub fn hit(&self, origin: DVec3, dir: DVec3) -> (DVec3, DVec3) {
        let (p, face) = self.hit_face(origin, dir);
        (p, face.inward_normal())
    }

    /// The box's 8 corners in room coordinates, corner `i` at the high end of X when bit
    /// 0 is set, of Y for bit 1, of Z for bit 2.
    pub fn corners(&self) -> [DVec3; 8] {
        let (lo, hi) = self.bounds();
        std::array::from_fn(|i| {
            DVec3::new(
                if i & 1 != 0 { hi.x } else { lo.x },
                if i & 2 != 0 { hi.y } else { lo.y },
                if i & 4 != 0 { hi.z } else { lo.z },
            )
        })
    }

    /// The box's 12 edges as pairs of indices into [`Room::corners`].
    pub const EDGES: [(usize, usize); 12] = [
        (0, 1),
        (2, 3),
        (4, 5),
        (6, 7),
        (0, 2),
        (1, 3),
        (4, 6),
        (5, 7),
        (0, 4),
        (1, 5),
        (2, 6),
        (3, 7),
    ];
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hit_faces_and_normals() {
        let r = Room::new(4.0, 6.0, 3.0, 1.5).unwrap();
        let o = r.camera_position();
        let (p, n) = r.hit(o, DVec3::new(0.0, -1.0, 0.0));
        assert_eq!((p, n), (DVec3::new(0.0, 0.0, 0.0), DVec3::Y));
        let (p, n) = r.hit(o, DVec3::new(1.0, 0.0, 0.0));
        assert_eq!((p, n), (DVec3::new(2.0, 1.5, 0.0), -DVec3::X));
        let (p, n) = r.hit(o, DVec3::new(0.0, 1.0, -1.0));
        assert_eq!(n, DVec3::NEG_Y);
        assert!((p - DVec3::new(0.0, 3.0, -1.5)).length() < 1e-12);
    }

    #[test]
    fn centre_shifts_the_walls_and_keeps_the_camera_inside() {
        let r = Room::new(4.0, 6.0, 3.0, 1.5)
            .unwrap()
            .with_center(0.5, -1.0)
            .unwrap();
        let o = r.camera_position();
        let (p, f) = r.hit_face(o, DVec3::X);
        assert_eq!((p.x, f), (2.5, RoomFace::Right));
        let (p, f) = r.hit_face(o, DVec3::NEG_Z);
        assert_eq!((p.z, f), (-4.0, RoomFace::Back));
        assert!(r.contains(DVec3::new(-1.5, 0.0, 2.0)));
        assert!(!r.contains(DVec3::new(-1.6, 0.0, 0.0)));
        assert!(Room::new(4.0, 6.0, 3.0, 1.5)
            .unwrap()
            .with_center(2.0, 0.0)
            .is_err());
        assert!(Room::new(4.0, 6.0, 3.0, 1.5)
            .unwrap()
            .with_center(0.0, f64::NAN)
            .is_err());
    }

    #[test]
    fn yaw_turns_the_panorama_into_the_room() {
        let r = Room::new(4.0, 6.0, 3.0, 1.5)
            .unwrap()
            .with_yaw(90.0)
            .unwrap();
        // The room's +Z (front) is at panorama yaw 90: the panorama's +X.
        assert!((r.to_room(DVec3::X) - DVec3::Z).length() < 1e-15);
        assert!((r.to_world(DVec3::Z) - DVec3::X).length() < 1e-15);
        for d in [DVec3::new(0.3, -0.2, 0.9), DVec3::new(-1.0, 2.0, 0.5)] {
            assert!((r.to_world(r.to_room(d)) - d).length() < 1e-15);
        }
        assert_eq!(
            Room::new(4.0, 6.0, 3.0, 1.5)
                .unwrap()
                .with_yaw(540.0)
                .unwrap()
                .yaw_deg(),
            180.0
        );
    }

    #[test]
    fn faces_at_points() {
        let r = Room::new(4.0, 6.0, 3.0, 1.5).unwrap();
        assert_eq!(
            r.faces_at(DVec3::new(0.0, 0.0, 0.0), 1e-3),
            [RoomFace::Floor]
        );
        assert_eq!(
            r.faces_at(DVec3::new(1.9995, 1.0, 0.0), 1e-3),
            [RoomFace::Right]
        );
        assert!(r.faces_at(DVec3::new(1.99, 1.0, 0.0), 1e-3).is_empty());
        assert_eq!(
            r.faces_at(DVec3::new(2.0, 3.0, 0.0), 1e-3),
            [RoomFace::Ceiling, RoomFace::Right]
        );
        for f in RoomFace::ALL {
            let (u, v) = f.plane_axes();
            assert!(u != f.axis() && v != f.axis() && u != v);
            assert_eq!(RoomFace::on_axis(f.axis(), f.is_high()), f);
            assert_eq!(RoomFace::ALL[f.index()], f);
        }
    }

    #[test]
    fn surface_normals_of_points() {
        let r = Room::new(4.0, 6.0, 3.0, 1.5).unwrap();
        let n = |x, y, z| r.surface_normal(DVec3::new(x, y, z), 1e-3);
        assert_eq!(n(0.3, 0.0, 1.0).unwrap(), DVec3::Y);
        assert_eq!(n(0.3, 3.0004, 1.0).unwrap(), DVec3::NEG_Y);
        assert_eq!(n(-2.0, 1.0, 1.0).unwrap(), DVec3::X);
        assert_eq!(n(0.0, 1.0, 2.9995).unwrap(), DVec3::NEG_Z);
        assert!(matches!(
            n(0.0, 1.0, 0.0),
            Err(LightError::PointOffSurface { .. })
        ));
        assert!(matches!(
            n(2.0, 0.0, 0.0),
            Err(LightError::PointOnEdge {
                faces: ("floor", "right wall"),
                ..
            })
        ));
        let e = n(0.0, -0.5, 0.0).unwrap_err();
        assert!(matches!(e, LightError::PointOutsideRoom { .. }));
        assert!(e.to_string().contains("outside the room"), "{e}");
    }

    #[test]
    fn corners_and_edges() {
        let r = Room::new(2.0, 4.0, 3.0, 1.0).unwrap();
        let c = r.corners();
        for (a, b) in Room::EDGES {
            // Each edge joins corners differing in one coordinate.
            assert_eq!((a ^ b).count_ones(), 1);
            let len = (c[a] - c[b]).length();
            assert!([2.0, 3.0, 4.0].contains(&len));
        }
    }
}
