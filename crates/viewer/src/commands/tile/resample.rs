//! A streaming, separable resampler of RGB8 rows: rows go in one at a time (or a band at
//! a time, resampled across in parallel), finished output rows come out as soon as every
//! input row they depend on has arrived, so a face of any size is resized holding a few
//! rows. Shrinking averages areas (each output pixel the exact coverage-weighted mean of
//! the input pixels under it: a 2×2 box for an even side halved, fractional weights for
//! generate.py's `int(size / 2)` of an odd side); enlarging (a fallback face larger than
//! the cube face) is linear between pixel centres, edges clamped.

use rayon::prelude::*;
use std::collections::VecDeque;

/// The weights of one output index: input indices `start..start + w.len()`.
#[derive(Debug, Clone)]
struct Taps {
    start: u32,
    w: Vec<f32>,
}

fn taps(input: u32, output: u32) -> Vec<Taps> {
    let scale = f64::from(input) / f64::from(output);
    (0..output)
        .map(|j| {
            let mut t = if scale >= 1.0 {
                // area: [j·scale, (j+1)·scale)
                let a = f64::from(j) * scale;
                let b = (f64::from(j + 1) * scale).min(f64::from(input));
                let first = a.floor() as u32;
                let last = (b.ceil() as u32).clamp(first + 1, input);
                let w = (first..last)
                    .map(|i| {
                        let lo = a.max(f64::from(i));
                        let hi = b.min(f64::from(i + 1));
                        ((hi - lo).max(0.0) / (b - a)) as f32
                    })
                    .collect();
                Taps { start: first, w }
            } else {
                // linear between centres: c in input pixel-centre coordinates
                let c = (f64::from(j) + 0.5) * scale - 0.5;
                let i0 = c.floor();
                let f = (c - i0) as f32;
                let lo = (i0.max(0.0) as u32).min(input - 1);
                let hi = ((i0 + 1.0).max(0.0) as u32).min(input - 1);
                if lo == hi {
                    Taps {
                        start: lo,
                        w: vec![1.0],
                    }
                } else {
                    Taps {
                        start: lo,
                        w: vec![1.0 - f, f],
                    }
                }
            };
            // drop zero-weight ends (keeps the streaming window tight)
            while t.w.len() > 1 && t.w[t.w.len() - 1] == 0.0 {
                t.w.pop();
            }
            while t.w.len() > 1 && t.w[0] == 0.0 {
                t.w.remove(0);
                t.start += 1;
            }
            t
        })
        .collect()
}

/// Resample a row of `RGB8` pixels across (`src` holds `in_w` pixels) into `dst` (f32).
fn across(h: &[Taps], src: &[u8], dst: &mut [f32]) {
    for (t, d) in h.iter().zip(dst.chunks_exact_mut(3)) {
        let mut acc = [0f32; 3];
        let s = t.start as usize * 3;
        for (k, w) in t.w.iter().enumerate() {
            let p = &src[s + 3 * k..s + 3 * k + 3];
            acc[0] += w * f32::from(p[0]);
            acc[1] += w * f32::from(p[1]);
            acc[2] += w * f32::from(p[2]);
        }
        d.copy_from_slice(&acc);
    }
}

/// Two input rows halved into one output row (RGB8, 2 × 2 means rounded half up).
fn halve_pair(a: &[u8], b: &[u8], out: &mut [u8]) {
    for ((o, a), b) in out
        .chunks_exact_mut(3)
        .zip(a.chunks_exact(6))
        .zip(b.chunks_exact(6))
    {
        for c in 0..3 {
            let s = u16::from(a[c]) + u16::from(a[c + 3]) + u16::from(b[c]) + u16::from(b[c + 3]);
            o[c] = ((s + 2) >> 2) as u8;
        }
    }
}

/// A streaming resampler from `in_w × in_h` to `out_w × out_h` (RGB8).
#[derive(Debug)]
pub struct Resampler {
    in_w: u32,
    out_w: u32,
    h: Vec<Taps>,
    v: Vec<Taps>,
    next_in: u32,
    next_start: u32,
    pending: VecDeque<(u32, Vec<f32>)>,
    /// Exactly halving both sides (even to half): 2 × 2 means in integers, the
    /// output rows emitted so far and an input row waiting for its pair.
    halving: Option<(u32, Option<Vec<u8>>)>,
}

