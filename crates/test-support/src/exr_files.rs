//! Small OpenEXR files written by the `exr` crate, for the loader's tests and the fuzz
//! seeds: any channels, compression and block layout, half or full floats.

use exr::prelude::*;

/// The value [`exr_file`] stores at `(x, y)` of its channel number `c` (0-based) in an
/// image `w` wide: a ramp per channel, negative at the left (the loader must clamp).
pub fn exr_value(c: usize, x: usize, y: usize, w: usize) -> f32 {
    (x as f32 / w as f32) * (c as f32 + 0.5) + y as f32 * 0.05 - 0.1
}

/// A `w × h` single-part EXR with channels `names` (each filled by [`exr_value`]),
/// `compression`, scan lines or tiles (`blocks`), as f16 (`half`) or f32 samples.
pub fn exr_file(
    w: usize,
    h: usize,
    names: &[&str],
    compression: Compression,
    blocks: Blocks,
    half: bool,
) -> Vec<u8> {
    let chans: Vec<AnyChannel<FlatSamples>> = names
        .iter()
        .enumerate()
        .map(|(c, n)| {
            let v = (0..w * h).map(|p| exr_value(c, p % w, p / w, w));
            let samples = if half {
                FlatSamples::F16(v.map(f16::from_f32).collect())
            } else {
                FlatSamples::F32(v.collect())
            };
            AnyChannel::new(*n, samples)
        })
        .collect();
    let layer = Layer::new(
        (w, h),
        LayerAttributes::default(),
        Encoding {
            compression,
            blocks,
            line_order: LineOrder::Increasing,
        },
        AnyChannels::sort(chans.into()),
    );
    let mut out = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .expect("write an EXR in memory");
    out.into_inner()
}

/// Every compression `exr` writes, with a short name.
pub fn compressions() -> [(&'static str, Compression); 10] {
    [
        ("none", Compression::Uncompressed),
        ("rle", Compression::RLE),
        ("zip1", Compression::ZIP1),
        ("zip16", Compression::ZIP16),
        ("piz", Compression::PIZ),
        ("pxr24", Compression::PXR24),
        ("b44", Compression::B44),
        ("b44a", Compression::B44A),
        ("dwaa", Compression::DWAA(None)),
        ("dwab", Compression::DWAB(None)),
    ]
}
