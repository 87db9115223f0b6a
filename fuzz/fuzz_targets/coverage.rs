//! The `--coverage HFOVxVFOV[±YAW±PITCH]` grammar, the crop it gives an image, and the
//! view limit inside it for a few views and frame sizes.
#![no_main]
use libfuzzer_sys::fuzz_target;
use lut_core::{limit_view, Coverage, View};

fuzz_target!(|data: &[u8]| {
    let Ok(s) = std::str::from_utf8(data) else {
        return;
    };
    match s.parse::<Coverage>() {
        Err(e) => assert!(!e.to_string().is_empty()),
        Ok(c) => {
            assert!(c.hfov() > 0.0 && c.hfov() <= 360.0 && c.vfov() > 0.0 && c.vfov() <= 180.0);
            for (w, h) in [(512u32, 256u32), (1, 1), (7, 3000)] {
                let _ = c.crop_for_image(w, h);
            }
            // One view per input, picked by its length.
            let views = [(0.0, 0.0, 90.0), (179.0, 89.0, 170.0), (-30.0, -60.0, 1.0)];
            {
                let (yaw, pitch, hfov) = views[s.len() % views.len()];
                let v = View::new(yaw, pitch, hfov).unwrap();
                let l = limit_view(v, 640, 480, &c);
                assert!(
                    l.hfov_deg().is_finite()
                        && l.yaw_deg().is_finite()
                        && l.pitch_deg().is_finite()
                );
            }
        }
    }
});