impl Resampler {
    /// A resampler from `input` (w, h) to `output` (w, h); every side at least 1.
    pub fn new(input: (u32, u32), output: (u32, u32)) -> Resampler {
        debug_assert!(input.0 > 0 && input.1 > 0 && output.0 > 0 && output.1 > 0);
        Resampler {
            in_w: input.0,
            out_w: output.0,
            h: taps(input.0, output.0),
            v: taps(input.1, output.1),
            next_in: 0,
            next_start: 0,
            pending: VecDeque::new(),
            halving: (input.0 == 2 * output.0 && input.1 == 2 * output.1).then_some((0, None)),
        }
    }

    /// Output rows finished so far are all there are (every input row went in).
    pub fn done(&self) -> bool {
        if let Some((out_rows, carry)) = &self.halving {
            return *out_rows as usize == self.v.len() && carry.is_none();
        }
        self.next_start as usize == self.v.len() && self.pending.is_empty()
    }

    /// [`Resampler::push_rows`] when halving: each output texel the rounded mean of its
    /// 2 × 2 input texels, `(a + b + c + d + 2) >> 2`: what the general path computes in
    /// f32 (weights ½ are exact, and its rounding is half up), at a fraction of the cost.
    fn push_halving(&mut self, mut rows: &[u8], emit: &mut dyn FnMut(&[u8])) {
        let in_row = 3 * self.in_w as usize;
        let out_row = 3 * self.out_w as usize;
        let Some((out_rows, carry)) = self.halving.as_mut() else {
            return;
        };
        if let Some(first) = carry.take() {
            if rows.len() < in_row {
                *carry = Some(first);
                return;
            }
            let (second, rest) = rows.split_at(in_row);
            let mut out = vec![0u8; out_row];
            halve_pair(&first, second, &mut out);
            emit(&out);
            *out_rows += 1;
            rows = rest;
        }
        let pairs = rows.len() / (2 * in_row);
        let mut outs = vec![0u8; pairs * out_row];
        outs.par_chunks_mut(out_row)
            .zip(rows.par_chunks_exact(2 * in_row))
            .with_min_len(4)
            .for_each(|(o, pair)| halve_pair(&pair[..in_row], &pair[in_row..], o));
        for o in outs.chunks_exact(out_row) {
            emit(o);
        }
        *out_rows += pairs as u32;
        let rest = &rows[pairs * 2 * in_row..];
        if !rest.is_empty() {
            *carry = Some(rest.to_vec());
        }
    }

