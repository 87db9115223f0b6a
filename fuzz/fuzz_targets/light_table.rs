//! The light table built from an IES or EULUMDAT file (format chosen by content, as
//! `viewer ies` and `--light` do): symmetry folding, constant ranges, the distance
//! series; candela lookups anywhere must be finite and non-negative.
#![no_main]
use libfuzzer_sys::fuzz_target;
use lut_core::{LightTable, Photometry, TableOptions};
use lutpano_fuzz::text;

fuzz_target!(|data: &[u8]| {
    let Ok(p) = Photometry::parse(&text(data), "fuzz") else {
        return;
    };
    let Ok(table) = LightTable::from_photometry(&p, &TableOptions::default()) else {
        return;
    };
    for (v, h) in [
        (0.0, 0.0),
        (45.0, 90.0),
        (90.0, 180.0),
        (180.0, 359.0),
        (-10.0, 725.0),
    ] {
        let c = table.candela(v, h);
        assert!(c.is_finite() && c >= 0.0, "candela {c} at {v},{h}");
    }
    assert!(table.luminous_flux().is_finite());
});
