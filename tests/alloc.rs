//! The LUT renderer allocates nothing per frame after the first (single-threaded; with
//! threads the only allocations are rayon's own job bookkeeping).

use lut_core::Frame;
use lut_core::{Projection, RenderOptions, Renderer, View};
use test_support::alloc::Counting;

#[global_allocator]
static GLOBAL: Counting = Counting::new();

#[test]
fn no_allocation_per_frame_after_the_first() {
    let map = lut_core::grid_map(1024, 512, Projection::Equirect).unwrap();
    let mut r = Renderer::new(&map);
    let (w, h) = (320u32, 200u32);
    let mut out = vec![0u32; (w * h) as usize];
    let opts = RenderOptions {
        threads: false,
        ..RenderOptions::default()
    };
    // First frames build the tables (both kinds) and size the scratch.
    for hfov in [90.0, 40.0] {
        r.render(
            &map,
            View::new(0.0, 0.0, hfov).unwrap(),
            &opts,
            &mut Frame::new(&mut out, w, h).unwrap(),
        )
        .unwrap();
    }
    let before = GLOBAL.calls();
    // Turning, zooming across the table switch, looking at the poles and the seam.
    for (yaw, pitch, hfov) in [
        (30.0, 10.0, 90.0),
        (180.0, 90.0, 120.0),
        (-170.0, -89.9, 40.0),
        (1e6, 45.0, 59.0),
    ] {
        r.render(
            &map,
            View::new(yaw, pitch, hfov).unwrap(),
            &opts,
            &mut Frame::new(&mut out, w, h).unwrap(),
        )
        .unwrap();
    }
    let after = GLOBAL.calls();
    assert_eq!(
        after - before,
        0,
        "the renderer allocated {} times in 4 frames",
        after - before
    );
}