    /// Push a band of whole input rows (`3 · in_w` bytes each, in order); each finished
    /// output row (`3 · out_w` bytes) is passed to `emit` in order.
    pub fn push_rows(&mut self, rows: &[u8], emit: &mut dyn FnMut(&[u8])) {
        let in_row = 3 * self.in_w as usize;
        let out_row = 3 * self.out_w as usize;
        debug_assert_eq!(rows.len() % in_row, 0);
        if self.halving.is_some() {
            self.push_halving(rows, emit);
            return;
        }
        let n = rows.len() / in_row;
        let mut across_rows = vec![0f32; n * out_row];
        let h = &self.h;
        across_rows
            .par_chunks_mut(out_row)
            .zip(rows.par_chunks(in_row))
            .with_min_len(8)
            .for_each(|(d, s)| across(h, s, d));
        let mut out = vec![0u8; out_row];
        for row in across_rows.chunks_exact(out_row) {
            let r = self.next_in;
            self.next_in += 1;
            while (self.next_start as usize) < self.v.len()
                && self.v[self.next_start as usize].start <= r
            {
                self.pending
                    .push_back((self.next_start, vec![0f32; out_row]));
                self.next_start += 1;
            }
            for (j, acc) in self.pending.iter_mut() {
                let t = &self.v[*j as usize];
                if r >= t.start && ((r - t.start) as usize) < t.w.len() {
                    let w = t.w[(r - t.start) as usize];
                    for (a, x) in acc.iter_mut().zip(row) {
                        *a += w * x;
                    }
                }
            }
            while let Some((j, _)) = self.pending.front() {
                let t = &self.v[*j as usize];
                if t.start as usize + t.w.len() - 1 > r as usize {
                    break;
                }
                let (_, acc) = self.pending.pop_front().expect("front exists");
                for (o, a) in out.iter_mut().zip(&acc) {
                    // round half up (a ≥ 0), no library call (`f32::round` is one)
                    *o = (a.clamp(0.0, 255.0) + 0.5) as u8;
                }
                emit(&out);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Resample a whole image at once (the reference: every output pixel the exact
    /// coverage-weighted mean, computed in f64 from the definition).
    fn area_reference(src: &[u8], w: u32, h: u32, ow: u32, oh: u32) -> Vec<u8> {
        let (sx, sy) = (f64::from(w) / f64::from(ow), f64::from(h) / f64::from(oh));
        let overlap =
            |a: f64, b: f64, i: u32| (b.min(f64::from(i + 1)) - a.max(f64::from(i))).max(0.0);
        let mut out = vec![0u8; (ow * oh * 3) as usize];
        for y in 0..oh {
            for x in 0..ow {
                let (ax, bx) = (f64::from(x) * sx, f64::from(x + 1) * sx);
                let (ay, by) = (f64::from(y) * sy, f64::from(y + 1) * sy);
                for c in 0..3 {
                    let mut acc = 0.0;
                    for iy in 0..h {
                        for ix in 0..w {
                            let a = overlap(ax, bx, ix) * overlap(ay, by, iy);
                            acc += a * f64::from(src[((iy * w + ix) * 3 + c) as usize]);
                        }
                    }
                    out[((y * ow + x) * 3 + c) as usize] = (acc / (sx * sy)).round() as u8;
                }
            }
        }
        out
    }

    fn noise(w: u32, h: u32) -> Vec<u8> {
        let mut s = 0x1234_5678u32;
        (0..w * h * 3)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                (s >> 24) as u8
            })
            .collect()
    }

    fn run(src: &[u8], w: u32, h: u32, ow: u32, oh: u32, band: usize) -> Vec<u8> {
        let mut r = Resampler::new((w, h), (ow, oh));
        let mut out = Vec::new();
        for rows in src.chunks(band * 3 * w as usize) {
            r.push_rows(rows, &mut |row| out.extend_from_slice(row));
        }
        assert!(r.done());
        out
    }

    #[test]
    fn area_shrink_equals_the_definition_for_odd_and_even_sides() {
        for (w, h) in [(8, 8), (13, 13), (7, 5), (1, 3)] {
            let src = noise(w, h);
            let (ow, oh) = ((w / 2).max(1), (h / 2).max(1));
            let want = area_reference(&src, w, h, ow, oh);
            for band in [1, 3, 64] {
                let got = run(&src, w, h, ow, oh, band);
                let worst = got.iter().zip(&want).map(|(a, b)| a.abs_diff(*b)).max();
                assert!(worst <= Some(1), "{w}x{h} band {band}: {worst:?}");
            }
        }
    }

    #[test]
    fn halving_equals_the_general_path_byte_for_byte() {
        for (w, h) in [(8u32, 8u32), (14, 6), (2, 2), (40, 22)] {
            let src = noise(w, h);
            for band in [1, 3, 4, 7, 64] {
                let fast = run(&src, w, h, w / 2, h / 2, band);
                let mut r = Resampler::new((w, h), (w / 2, h / 2));
                r.halving = None;
                let mut slow = Vec::new();
                for rows in src.chunks(band * 3 * w as usize) {
                    r.push_rows(rows, &mut |row| slow.extend_from_slice(row));
                }
                assert!(r.done());
                assert_eq!(fast, slow, "{w}x{h} band {band}");
                // and both are the exact means, rounded half up
                let want = area_reference(&src, w, h, w / 2, h / 2);
                assert_eq!(fast, want, "{w}x{h}");
            }
        }
    }

    #[test]
    fn enlarging_is_linear_and_keeps_flat_colour() {
        let src: Vec<u8> = [10u8, 200, 30].repeat(5 * 5);
        let got = run(&src, 5, 5, 12, 12, 2);
        assert_eq!(got.len(), 12 * 12 * 3);
        assert!(got.chunks(3).all(|p| p == [10, 200, 30]));
        // a ramp stays a ramp between the centres
        let ramp: Vec<u8> = (0..4u8).flat_map(|x| [x * 60, 0, 0]).collect();
        let got = run(&ramp, 4, 1, 8, 1, 1);
        let reds: Vec<u8> = got.chunks(3).map(|p| p[0]).collect();
        assert_eq!(reds, [0, 15, 45, 75, 105, 135, 165, 180]);
    }
}
