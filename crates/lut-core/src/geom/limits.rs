//! Size limits every stage checks against: maps (stored and full panoramas) and output
//! frames.

/// Largest accepted map side. 65536 wide is the widest map whose fixed-point path is
/// tested (see `tests/stability.rs`); the table format allows up to 131068.
pub const MAX_MAP_WIDTH: u32 = 65536;
/// Largest accepted map height.
pub const MAX_MAP_HEIGHT: u32 = 65536;
/// Largest accepted pixel count of a map (32768 × 16384 × 2).
pub const MAX_MAP_PIXELS: u64 = 1 << 30;

/// Largest accepted output side, in pixels (per side). 16384 keeps a frame under 1 GiB.
pub const MAX_OUTPUT_SIDE: u32 = 16384;
