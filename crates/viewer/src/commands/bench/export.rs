//! `viewer bench --export-maps DIR`: for the hfov-90 set, the source map (`map.rgb`, raw
//! RGB24), the exact sampling maps in OpenCV's convention (`mapx_NN.f32` /
//! `mapy_NN.f32` = u − ½, v − ½, NaN for the background), the exact renders
//! (`exact_{nearest,bilinear}_NN.rgb`) and `views.json`, for `scripts/peers.py`.

use crate::output::rgb24;
use anyhow::{Context, Result};
use lut_core::View;
use std::path::{Path, PathBuf};

/// An export in progress: the folder and the views written so far.
pub struct Export {
    dir: PathBuf,
    manifest: Vec<serde_json::Value>,
}

/// Write `bytes` to `path`, naming the file in the error.
fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).with_context(|| format!("{}: cannot write", path.display()))
}

impl Export {
    /// Create `dir` (if missing) and write the map's unpadded pixels `src` to `map.rgb`.
    ///
    /// # Errors
    /// A folder or file that cannot be written.
    pub fn start(dir: &Path, src: &[u32]) -> Result<Export> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create the export folder", dir.display()))?;
        write(&dir.join("map.rgb"), &rgb24(src))?;
        Ok(Export {
            dir: dir.to_path_buf(),
            manifest: Vec::new(),
        })
    }

    /// Views written so far.
    pub fn len(&self) -> usize {
        self.manifest.len()
    }

    /// Whether no view was written yet.
    pub fn is_empty(&self) -> bool {
        self.manifest.is_empty()
    }

    /// Write view `vi`: its exact positions (`exact`: per pixel the map position, if any,
    /// and the latitude) and its exact nearest and bilinear images.
    ///
    /// # Errors
    /// A file that cannot be written.
    pub fn view(
        &mut self,
        vi: usize,
        view: View,
        exact: &[(Option<(f64, f64)>, f64)],
        imgs: &[Vec<u32>; 2],
    ) -> Result<()> {
        let mut mx = Vec::with_capacity(exact.len() * 4);
        let mut my = Vec::with_capacity(exact.len() * 4);
        for (uv, _) in exact {
            let (u, v) = uv.map_or((f32::NAN, f32::NAN), |(u, v)| {
                ((u - 0.5) as f32, (v - 0.5) as f32)
            });
            mx.extend_from_slice(&u.to_le_bytes());
            my.extend_from_slice(&v.to_le_bytes());
        }
        let names = [
            format!("mapx_{vi:02}.f32"),
            format!("mapy_{vi:02}.f32"),
            format!("exact_nearest_{vi:02}.rgb"),
            format!("exact_bilinear_{vi:02}.rgb"),
        ];
        write(&self.dir.join(&names[0]), &mx)?;
        write(&self.dir.join(&names[1]), &my)?;
        write(&self.dir.join(&names[2]), &rgb24(&imgs[0]))?;
        write(&self.dir.join(&names[3]), &rgb24(&imgs[1]))?;
        self.manifest.push(serde_json::json!({
            "yaw": view.yaw_deg(), "pitch": view.pitch_deg(), "hfov": view.hfov_deg(),
            "mapx": names[0], "mapy": names[1],
            "exact_bilinear": names[3],
            "exact_nearest": names[2],
        }));
        Ok(())
    }

    /// Write `views.json`: the map's size, the output size, the threads, the convention
    /// and every view written.
    ///
    /// # Errors
    /// A file that cannot be written.
    pub fn finish(self, map: (u32, u32), size: (u32, u32)) -> Result<()> {
        let doc = serde_json::json!({
            "map": "map.rgb", "map_width": map.0, "map_height": map.1,
            "width": size.0, "height": size.1, "threads": rayon::current_num_threads(),
            "convention": "mapx/mapy: float32, row-major, OpenCV pixel centers (u - 0.5, v - 0.5); NaN = background",
            "views": self.manifest,
        });
        std::fs::write(
            self.dir.join("views.json"),
            serde_json::to_string_pretty(&doc)?,
        )
        .with_context(|| format!("{}: cannot write views.json", self.dir.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_follow_the_opencv_convention() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("export");
        let mut ex = Export::start(&dir, &[0x0001_0203, 0x0004_0506]).unwrap();
        assert_eq!(
            std::fs::read(dir.join("map.rgb")).unwrap(),
            [1, 2, 3, 4, 5, 6]
        );
        let exact = [(Some((10.5, 3.25)), 0.1), (None, 0.0)];
        let imgs = [vec![0x00FF_0000, 0], vec![0x0000_FF00, 1]];
        ex.view(7, View::new(30.0, -10.0, 90.0).unwrap(), &exact, &imgs)
            .unwrap();
        let floats = |name: &str| -> Vec<f32> {
            std::fs::read(dir.join(name))
                .unwrap()
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
                .collect()
        };
        let mx = floats("mapx_07.f32");
        let my = floats("mapy_07.f32");
        assert_eq!((mx[0], my[0]), (10.0, 2.75));
        assert!(mx[1].is_nan() && my[1].is_nan());
        assert_eq!(
            std::fs::read(dir.join("exact_bilinear_07.rgb")).unwrap(),
            [0, 255, 0, 0, 0, 1]
        );
        ex.finish((2, 1), (2, 1)).unwrap();
        let doc: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("views.json")).unwrap()).unwrap();
        assert_eq!(doc["map_width"], 2);
        assert_eq!(doc["views"][0]["yaw"], 30.0);
        assert_eq!(doc["views"][0]["exact_nearest"], "exact_nearest_07.rgb");
    }
}
