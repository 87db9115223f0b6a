//! Scratch probe (not committed): single-thread frame times for the LUT kernels.
use lut_core::lut::Surface;
use lut_core::synth::grid_map;
use lut_core::{
    IndexStep, LutChoice, Projection, RenderOptions, Renderer, RendererKind, Sampler, View,
};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let frames: u32 = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(20);
    let map = grid_map(8192, 4096, Projection::Equirect).expect("map");
    let mut r = Renderer::new(&map);
    let (w, h) = (1920u32, 1080u32);
    let mut out = vec![0u32; (w * h) as usize];
    let step = match std::env::var("STEP").ok().and_then(|s| s.parse().ok()) {
        Some(n) => IndexStep::Fixed(n),
        None => IndexStep::Adaptive,
    };
    for sampler in [Sampler::Nearest, Sampler::Bilinear] {
        let o = RenderOptions {
            renderer: RendererKind::Lut,
            sampler,
            index_step: step,
            lut: LutChoice::Wide,
            surface: Surface::Cylinder,
            threads: false,
        };
        let rep = r
            .render(
                &map,
                View::new(0.0, 10.0, 90.0).unwrap(),
                &o,
                &mut out,
                w,
                h,
            )
            .unwrap();
        println!("{rep:?}");
        let mut ts = vec![];
        for f in 0..frames {
            let v =
                View::new((f as f64 * 7.3) % 360.0, 10.0 + (f % 5) as f64 * 10.0, 90.0).unwrap();
            let t = Instant::now();
            r.render(&map, v, &o, &mut out, w, h).unwrap();
            ts.push(t.elapsed().as_secs_f64() * 1e3);
        }
        ts.sort_by(|a, b| a.partial_cmp(b).unwrap());
        println!(
            "{:?}: median {:.2} ms min {:.2}",
            sampler,
            ts[ts.len() / 2],
            ts[0]
        );
    }
}
