//! What the room and its luminaires look like drawn over a view: the room box as a
//! wireframe (to fit it to the photograph's walls), each light as a marker with its aim,
//! the false-colour legend. Pure geometry in image coordinates, so the window (egui
//! shapes) and `viewer render --show-room` (drawn into the frame) draw the same thing.

use glam::DVec3;
use lut_core::{Camera, Room};

/// How close to the camera plane an edge is clipped, in the camera's focal units (rays
/// closer to sideways than this are not drawn).
const NEAR: f64 = 1e-3;

/// A segment in image coordinates (pixels, centres at +0.5).
pub type Segment = ((f64, f64), (f64, f64));

/// The camera-space depth of a panorama-frame direction: its component along the view
/// axis.
fn depth(cam: &Camera, d: DVec3) -> f64 {
    let f = cam
        .ray(cam.width as f64 / 2.0, cam.height as f64 / 2.0)
        .unwrap_or(DVec3::Z);
    d.dot(f) / f.length()
}

/// The part of the 3-D segment `a`–`b` (room coordinates) in front of the camera,
/// projected into the image; `None` when it is all behind.
pub fn project_segment(room: &Room, cam: &Camera, a: DVec3, b: DVec3) -> Option<Segment> {
    let o = room.camera_position();
    let (mut wa, mut wb) = (room.to_world(a - o), room.to_world(b - o));
    let (da, db) = (depth(cam, wa), depth(cam, wb));
    let near = NEAR * wa.length().max(wb.length());
    if da < near && db < near {
        return None;
    }
    // Clip the part behind the near plane (depth is linear along the segment).
    if da < near {
        wa = wa + (wb - wa) * ((near - da) / (db - da));
    } else if db < near {
        wb = wb + (wa - wb) * ((near - db) / (da - db));
    }
    Some((cam.project(wa)?, cam.project(wb)?))
}

/// Pieces of an edge of a view projection that bends straight lines (fisheye, little
/// planet, Pannini).
const CURVE_PIECES: usize = 48;

/// The 3-D segment `a`–`b` (room coordinates) as drawn in `cam`'s image: one clipped
/// segment for a rectilinear view, else `CURVE_PIECES` pieces of the curve it becomes
/// (pieces the view does not show, or that jump across the image where the projection
/// wraps, are left out).
pub fn edge_pieces(room: &Room, cam: &Camera, a: DVec3, b: DVec3) -> Vec<Segment> {
    if cam.projection().is_rectilinear() {
        return project_segment(room, cam, a, b).into_iter().collect();
    }
    let o = room.camera_position();
    let at = |t: f64| cam.project(room.to_world(a + (b - a) * t - o));
    let jump = (cam.width + cam.height) as f64 / 4.0;
    let mut out = Vec::new();
    let mut prev = at(0.0);
    for k in 1..=CURVE_PIECES {
        let next = at(k as f64 / CURVE_PIECES as f64);
        if let (Some(p), Some(q)) = (prev, next) {
            if (p.0 - q.0).hypot(p.1 - q.1) < jump {
                out.push((p, q));
            }
        }
        prev = next;
    }
    out
}

/// The room box's 12 edges as seen by `cam` (the parts it shows).
pub fn room_edges(room: &Room, cam: &Camera) -> Vec<Segment> {
    let c = room.corners();
    Room::EDGES
        .iter()
        .flat_map(|&(i, j)| edge_pieces(room, cam, c[i], c[j]))
        .collect()
}

/// Where a light (room coordinates) appears in the image, if in front of the camera.
pub fn project_point(room: &Room, cam: &Camera, p: DVec3) -> Option<(f64, f64)> {
    let w = room.to_world(p - room.camera_position());
    if cam.projection().is_rectilinear() && depth(cam, w) <= NEAR * w.length() {
        return None;
    }
    cam.project(w)
}

/// A light's marker: its place in the image and a short stroke toward its aim (35 cm
/// along the aim), when in front of the camera.
pub fn light_marker(
    room: &Room,
    cam: &Camera,
    position: DVec3,
    aim: DVec3,
) -> Option<((f64, f64), Option<Segment>)> {
    let at = project_point(room, cam, position)?;
    let stroke = edge_pieces(room, cam, position, position + aim * 0.35)
        .into_iter()
        .reduce(|a, b| (a.0, b.1));
    Some((at, stroke))
}

