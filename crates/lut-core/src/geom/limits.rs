//! The limits module: every number that sizes work or memory, in one place, each checked
//! before any work (with [`check_limit`](crate::check_limit), whose message names the
//! value and the limit). docs/reliability.md lists them with their reasons; new input
//! paths (tours, tiled pyramids) check theirs here too.

/// Largest accepted map side. 65536 wide is the widest map whose fixed-point path is
/// tested (see `tests/stability.rs`); the table format allows up to 131068.
pub const MAX_MAP_WIDTH: u32 = 65536;
/// Largest accepted map height.
pub const MAX_MAP_HEIGHT: u32 = 65536;
/// Largest accepted pixel count of a map (32768 × 16384 × 2).
pub const MAX_MAP_PIXELS: u64 = 1 << 30;

/// Largest accepted output side, in pixels (per side). 16384 keeps a frame under 1 GiB.
pub const MAX_OUTPUT_SIDE: u32 = 16384;

/// Largest room side (width, depth or height), metres: a sports hall or a church nave;
/// a room typed in millimetres (`--room 4170x2990x2700`) is refused with this limit in
/// the message instead of asking for hundreds of gigabytes of illuminance map.
pub const MAX_ROOM_SIDE: f64 = 100.0;
/// Most luminaires in one scene (command line and scene file together): each one is
/// evaluated at every node of the illuminance map and every lit pixel.
pub const MAX_LIGHTS: usize = 200;
/// Most nodes of one illuminance map (16 MiB of `f32`): a larger room gets coarser nodes
/// instead of more of them, so the map's memory does not grow with the room.
pub const MAX_ILLUM_NODES: usize = 4 << 20;
/// Most node × luminaire evaluations to build one illuminance map (a few seconds of one
/// core): with many luminaires the nodes get coarser, so building takes bounded time.
pub const MAX_ILLUM_WORK: usize = 256 << 20;
/// Largest factor a luminaire's intensity may be multiplied by (`--light-multiplier`,
/// a scene's `light_multiplier` and each light's `multiplier`): far beyond any real
/// dimmer or lamp count, and small enough that illuminance stays a finite number.
pub const MAX_LIGHT_MULTIPLIER: f64 = 1e6;
/// Largest scene file read, bytes (a scene of [`MAX_LIGHTS`] luminaires is about 50 KB).
pub const MAX_SCENE_FILE_BYTES: u64 = 4 << 20;
/// Largest settings file read, bytes (the window writes about 1 KB).
pub const MAX_SETTINGS_FILE_BYTES: u64 = 1 << 20;
/// Largest tour file read (a Pannellum config or a Marzipano `data.js`), bytes: text,
/// and 64 MiB holds [`MAX_TOUR_SCENES`] scenes of many hotspots each.
pub const MAX_TOUR_FILE_BYTES: u64 = 64 << 20;
/// Most scenes of one tour read; the rest are left out with a problem naming the limit.
pub const MAX_TOUR_SCENES: usize = 10_000;
/// Most hotspots of one tour scene read; the rest are left out with a problem naming
/// the limit.
pub const MAX_TOUR_HOTSPOTS: usize = 10_000;
/// Longest string of a tour file (a scene id, a title, a hotspot's text, a path), bytes:
/// a longer one is a syntax error naming the limit. What is shown of one is shortened
/// further ([`crate::guard::shown`]).
pub const MAX_TOUR_STRING_BYTES: usize = 1 << 20;