/// Blend `color` (0RGB) over the pixel at (x, y) with `alpha` in [0, 1].
fn blend_px(frame: &mut [u32], w: u32, h: u32, x: i64, y: i64, color: u32, alpha: f64) {
    if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 || alpha <= 0.0 {
        return;
    }
    let p = &mut frame[(y as u32 * w + x as u32) as usize];
    let a = alpha.min(1.0);
    let ch = |s: u32| {
        let (c, d) = (((color >> s) & 0xff) as f64, ((*p >> s) & 0xff) as f64);
        ((c * a + d * (1.0 - a)).round() as u32).min(255) << s
    };
    *p = ch(16) | ch(8) | ch(0);
}

/// Distance from (px, py) to the segment `s`.
fn segment_distance(s: Segment, px: f64, py: f64) -> f64 {
    let ((x0, y0), (x1, y1)) = s;
    let (dx, dy) = (x1 - x0, y1 - y0);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((px - x0) * dx + (py - y0) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    ((px - x0 - t * dx).powi(2) + (py - y0 - t * dy).powi(2)).sqrt()
}

/// Draw an anti-aliased segment `width` pixels wide into a `w × h` 0RGB frame: each pixel
/// within reach is blended once, by its coverage.
pub fn draw_segment(frame: &mut [u32], w: u32, h: u32, s: Segment, width: f64, color: u32) {
    let ((x0, y0), (x1, y1)) = s;
    if !(x0.is_finite() && y0.is_finite() && x1.is_finite() && y1.is_finite()) {
        return;
    }
    let half = width / 2.0;
    let r = half.ceil() as i64 + 1;
    let (dx, dy) = (x1 - x0, y1 - y0);
    // Walk the major axis inside the frame; cover the pixels across the line.
    let steep = dy.abs() > dx.abs();
    let (a0, a1, extent) = if steep { (y0, y1, h) } else { (x0, x1, w) };
    let lo = (a0.min(a1).floor() as i64 - r).max(0);
    let hi = (a0.max(a1).ceil() as i64 + r).min(extent as i64 - 1);
    for m in lo..=hi {
        let c = m as f64 + 0.5;
        // Where the line crosses this row (or column).
        let t = if a1 != a0 {
            ((c - a0) / (a1 - a0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let across = if steep { x0 + dx * t } else { y0 + dy * t };
        for n in across.floor() as i64 - r..=across.floor() as i64 + r {
            let (xx, yy) = if steep { (n, m) } else { (m, n) };
            let d = segment_distance(s, xx as f64 + 0.5, yy as f64 + 0.5);
            blend_px(frame, w, h, xx, yy, color, (half + 0.5 - d).clamp(0.0, 1.0));
        }
    }
}

/// Draw a filled disc of `radius` pixels with a dark outline.
pub fn draw_marker(frame: &mut [u32], w: u32, h: u32, at: (f64, f64), radius: f64, color: u32) {
    let r = radius.ceil() as i64 + 2;
    let (cx, cy) = at;
    for yy in cy.floor() as i64 - r..=cy.floor() as i64 + r {
        for xx in cx.floor() as i64 - r..=cx.floor() as i64 + r {
            let d = ((xx as f64 + 0.5 - cx).powi(2) + (yy as f64 + 0.5 - cy).powi(2)).sqrt();
            let outline = (radius + 1.5 - d).clamp(0.0, 1.0);
            blend_px(frame, w, h, xx, yy, 0x101010, outline);
            blend_px(
                frame,
                w,
                h,
                xx,
                yy,
                color,
                (radius + 0.5 - d).clamp(0.0, 1.0),
            );
        }
    }
}

/// The luminaire of `st` whose marker is nearest to (px, py) in a `w × h` frame of
/// `view`, if within `radius` pixels.
pub fn pick_light(
    st: &super::LightsState,
    view: lut_core::View,
    w: u32,
    h: u32,
    (px, py): (f64, f64),
    radius: f64,
) -> Option<usize> {
    let room = st.room_box().ok()?;
    let cam = Camera::new(view, w, h);
    let lights = st.lights.iter().enumerate().filter_map(|(i, l)| {
        let (x, y) = project_point(&room, &cam, DVec3::from(l.position))?;
        Some((i, (x - px).hypot(y - py)))
    });
    nearest_within(lights, radius)
}

/// Where a luminaire at `position` moves when dragged to (px, py) of a `cam` frame: along
/// the room face it is nearest to (the ceiling, a wall or the floor), keeping its
/// distance from that face, to the point under the cursor; kept 1 cm inside the room.
/// `None` when the cursor's ray does not meet that plane in front of the camera.
pub fn drag_on_surface(
    room: &Room,
    cam: &Camera,
    position: DVec3,
    (px, py): (f64, f64),
) -> Option<DVec3> {
    let (lo, hi) = room.bounds();
    // The nearest face: its axis and the plane through the light parallel to it.
    let dist = [
        (position.x - lo.x).min(hi.x - position.x),
        (position.y - lo.y).min(hi.y - position.y),
        (position.z - lo.z).min(hi.z - position.z),
    ];
    let axis = (0..3).min_by(|&a, &b| dist[a].total_cmp(&dist[b]))?;
    let o = room.camera_position();
    let d = room.to_room(cam.ray(px, py)?);
    if d[axis].abs() < 1e-12 {
        return None;
    }
    let t = (position[axis] - o[axis]) / d[axis];
    if !(t > 0.0 && t.is_finite()) {
        return None;
    }
    let p = o + d * t;
    let m = DVec3::splat(0.01);
    let mut q = p.clamp(lo + m, hi - m);
    q[axis] = position[axis];
    Some(q)
}

/// The room edge (an index into [`Room::EDGES`]) drawn nearest to (px, py) in a `cam`
/// frame, if within `radius` pixels.
pub fn pick_room_edge(
    room: &Room,
    cam: &Camera,
    (px, py): (f64, f64),
    radius: f64,
) -> Option<usize> {
    let c = room.corners();
    let edges = Room::EDGES.iter().enumerate().filter_map(|(k, &(i, j))| {
        let d = edge_pieces(room, cam, c[i], c[j])
            .into_iter()
            .map(|s| segment_distance(s, px, py))
            .min_by(f64::total_cmp)?;
        Some((k, d))
    });
    nearest_within(edges, radius)
}

/// The index of the nearest of (index, distance) pairs within `radius`.
fn nearest_within(pairs: impl Iterator<Item = (usize, f64)>, radius: f64) -> Option<usize> {
    pairs
        .filter(|&(_, d)| d <= radius)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| k)
}

/// The room box after its edge `edge` (an index into [`Room::EDGES`]) is dragged to
/// (px, py) of a `cam` frame, as (width, depth, centre x, centre z); the height, camera
/// height and turn stay. An edge along the floor or the ceiling moves its wall to where
/// the cursor's ray meets the floor or ceiling; a vertical edge (a corner between two
/// walls) turns about the camera to the cursor's bearing at its distance, moving both
/// walls. The camera stays at least 5 cm inside. `None` when the cursor's ray does not
/// meet the floor or ceiling in front of the camera.
pub fn drag_room_edge(
    room: &Room,
    cam: &Camera,
    edge: usize,
    at: (f64, f64),
) -> Option<(f64, f64, f64, f64)> {
    let (i, j) = *Room::EDGES.get(edge)?;
    let axis = (i ^ j).trailing_zeros() as usize;
    let high = |bit: usize| i & (1 << bit) != 0;
    let (mut lo, mut hi) = room.bounds();
    if axis == 1 {
        let d = room.to_room(cam.ray(at.0, at.1)?);
        let c = room.corners()[i];
        let bearing = DVec3::new(d.x, 0.0, d.z);
        if bearing.length() < 1e-9 {
            return None;
        }
        let p = bearing.normalize() * c.x.hypot(c.z);
        set_wall(&mut lo, &mut hi, 0, high(0), p.x);
        set_wall(&mut lo, &mut hi, 2, high(2), p.z);
    } else {
        let y = if high(1) { hi.y } else { lo.y };
        let p = cursor_at_height(room, cam, at, y)?;
        let wall = 2 - axis;
        set_wall(&mut lo, &mut hi, wall, high(wall), p[wall]);
    }
    Some(box_walls(lo, hi))
}

/// The room's (height, camera height) after the floor or ceiling edge `edge` (an index
/// into [`Room::EDGES`]) is lifted or lowered to (px, py) of a `cam` frame (the window's
/// Shift-drag of an edge): the edge slides up or down its wall to where the cursor's ray
/// meets that wall, taking the ceiling (a top edge: the height changes) or the floor (a
/// bottom edge: the floor moves under the camera, so the camera height and the height
/// change together and the ceiling stays). Walls, turn and centre stay; the camera
/// stays at least 5 cm inside. `None` for a vertical edge or when the cursor's ray does
/// not meet the wall in front of the camera.
pub fn drag_room_level(
    room: &Room,
    cam: &Camera,
    edge: usize,
    at: (f64, f64),
) -> Option<(f64, f64)> {
    let (i, j) = *Room::EDGES.get(edge)?;
    let axis = (i ^ j).trailing_zeros() as usize;
    if axis == 1 {
        return None;
    }
    // The wall that holds the edge: perpendicular to the other horizontal axis.
    let wall = 2 - axis;
    let plane = room.corners()[i][wall];
    let o = room.camera_position();
    let d = room.to_room(cam.ray(at.0, at.1)?);
    let t = (plane - o[wall]) / d[wall];
    if !(t > 0.0 && t.is_finite()) {
        return None;
    }
    let y = o.y + d.y * t;
    let (h, c) = (room.height(), o.y);
    Some(if i & 2 != 0 {
        (y.max(c + INSIDE), c)
    } else {
        // The floor at y (room coordinates, the old floor at 0): the ceiling stays.
        let y = y.min(c - INSIDE);
        (h - y, c - y)
    })
}

/// How close (metres) a dragged wall, floor or ceiling may come to the camera.
const INSIDE: f64 = 0.05;

/// Move the wall on `axis` (0: X, 2: Z) at the box's `high` or low end to `v`, keeping
/// it [`INSIDE`] from the camera (at 0 on both axes).
fn set_wall(lo: &mut DVec3, hi: &mut DVec3, axis: usize, high: bool, v: f64) {
    if high {
        hi[axis] = v.max(INSIDE);
    } else {
        lo[axis] = v.min(-INSIDE);
    }
}

/// (width, depth, centre x, centre z) of the box `lo` … `hi`.
fn box_walls(lo: DVec3, hi: DVec3) -> (f64, f64, f64, f64) {
    (
        hi.x - lo.x,
        hi.z - lo.z,
        (lo.x + hi.x) / 2.0,
        (lo.z + hi.z) / 2.0,
    )
}

/// Where the ray through (px, py) of a `cam` frame meets the horizontal plane at height
/// `y` (room coordinates), in front of the camera.
fn cursor_at_height(room: &Room, cam: &Camera, (px, py): (f64, f64), y: f64) -> Option<DVec3> {
    let o = room.camera_position();
    let d = room.to_room(cam.ray(px, py)?);
    let t = (y - o.y) / d.y;
    (t > 0.0 && t.is_finite()).then(|| o + d * t)
}

/// The room corner (an index into [`Room::corners`]) drawn nearest to (px, py) in a
/// `cam` frame, within `radius` pixels (corners behind the camera left out).
pub fn pick_room_corner(
    room: &Room,
    cam: &Camera,
    (px, py): (f64, f64),
    radius: f64,
) -> Option<usize> {
    let all = room.corners();
    let corners = all.iter().enumerate().filter_map(|(k, &c)| {
        let (x, y) = project_point(room, cam, c)?;
        Some((k, (x - px).hypot(y - py)))
    });
    nearest_within(corners, radius)
}

/// The room box after its corner `corner` (an index into [`Room::corners`]) is dragged
/// to (px, py) of a `cam` frame, as (width, depth, centre x, centre z): the two walls
/// meeting at the corner move so that it sits where the cursor's ray meets the corner's
/// floor (a bottom corner) or ceiling (a top one); the other two walls, the height, the
/// camera height and the turn stay. The camera stays at least 5 cm inside. `None` when
/// the cursor's ray does not meet that floor or ceiling in front of the camera.
pub fn drag_room_corner(
    room: &Room,
    cam: &Camera,
    corner: usize,
    at: (f64, f64),
) -> Option<(f64, f64, f64, f64)> {
    let c = *room.corners().get(corner)?;
    let p = cursor_at_height(room, cam, at, c.y)?;
    let (mut lo, mut hi) = room.bounds();
    set_wall(&mut lo, &mut hi, 0, corner & 1 != 0, p.x);
    set_wall(&mut lo, &mut hi, 2, corner & 4 != 0, p.z);
    Some(box_walls(lo, hi))
}

/// Draw the room's wireframe and the lights' markers of `st` over a rendered `w × h`
/// frame of `view` (what `viewer render --show-room` adds and the window shows with
/// "Show room"); the selected light ([`super::LightsState::selected`]) is drawn larger,
/// in white.
///
/// # Errors
/// A room the state cannot build.
pub fn draw_room_and_lights(
    st: &super::LightsState,
    view: lut_core::View,
    frame: &mut [u32],
    w: u32,
    h: u32,
) -> Result<(), String> {
    let room = st.room_box()?;
    let cam = Camera::new(view, w, h);
    let scale = (w.max(h) as f64 / 800.0).max(1.0);
    for s in room_edges(&room, &cam) {
        draw_segment(frame, w, h, s, 2.0 * scale, ROOM_COLOR);
    }
    for (i, l) in st.lights.iter().enumerate() {
        let selected = st.selected == Some(i);
        let mut lum = lut_core::Luminaire::new(l.table.clone(), DVec3::from(l.position));
        lum.yaw_deg = l.yaw;
        lum.pitch_deg = l.pitch;
        if let Some((at, stroke)) = light_marker(&room, &cam, lum.position, lum.frame().2) {
            if let Some(s) = stroke {
                draw_segment(frame, w, h, s, 2.0 * scale, LIGHT_COLOR);
            }
            let color = match (selected, l.enabled) {
                (true, _) => SELECTED_COLOR,
                (false, true) => LIGHT_COLOR,
                (false, false) => 0x808080,
            };
            let r = if selected { 7.0 } else { 5.0 };
            draw_marker(frame, w, h, at, r * scale, color);
        }
    }
    Ok(())
}

/// The wireframe colour of the room box (a light cyan that reads on most photographs).
pub const ROOM_COLOR: u32 = 0x40e0ff;
/// The lights' marker colour.
pub const LIGHT_COLOR: u32 = 0xffd040;
/// The selected light's marker colour.
pub const SELECTED_COLOR: u32 = 0xffffff;

#[cfg(test)]
mod tests {
    use super::*;
    use lut_core::View;

    #[test]
    fn edges_project_where_the_box_is() {
        // Looking straight down from 1.5 m in a 4 × 4 m room: the floor's four edges form
        // a square around the image centre, the same on both axes.
        let room = Room::new(4.0, 4.0, 3.0, 1.5).unwrap();
        let cam = Camera::new(View::new(0.0, -90.0, 120.0).unwrap(), 200, 200);
        let edges = room_edges(&room, &cam);
        // The four floor edges and the four vertical ones are in front; the ceiling's
        // are behind.
        assert_eq!(edges.len(), 8);
        let f = cam.focal;
        let half = 2.0 / 1.5 * f;
        let floor_corner = (100.0 + half, 100.0 + half);
        assert!(edges.iter().any(|s| {
            let near = |p: (f64, f64)| {
                (p.0 - floor_corner.0).abs() < 1e-6 && (p.1 - floor_corner.1).abs() < 1e-6
            };
            near(s.0) || near(s.1)
        }));
    }

    #[test]
    fn edges_behind_are_clipped_not_dropped() {
        // Looking at a wall corner: edges running past the camera are cut at the near
        // plane and still drawn.
        let room = Room::new(4.0, 4.0, 3.0, 1.5).unwrap();
        let cam = Camera::new(View::new(45.0, 0.0, 90.0).unwrap(), 100, 60);
        let edges = room_edges(&room, &cam);
        assert!(edges.len() >= 3, "{edges:?}");
        for ((a, b), (c, d)) in &edges {
            assert!(a.is_finite() && b.is_finite() && c.is_finite() && d.is_finite());
        }
    }

    #[test]
    fn turning_the_room_turns_its_wireframe() {
        // The corner at the room's front-right, with the room turned by 30°, appears where
        // the unturned room's corner appears when the view turns by −30°.
        let room = Room::new(4.0, 6.0, 3.0, 1.5).unwrap();
        let turned = room.with_yaw(30.0).unwrap();
        let p = DVec3::new(2.0, 0.0, 3.0);
        let a = project_point(
            &turned,
            &Camera::new(View::new(40.0, -20.0, 90.0).unwrap(), 80, 60),
            p,
        );
        let b = project_point(
            &room,
            &Camera::new(View::new(10.0, -20.0, 90.0).unwrap(), 80, 60),
            p,
        );
        let (a, b) = (a.unwrap(), b.unwrap());
        assert!((a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9);
    }

    #[test]
    fn a_dragged_light_follows_the_cursor_on_its_face() {
        // A light on the ceiling of a turned, off-centre room, dragged to where another
        // ceiling point appears: it moves there, at the same height.
        let room = Room::new(4.0, 6.0, 3.0, 1.5)
            .unwrap()
            .with_yaw(25.0)
            .unwrap()
            .with_center(0.4, -0.3)
            .unwrap();
        let cam = Camera::new(View::new(20.0, 50.0, 100.0).unwrap(), 320, 200);
        let light = DVec3::new(0.5, 2.9, 0.2);
        let target = DVec3::new(-0.7, 2.9, 1.1);
        let at = project_point(&room, &cam, target).unwrap();
        let moved = drag_on_surface(&room, &cam, light, at).unwrap();
        assert!((moved - target).length() < 1e-9, "{moved}");
        // On a wall: it slides along the wall.
        let (lo, _) = room.bounds();
        let wall = DVec3::new(lo.x + 0.05, 2.0, 0.0);
        let goal = DVec3::new(lo.x + 0.05, 1.2, 0.8);
        let cam = Camera::new(View::new(-90.0, 0.0, 100.0).unwrap(), 320, 200);
        let at = project_point(&room, &cam, goal).unwrap();
        let moved = drag_on_surface(&room, &cam, wall, at).unwrap();
        assert!((moved - goal).length() < 1e-9, "{moved}");
        // Past the room's edge: kept inside.
        let far = drag_on_surface(&room, &cam, wall, (0.0, 0.0)).unwrap();
        assert!(room.contains(far));
    }

    #[test]
    fn dragged_room_edges_move_their_walls() {
        let room = Room::new(4.0, 6.0, 2.8, 1.5)
            .unwrap()
            .with_yaw(20.0)
            .unwrap()
            .with_center(0.3, -0.4)
            .unwrap();
        let (lo, hi) = room.bounds();
        let rebuilt = |(w, d, cx, cz): (f64, f64, f64, f64)| {
            Room::new(w, d, 2.8, 1.5)
                .unwrap()
                .with_yaw(20.0)
                .unwrap()
                .with_center(cx, cz)
                .unwrap()
        };
        // The floor edge of the front wall (z high, y 0, along X): dragged to a floor
        // point 40 cm further, the front wall moves there; the others stay.
        let k = Room::EDGES
            .iter()
            .position(|&(i, j)| (i ^ j) == 1 && i & 2 == 0 && i & 4 != 0)
            .unwrap();
        let cam = Camera::new(View::new(20.0, -30.0, 100.0).unwrap(), 320, 200);
        let target = DVec3::new(0.2, 0.0, hi.z + 0.4);
        let at = project_point(&room, &cam, target).unwrap();
        assert!(pick_room_edge(&room, &cam, at, 200.0).is_some());
        let (lo2, hi2) = rebuilt(drag_room_edge(&room, &cam, k, at).unwrap()).bounds();
        assert!((hi2.z - target.z).abs() < 1e-9, "{hi2}");
        assert!((lo2 - lo).length() < 1e-9 && (hi2.x - hi.x).abs() < 1e-9);
        // A vertical edge (x low, z high) dragged to a bearing 5° round at the same
        // distance: the corner goes there, both walls move.
        let k = Room::EDGES
            .iter()
            .position(|&(i, j)| (i ^ j) == 2 && i & 1 == 0 && i & 4 != 0)
            .unwrap();
        let c = DVec3::new(lo.x, 0.0, hi.z);
        let turned = glam::DQuat::from_rotation_y(5f64.to_radians()) * c;
        let cam = Camera::new(View::new(-10.0, 0.0, 100.0).unwrap(), 320, 200);
        let at = project_point(&room, &cam, turned + DVec3::Y * 1.2).unwrap();
        let (lo2, hi2) = rebuilt(drag_room_edge(&room, &cam, k, at).unwrap()).bounds();
        assert!((lo2.x - turned.x).abs() < 1e-9 && (hi2.z - turned.z).abs() < 1e-9);
        assert!((hi2.x - hi.x).abs() < 1e-9 && (lo2.z - lo.z).abs() < 1e-9);
        // Never past the camera.
        let far = drag_room_edge(&room, &cam, k, (319.0, 100.0)).unwrap();
        let (lo3, hi3) = rebuilt(far).bounds();
        assert!(lo3.x <= -0.05 + 1e-12 && hi3.z >= 0.05 - 1e-12);
    }

    #[test]
    fn lifted_edges_move_the_ceiling_or_the_floor() {
        let room = Room::new(4.0, 6.0, 2.8, 1.5)
            .unwrap()
            .with_yaw(-35.0)
            .unwrap()
            .with_center(0.3, -0.4)
            .unwrap();
        let (lo, hi) = room.bounds();
        let rebuilt = |(h, c): (f64, f64)| {
            Room::new(4.0, 6.0, h, c)
                .unwrap()
                .with_yaw(-35.0)
                .unwrap()
                .with_center(0.3, -0.4)
                .unwrap()
        };
        let edge = |a: usize, b: usize| Room::EDGES.iter().position(|&e| e == (a, b)).unwrap();
        // The ceiling edge on the low-z wall raised to 3.4 m; the floor edge on the
        // high-z wall lowered 0.3 m below the floor (and one on the low-x wall raised
        // 0.2 m): each lands where the cursor is, on its own wall.
        let xm = (lo.x + hi.x) / 2.0;
        let zm = (lo.z + hi.z) / 2.0;
        let view_of = |target: DVec3, pitch: f64| {
            (0..36)
                .map(|s| Camera::new(View::new(s as f64 * 10.0, pitch, 100.0).unwrap(), 320, 200))
                .find(|cam| {
                    project_point(&room, cam, target).is_some_and(|(x, y)| {
                        (0.0..320.0).contains(&x) && (0.0..200.0).contains(&y)
                    })
                })
                .expect("a view of the target")
        };
        for (k, target, want, pitch) in [
            (edge(2, 3), DVec3::new(xm, 3.4, lo.z), (3.4, 1.5), 20.0),
            (edge(4, 5), DVec3::new(xm, -0.3, hi.z), (3.1, 1.8), -30.0),
            (edge(0, 4), DVec3::new(lo.x, 0.2, zm), (2.6, 1.3), -30.0),
        ] {
            let (i, _) = Room::EDGES[k];
            let cam = view_of(target, pitch);
            let at = project_point(&room, &cam, target).unwrap();
            let got = drag_room_level(&room, &cam, k, at).unwrap();
            assert!(
                (got.0 - want.0).abs() < 1e-9 && (got.1 - want.1).abs() < 1e-9,
                "edge {k}: {got:?} vs {want:?}"
            );
            // The rebuilt room's edge passes under the cursor: its corner's height is the
            // target's, seen from the same camera.
            let moved = rebuilt(got);
            let mut p = target;
            p.y = moved.corners()[i].y;
            let seen = project_point(&moved, &cam, p).unwrap();
            assert!((seen.0 - at.0).abs() < 1e-6 && (seen.1 - at.1).abs() < 1e-6);
            assert_eq!(moved.bounds().0.x, lo.x);
            assert_eq!(moved.bounds().1.z, hi.z);
        }
        // Never past the camera: the ceiling edge dragged below eye level stops 5 cm
        // above it, the floor edge dragged above it 5 cm below.
        let low = DVec3::new(xm, 1.0, lo.z);
        let cam = view_of(low, -10.0);
        let at = project_point(&room, &cam, low).unwrap();
        let (h, c) = drag_room_level(&room, &cam, edge(2, 3), at).unwrap();
        assert!((h - 1.55).abs() < 1e-12 && c == 1.5, "{h} {c}");
        let high = DVec3::new(xm, 2.0, lo.z);
        let cam = view_of(high, 10.0);
        let at = project_point(&room, &cam, high).unwrap();
        let (h, c) = drag_room_level(&room, &cam, edge(0, 1), at).unwrap();
        assert!(
            (c - 0.05).abs() < 1e-12 && (h - 1.35).abs() < 1e-12,
            "{h} {c}"
        );
        // A vertical edge is not a level.
        assert!(drag_room_level(&room, &cam, edge(0, 2), (160.0, 100.0)).is_none());
    }

    #[test]
    fn dragged_room_corners_move_both_walls() {
        let room = Room::new(4.0, 6.0, 2.8, 1.5)
            .unwrap()
            .with_yaw(-25.0)
            .unwrap()
            .with_center(0.3, -0.4)
            .unwrap();
        let (lo, hi) = room.bounds();
        let rebuilt = |(w, d, cx, cz): (f64, f64, f64, f64)| {
            Room::new(w, d, 2.8, 1.5)
                .unwrap()
                .with_yaw(-25.0)
                .unwrap()
                .with_center(cx, cz)
                .unwrap()
        };
        // The floor corner at x high, z high, and the ceiling corner at x low, z low:
        // each dragged to a point of its floor / ceiling; picked under the cursor.
        for (corner, target, pitch) in [
            (1 | 4, DVec3::new(hi.x + 0.3, 0.0, hi.z - 0.5), -30.0),
            (2, DVec3::new(lo.x + 0.4, 2.8, lo.z - 0.2), 30.0),
        ] {
            // A view that sees both the corner and the target.
            let inside = |cam: &Camera, p: DVec3| {
                project_point(&room, cam, p)
                    .is_some_and(|(x, y)| (0.0..320.0).contains(&x) && (0.0..200.0).contains(&y))
            };
            let cam = (0..36)
                .map(|k| Camera::new(View::new(k as f64 * 10.0, pitch, 100.0).unwrap(), 320, 200))
                .find(|cam| inside(cam, room.corners()[corner]) && inside(cam, target))
                .expect("a view of the corner");
            let here = project_point(&room, &cam, room.corners()[corner]).unwrap();
            assert_eq!(pick_room_corner(&room, &cam, here, 6.0), Some(corner));
            assert_eq!(
                pick_room_corner(&room, &cam, (here.0 + 40.0, here.1), 6.0),
                None
            );
            let at = project_point(&room, &cam, target).unwrap();
            let moved = rebuilt(drag_room_corner(&room, &cam, corner, at).unwrap());
            let got = moved.corners()[corner];
            assert!(
                (got - target).length() < 1e-9,
                "{corner}: {got} vs {target}"
            );
            // The opposite walls stay.
            let (lo2, hi2) = moved.bounds();
            let opposite = moved.corners()[7 - corner];
            assert!((opposite - room.corners()[7 - corner]).length() < 1e-9);
            assert!((lo2.y - lo.y).abs() < 1e-12 && (hi2.y - hi.y).abs() < 1e-12);
        }
        // Never past the camera: a bottom corner dragged to a floor point behind it.
        let cam = Camera::new(View::new(0.0, -80.0, 100.0).unwrap(), 320, 200);
        let at = project_point(&room, &cam, DVec3::new(-0.5, 0.0, -0.5)).unwrap();
        let (_, hi3) = rebuilt(drag_room_corner(&room, &cam, 1 | 4, at).unwrap()).bounds();
        assert!(hi3.x >= 0.05 - 1e-12 && hi3.z >= 0.05 - 1e-12, "{hi3}");
        // The cursor above the horizon never meets the floor.
        let cam = Camera::new(View::new(0.0, 60.0, 60.0).unwrap(), 320, 200);
        assert!(drag_room_corner(&room, &cam, 1, (160.0, 100.0)).is_none());
    }

    #[test]
    fn markers_are_picked_near_the_cursor() {
        let mut st = crate::lighting::LightsState::default();
        st.load_and_add(&crate::lighting::sample_path()).unwrap();
        st.load_and_add(&crate::lighting::sample_path()).unwrap();
        let view = View::new(0.0, 60.0, 120.0).unwrap();
        let room = st.room_box().unwrap();
        let cam = Camera::new(view, 400, 300);
        let p1 = project_point(&room, &cam, DVec3::from(st.lights[1].position)).unwrap();
        assert_eq!(
            pick_light(&st, view, 400, 300, (p1.0 + 3.0, p1.1), 10.0),
            Some(1)
        );
        assert_eq!(
            pick_light(&st, view, 400, 300, (p1.0 + 30.0, p1.1 + 30.0), 10.0),
            None
        );
    }

    #[test]
    fn drawing_stays_inside_the_frame() {
        let mut f = vec![0u32; 50 * 40];
        draw_segment(
            &mut f,
            50,
            40,
            ((-100.0, -100.0), (300.0, 200.0)),
            2.0,
            0xffffff,
        );
        draw_segment(&mut f, 50, 40, ((10.0, 10.0), (10.0, 10.0)), 2.0, 0xffffff);
        draw_marker(&mut f, 50, 40, (49.0, 39.0), 5.0, 0xff0000);
        assert!(f.iter().any(|&p| p != 0));
    }
}
