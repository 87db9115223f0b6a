//! GPano XMP metadata (Google's Photo Sphere fields) read from JPEG bytes.
//!
//! Phones and stitchers place a partial equirectangular panorama in its full panorama
//! with these fields of the namespace `http://ns.google.com/photos/1.0/panorama/`:
//! `FullPanoWidthPixels`, `FullPanoHeightPixels`, `CroppedAreaLeftPixels`,
//! `CroppedAreaTopPixels`, `CroppedAreaImageWidthPixels`, `CroppedAreaImageHeightPixels`,
//! and `PoseHeadingDegrees` (compass heading of the panorama's centre column); and the
//! start view viewers open at, `InitialViewHeadingDegrees` (a compass heading, so the yaw
//! is it minus `PoseHeadingDegrees`), `InitialViewPitchDegrees` and
//! `InitialHorizontalFOVDegrees` ([`GPano::start_view`]).
//!
//! The XMP packet is the JPEG APP1 segment that starts with
//! `http://ns.adobe.com/xap/1.0/\0`; it is parsed as XML (roxmltree) with namespaces
//! resolved, so both forms real files use are read: attributes
//! (`<rdf:Description GPano:FullPanoWidthPixels="8000" …/>`) and elements
//! (`<GPano:FullPanoWidthPixels>8000</GPano:FullPanoWidthPixels>`), whatever prefix the
//! writer chose. Extended XMP (`http://ns.adobe.com/xmp/extension/` segments, where
//! Photo Sphere cameras put depth maps and other bulky data) is not read: GPano lives in
//! the main packet, and a missing or truncated extension changes nothing.
//!
//! Rules (see [`GPano::crop_for_image`]):
//! * no XMP, no GPano fields, or XMP without the word "GPano" that does not parse: not a
//!   partial panorama (`Ok(None)`);
//! * XMP mentioning GPano that does not parse, non-numeric or negative values, a
//!   `ProjectionType` other than equirectangular, an incomplete set of crop fields, or a
//!   crop outside the full panorama: an error naming the field;
//! * the start view is a hint: a value there that does not parse, is not finite, or an
//!   hfov outside (0, 180) is ignored, never an error;
//! * `FullPanoHeightPixels` missing: half the full width (a 2:1 panorama);
//! * `CroppedAreaLeftPixels` must be a column of the full panorama (below
//!   `FullPanoWidthPixels`): a left edge of 4 000 000 000 on a 512-pixel panorama is an
//!   error, not wrapped around millions of times; a crop running past the right edge
//!   continues at column 0 (it straddles the ±180° seam);
//! * an image whose size differs from `CroppedAreaImage{Width,Height}Pixels` (the usual
//!   case after resizing a phone panorama): every pixel value is scaled by
//!   `image width / CroppedAreaImageWidthPixels`, provided the height agrees within 1 %;
//!   otherwise an error.

use crate::error::{CoverageError, GPanoError};
use crate::geom::coverage::{Crop, StartView};
use crate::geom::limits::MAX_MAP_WIDTH;

/// The GPano namespace URI.
pub const GPANO_NS: &str = "http://ns.google.com/photos/1.0/panorama/";
/// The signature that opens a JPEG APP1 segment holding the main XMP packet.
pub const XMP_SIGNATURE: &[u8] = b"http://ns.adobe.com/xap/1.0/\0";

/// The GPano fields of one file (pixel values as written, not yet checked against the
/// image).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GPano {
    /// `FullPanoWidthPixels`.
    pub full_pano_width_pixels: Option<f64>,
    /// `FullPanoHeightPixels`.
    pub full_pano_height_pixels: Option<f64>,
    /// `CroppedAreaLeftPixels`.
    pub cropped_area_left_pixels: Option<f64>,
    /// `CroppedAreaTopPixels`.
    pub cropped_area_top_pixels: Option<f64>,
    /// `CroppedAreaImageWidthPixels`.
    pub cropped_area_image_width_pixels: Option<f64>,
    /// `CroppedAreaImageHeightPixels`.
    pub cropped_area_image_height_pixels: Option<f64>,
    /// `PoseHeadingDegrees`.
    pub pose_heading_degrees: Option<f64>,
    /// `PosePitchDegrees` (the horizon's pitch: Pannellum's `horizonPitch`).
    pub pose_pitch_degrees: Option<f64>,
    /// `PoseRollDegrees` (the horizon's roll: Pannellum's `horizonRoll`).
    pub pose_roll_degrees: Option<f64>,
    /// `ProjectionType`, when given.
    pub projection_type: Option<String>,
    /// `InitialViewHeadingDegrees` (compass heading of the start view).
    pub initial_view_heading_degrees: Option<f64>,
    /// `InitialViewPitchDegrees`.
    pub initial_view_pitch_degrees: Option<f64>,
    /// `InitialHorizontalFOVDegrees`.
    pub initial_horizontal_fov_degrees: Option<f64>,
}

/// The start view fields: hints, ignored when they do not parse.
const VIEW_FIELDS: [&str; 3] = [
    "InitialViewHeadingDegrees",
    "InitialViewPitchDegrees",
    "InitialHorizontalFOVDegrees",
];

const FIELDS: [&str; 13] = [
    "FullPanoWidthPixels",
    "FullPanoHeightPixels",
    "CroppedAreaLeftPixels",
    "CroppedAreaTopPixels",
    "CroppedAreaImageWidthPixels",
    "CroppedAreaImageHeightPixels",
    "PoseHeadingDegrees",
    "PosePitchDegrees",
    "PoseRollDegrees",
    "ProjectionType",
    "InitialViewHeadingDegrees",
    "InitialViewPitchDegrees",
    "InitialHorizontalFOVDegrees",
];

impl GPano {
    /// True when any of the crop fields is present (the file claims to be a crop).
    pub fn has_crop(&self) -> bool {
        [
            self.full_pano_width_pixels,
            self.full_pano_height_pixels,
            self.cropped_area_left_pixels,
            self.cropped_area_top_pixels,
            self.cropped_area_image_width_pixels,
            self.cropped_area_image_height_pixels,
        ]
        .iter()
        .any(Option::is_some)
    }

    /// The start view the file asks for, relative to the map (yaw = the initial
    /// heading minus `PoseHeadingDegrees`, which counts as 0 when missing); `None`
    /// without `InitialViewHeadingDegrees` and `InitialViewPitchDegrees`.
    pub fn start_view(&self) -> Option<StartView> {
        if self.initial_view_heading_degrees.is_none() && self.initial_view_pitch_degrees.is_none()
        {
            return None;
        }
        let heading = self.initial_view_heading_degrees.unwrap_or(0.0);
        let yaw =
            (heading - self.pose_heading_degrees.unwrap_or(0.0) + 180.0).rem_euclid(360.0) - 180.0;
        Some(StartView {
            yaw_deg: yaw,
            pitch_deg: self
                .initial_view_pitch_degrees
                .unwrap_or(0.0)
                .clamp(-90.0, 90.0),
            hfov_deg: self.initial_horizontal_fov_degrees,
        })
    }

    fn slot(&mut self, field: &str) -> Option<&mut Option<f64>> {
        Some(match field {
            "FullPanoWidthPixels" => &mut self.full_pano_width_pixels,
            "FullPanoHeightPixels" => &mut self.full_pano_height_pixels,
            "CroppedAreaLeftPixels" => &mut self.cropped_area_left_pixels,
            "CroppedAreaTopPixels" => &mut self.cropped_area_top_pixels,
            "CroppedAreaImageWidthPixels" => &mut self.cropped_area_image_width_pixels,
            "CroppedAreaImageHeightPixels" => &mut self.cropped_area_image_height_pixels,
            "PoseHeadingDegrees" => &mut self.pose_heading_degrees,
            "PosePitchDegrees" => &mut self.pose_pitch_degrees,
            "PoseRollDegrees" => &mut self.pose_roll_degrees,
            "InitialViewHeadingDegrees" => &mut self.initial_view_heading_degrees,
            "InitialViewPitchDegrees" => &mut self.initial_view_pitch_degrees,
            "InitialHorizontalFOVDegrees" => &mut self.initial_horizontal_fov_degrees,
            _ => return None,
        })
    }

    /// Record one field (the first occurrence wins).
    fn set(&mut self, field: &str, text: &str) -> Result<(), GPanoError> {
        let text = text.trim();
        if field == "ProjectionType" {
            if self.projection_type.is_none() {
                self.projection_type = Some(text.to_string());
            }
            return Ok(());
        }
        if VIEW_FIELDS.contains(&field) {
            let ok = |v: &f64| {
                v.is_finite()
                    && (field != "InitialHorizontalFOVDegrees" || (*v > 0.0 && *v < 180.0))
            };
            if let (Some(v), Some(slot)) = (text.parse::<f64>().ok().filter(ok), self.slot(field)) {
                slot.get_or_insert(v);
            }
            return Ok(());
        }
        let name = FIELDS.iter().find(|f| **f == field).copied().unwrap_or("?");
        let heading = matches!(
            field,
            "PoseHeadingDegrees" | "PosePitchDegrees" | "PoseRollDegrees"
        );
        let value: f64 = text.parse().map_err(|_| GPanoError::Value {
            field: name,
            value: text.to_string(),
            expected: "a number",
        })?;
        if !value.is_finite() || (!heading && value < 0.0) {
            return Err(GPanoError::Value {
                field: name,
                value: text.to_string(),
                expected: if heading {
                    "a finite number"
                } else {
                    "a non-negative number of pixels"
                },
            });
        }
        if let Some(slot) = self.slot(field) {
            if slot.is_none() {
                *slot = Some(value);
            }
        }
        Ok(())
    }

    /// Read the fields from an XMP packet (UTF-8 XML).
    ///
    /// # Errors
    /// [`GPanoError`] for malformed XML that mentions GPano, or bad values.
    pub fn from_xmp(xmp: &str) -> Result<Option<GPano>, GPanoError> {
        let xmp = xmp.trim_end_matches(['\0', ' ', '\n', '\r', '\t']);
        let doc = match roxmltree::Document::parse(xmp) {
            Ok(d) => d,
            // XMP that has nothing to do with panoramas must not stop a file opening.
            Err(_) if !xmp.contains("GPano") && !xmp.contains(GPANO_NS) => return Ok(None),
            Err(e) => return Err(GPanoError::Xml(e.to_string())),
        };
        let mut g = GPano::default();
        let mut any = false;
        for node in doc.descendants().filter(|n| n.is_element()) {
            for a in node.attributes() {
                if a.namespace() == Some(GPANO_NS) && FIELDS.contains(&a.name()) {
                    g.set(a.name(), a.value())?;
                    any = true;
                }
            }
            let tag = node.tag_name();
            if tag.namespace() == Some(GPANO_NS) && FIELDS.contains(&tag.name()) {
                let text: String = node
                    .children()
                    .filter(|c| c.is_text())
                    .filter_map(|c| c.text())
                    .collect();
                g.set(tag.name(), &text)?;
                any = true;
            }
        }
        Ok(any.then_some(g))
    }

    /// Where an `image_w × image_h` image with these fields sits in its full panorama
    /// (the rules are in the module docs).
    ///
    /// # Errors
    /// [`CoverageError::GPanoCrop`] naming the field and the values, or the
    /// [`CoverageError::Crop`] of an impossible crop.
    pub fn crop_for_image(&self, image_w: u32, image_h: u32) -> Result<Crop, CoverageError> {
        let err = CoverageError::GPanoCrop;
        if let Some(t) = &self.projection_type {
            if !t.eq_ignore_ascii_case("equirectangular") {
                return Err(err(GPanoError::Inconsistent(format!(
                    "ProjectionType '{t}' is not supported (only equirectangular)"
                ))));
            }
        }
        let need = |v: Option<f64>, name| v.ok_or(GPanoError::Missing(name)).map_err(err);
        let fw = need(self.full_pano_width_pixels, "FullPanoWidthPixels")?;
        let cw = need(
            self.cropped_area_image_width_pixels,
            "CroppedAreaImageWidthPixels",
        )?;
        let ch = need(
            self.cropped_area_image_height_pixels,
            "CroppedAreaImageHeightPixels",
        )?;
        let left = need(self.cropped_area_left_pixels, "CroppedAreaLeftPixels")?;
        let top = need(self.cropped_area_top_pixels, "CroppedAreaTopPixels")?;
        let fh = self.full_pano_height_pixels.unwrap_or(fw / 2.0);
        let (iw, ih) = (image_w as f64, image_h as f64);
        if fw < 1.0 || fh < 1.0 || cw < 1.0 || ch < 1.0 {
            return Err(err(GPanoError::Inconsistent(format!(
                "sizes must be positive (full {fw}x{fh}, cropped {cw}x{ch})"
            ))));
        }
        if left >= fw {
            return Err(err(GPanoError::Inconsistent(format!(
                "CroppedAreaLeftPixels {left} is not a column of the full panorama \
                 (0 to {})",
                fw - 1.0
            ))));
        }
        if cw > fw || ch > fh {
            return Err(err(GPanoError::Inconsistent(format!(
                "cropped area {cw}x{ch} is larger than the full panorama {fw}x{fh}"
            ))));
        }
        if top + ch > fh + 0.5 {
            return Err(err(GPanoError::Inconsistent(format!(
                "cropped rows {top}..{} run below the full panorama's {fh} rows",
                top + ch
            ))));
        }
        // A resized image: scale every pixel value by the image's own scale.
        let s = iw / cw;
        if ((ih / ch) / s - 1.0).abs() > 0.01 {
            return Err(err(GPanoError::Inconsistent(format!(
                "cropped area is {cw}x{ch} but the image is {image_w}x{image_h} \
                 (not the same shape)"
            ))));
        }
        let full_w = (fw * s).round();
        let full_h = (fh * s).round();
        let max = MAX_MAP_WIDTH as f64;
        if full_w > max || full_h > max {
            return Err(err(GPanoError::Inconsistent(format!(
                "full panorama {full_w}x{full_h} (at the image's scale) is larger than \
                 the supported {max} pixels per side"
            ))));
        }
        let (full_w, full_h) = (full_w.max(iw) as u32, full_h.max(ih) as u32);
        let left = ((left * s).round() as u64 % full_w as u64) as u32;
        let top = ((top * s).round() as u32).min(full_h - image_h);
        Crop::new(full_w, full_h, left, top, image_w, image_h)
    }
}

/// The main XMP packet of a JPEG (the APP1 segment after the signature), or `None` for
/// a file that is not a JPEG or has no XMP. Stops at the first scan; a truncated segment
/// ends the search.
pub fn jpeg_xmp(bytes: &[u8]) -> Option<&[u8]> {
    if bytes.len() < 4 || bytes[0] != 0xFF || bytes[1] != 0xD8 {
        return None;
    }
    let mut i = 2;
    while i + 4 <= bytes.len() {
        if bytes[i] != 0xFF {
            return None;
        }
        let marker = bytes[i + 1];
        match marker {
            0xFF => {
                i += 1; // fill byte
                continue;
            }
            0x01 | 0xD0..=0xD7 => {
                i += 2; // markers without a length
                continue;
            }
            0xD9 | 0xDA => return None, // end of image, start of scan
            _ => {}
        }
        let len = u16::from_be_bytes([bytes[i + 2], bytes[i + 3]]) as usize;
        if len < 2 || i + 2 + len > bytes.len() {
            return None;
        }
        let data = &bytes[i + 4..i + 2 + len];
        if marker == 0xE1 && data.starts_with(XMP_SIGNATURE) {
            return Some(&data[XMP_SIGNATURE.len()..]);
        }
        i += 2 + len;
    }
    None
}

/// GPano fields of a JPEG's XMP, `Ok(None)` when there are none (or it is no JPEG).
///
/// # Errors
/// [`GPanoError`] as [`GPano::from_xmp`]; XMP that is not UTF-8 is an error only when it
/// mentions GPano.
pub fn read_gpano(bytes: &[u8]) -> Result<Option<GPano>, GPanoError> {
    let Some(xmp) = jpeg_xmp(bytes) else {
        return Ok(None);
    };
    match std::str::from_utf8(xmp) {
        Ok(s) => GPano::from_xmp(s),
        Err(e) => {
            let mentions = xmp.windows(5).any(|w| w == b"GPano");
            if mentions {
                Err(GPanoError::Xml(format!("XMP packet is not UTF-8: {e}")))
            } else {
                Ok(None)
            }
        }
    }
}

/// Insert an APP1 XMP segment holding `xmp` right after a JPEG's SOI marker (for tests
/// and tools that tag images).
///
/// # Errors
/// [`GPanoError::Inconsistent`] when `jpeg` is not a JPEG or `xmp` is too long for one
/// segment (65502 bytes).
pub fn insert_xmp(jpeg: &[u8], xmp: &str) -> Result<Vec<u8>, GPanoError> {
    if jpeg.len() < 2 || jpeg[0] != 0xFF || jpeg[1] != 0xD8 {
        return Err(GPanoError::Inconsistent(
            "not a JPEG (no SOI marker)".into(),
        ));
    }
    let len = 2 + XMP_SIGNATURE.len() + xmp.len();
    let len = u16::try_from(len)
        .map_err(|_| GPanoError::Inconsistent(format!("XMP of {} bytes is too long", xmp.len())))?;
    let mut out = Vec::with_capacity(jpeg.len() + len as usize + 2);
    out.extend_from_slice(&jpeg[..2]);
    out.extend_from_slice(&[0xFF, 0xE1]);
    out.extend_from_slice(&len.to_be_bytes());
    out.extend_from_slice(XMP_SIGNATURE);
    out.extend_from_slice(xmp.as_bytes());
    out.extend_from_slice(&jpeg[2..]);
    Ok(out)
}

/// A minimal XMP packet with GPano fields in attribute form (what phones write).
/// Values are `(field name without prefix, value)`.
pub fn xmp_packet(fields: &[(&str, &str)]) -> String {
    let attrs: String = fields
        .iter()
        .map(|(k, v)| format!("\n      GPano:{k}=\"{v}\""))
        .collect();
    format!(
        "<?xpacket begin=\"\u{feff}\" id=\"W5M0MpCehiHzreSzNTczkc9d\"?>\n\
         <x:xmpmeta xmlns:x=\"adobe:ns:meta/\">\n\
         <rdf:RDF xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n\
         <rdf:Description rdf:about=\"\" xmlns:GPano=\"{GPANO_NS}\"{attrs}/>\n\
         </rdf:RDF>\n</x:xmpmeta>\n<?xpacket end=\"w\"?>"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const ELEMENTS: &str = r#"<x:xmpmeta xmlns:x="adobe:ns:meta/">
 <rdf:RDF xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">
  <rdf:Description rdf:about="" xmlns:Pano="http://ns.google.com/photos/1.0/panorama/"
      xmlns:xmpNote="http://ns.adobe.com/xmp/note/" xmpNote:HasExtendedXMP="ABCDEF">
   <Pano:ProjectionType>equirectangular</Pano:ProjectionType>
   <Pano:FullPanoWidthPixels>8000</Pano:FullPanoWidthPixels>
   <Pano:FullPanoHeightPixels> 4000 </Pano:FullPanoHeightPixels>
   <Pano:CroppedAreaLeftPixels>7000</Pano:CroppedAreaLeftPixels>
   <Pano:CroppedAreaTopPixels>1000</Pano:CroppedAreaTopPixels>
   <Pano:CroppedAreaImageWidthPixels>2000</Pano:CroppedAreaImageWidthPixels>
   <Pano:CroppedAreaImageHeightPixels>1500</Pano:CroppedAreaImageHeightPixels>
   <Pano:PoseHeadingDegrees>-45.5</Pano:PoseHeadingDegrees>
  </rdf:Description>
 </rdf:RDF>
</x:xmpmeta>"#;

    #[test]
    fn element_form_with_another_prefix() {
        let g = GPano::from_xmp(ELEMENTS).unwrap().unwrap();
        assert_eq!(g.full_pano_width_pixels, Some(8000.0));
        assert_eq!(g.full_pano_height_pixels, Some(4000.0));
        assert_eq!(g.pose_heading_degrees, Some(-45.5));
        // resized to half: everything scales by 0.5; the crop straddles the seam
        let c = g.crop_for_image(1000, 750).unwrap();
        assert_eq!(
            (c.full_width(), c.full_height(), c.left(), c.top()),
            (4000, 2000, 3500, 500)
        );
        assert!(c.straddles_seam());
    }

    #[test]
    fn attribute_form_round_trips_through_a_jpeg() {
        let xmp = xmp_packet(&[
            ("FullPanoWidthPixels", "1000"),
            ("FullPanoHeightPixels", "500"),
            ("CroppedAreaLeftPixels", "100"),
            ("CroppedAreaTopPixels", "50"),
            ("CroppedAreaImageWidthPixels", "300"),
            ("CroppedAreaImageHeightPixels", "200"),
        ]);
        let mut jpeg = Vec::new();
        image::RgbImage::new(300, 200)
            .write_to(
                &mut std::io::Cursor::new(&mut jpeg),
                image::ImageFormat::Jpeg,
            )
            .unwrap();
        let tagged = insert_xmp(&jpeg, &xmp).unwrap();
        let g = read_gpano(&tagged).unwrap().unwrap();
        assert_eq!(g.cropped_area_left_pixels, Some(100.0));
        assert_eq!(g.pose_heading_degrees, None);
        let c = g.crop_for_image(300, 200).unwrap();
        assert_eq!(
            (c.left(), c.top(), c.width(), c.height()),
            (100, 50, 300, 200)
        );
        // the image still decodes
        assert!(image::load_from_memory(&tagged).is_ok());
        // untagged JPEG and non-JPEG bytes: nothing
        assert_eq!(read_gpano(&jpeg).unwrap(), None);
        assert_eq!(read_gpano(b"\x89PNG....").unwrap(), None);
    }

    #[test]
    fn unrelated_or_broken_xmp() {
        // unrelated, well-formed: nothing
        let plain = r#"<x:xmpmeta xmlns:x="adobe:ns:meta/"><a xmlns:dc="http://purl.org/dc/elements/1.1/" dc:format="image/jpeg"/></x:xmpmeta>"#;
        assert_eq!(GPano::from_xmp(plain).unwrap(), None);
        // unrelated, broken: nothing (does not stop the file opening)
        assert_eq!(
            GPano::from_xmp("<x:xmpmeta><oops></x:xmpmeta>").unwrap(),
            None
        );
        // broken and about GPano: an error
        let e = GPano::from_xmp("<a GPano:FullPanoWidthPixels='1'>").unwrap_err();
        assert!(matches!(e, GPanoError::Xml(_)));
        // trailing NULs and padding are fine
        let padded = format!("{}\n   \0\0", xmp_packet(&[("PoseHeadingDegrees", "10")]));
        assert_eq!(
            GPano::from_xmp(&padded)
                .unwrap()
                .unwrap()
                .pose_heading_degrees,
            Some(10.0)
        );
    }

    #[test]
    fn start_view_relative_to_the_pose_and_ignored_when_bad() {
        let g = GPano::from_xmp(&xmp_packet(&[
            ("PoseHeadingDegrees", "350"),
            ("InitialViewHeadingDegrees", "20"),
            ("InitialViewPitchDegrees", "-12.5"),
            ("InitialHorizontalFOVDegrees", "75"),
        ]))
        .unwrap()
        .unwrap();
        assert!(!g.has_crop(), "a start view is not a crop");
        let v = g.start_view().unwrap();
        assert!((v.yaw_deg - 30.0).abs() < 1e-9, "{v:?}");
        assert_eq!((v.pitch_deg, v.hfov_deg), (-12.5, Some(75.0)));
        // No pose: the heading is the yaw. Bad hints are ignored, not errors.
        let g = GPano::from_xmp(&xmp_packet(&[
            ("InitialViewHeadingDegrees", "200"),
            ("InitialViewPitchDegrees", "level"),
            ("InitialHorizontalFOVDegrees", "500"),
        ]))
        .unwrap()
        .unwrap();
        let v = g.start_view().unwrap();
        assert!((v.yaw_deg + 160.0).abs() < 1e-9, "{v:?}");
        assert_eq!((v.pitch_deg, v.hfov_deg), (0.0, None));
        let g = GPano::from_xmp(&xmp_packet(&[("PoseHeadingDegrees", "10")]))
            .unwrap()
            .unwrap();
        assert_eq!(g.start_view(), None);
    }

    #[test]
    fn bad_values() {
        for (k, v) in [
            ("FullPanoWidthPixels", "wide"),
            ("CroppedAreaTopPixels", "-3"),
            ("PoseHeadingDegrees", "NaN"),
            ("CroppedAreaLeftPixels", "inf"),
        ] {
            let e = GPano::from_xmp(&xmp_packet(&[(k, v)])).unwrap_err();
            assert!(matches!(e, GPanoError::Value { .. }), "{k}={v}: {e:?}");
            assert!(e.to_string().contains(k));
        }
    }

    fn gpano(f: [f64; 6]) -> GPano {
        GPano {
            full_pano_width_pixels: Some(f[0]),
            full_pano_height_pixels: Some(f[1]),
            cropped_area_left_pixels: Some(f[2]),
            cropped_area_top_pixels: Some(f[3]),
            cropped_area_image_width_pixels: Some(f[4]),
            cropped_area_image_height_pixels: Some(f[5]),
            ..GPano::default()
        }
    }

    #[test]
    fn inconsistent_metadata_is_an_error() {
        let cases = [
            // crop below the full panorama
            (gpano([1000.0, 500.0, 0.0, 400.0, 300.0, 200.0]), (300, 200)),
            // crop wider than the full panorama
            (gpano([1000.0, 500.0, 0.0, 0.0, 1300.0, 200.0]), (1300, 200)),
            // zero sizes
            (gpano([0.0, 500.0, 0.0, 0.0, 300.0, 200.0]), (300, 200)),
            (gpano([1000.0, 500.0, 0.0, 0.0, 0.0, 200.0]), (300, 200)),
            // image not the crop's shape
            (gpano([1000.0, 500.0, 0.0, 0.0, 300.0, 200.0]), (300, 100)),
            // full panorama too large at the image's scale
            (gpano([1e6, 5e5, 0.0, 0.0, 300.0, 200.0]), (300, 200)),
            // left edge outside the full panorama (issue 15: 4e9 on 512 pixels)
            (gpano([512.0, 256.0, 4e9, 0.0, 300.0, 200.0]), (300, 200)),
            (
                gpano([1000.0, 500.0, 1000.0, 0.0, 300.0, 200.0]),
                (300, 200),
            ),
        ];
        for (g, (w, h)) in cases {
            let e = g.crop_for_image(w, h);
            assert!(
                matches!(
                    e,
                    Err(CoverageError::GPanoCrop(_) | CoverageError::Crop { .. })
                ),
                "{g:?} {w}x{h}: {e:?}"
            );
        }
        let e = gpano([512.0, 256.0, 4e9, 0.0, 300.0, 200.0])
            .crop_for_image(300, 200)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("CroppedAreaLeftPixels") && e.contains("4000000000"),
            "{e}"
        );
        // The last column is still a column: the crop straddles the seam.
        let c = gpano([1000.0, 500.0, 999.0, 0.0, 300.0, 200.0])
            .crop_for_image(300, 200)
            .unwrap();
        assert!(c.straddles_seam());
        let mut g = gpano([1000.0, 500.0, 0.0, 0.0, 300.0, 200.0]);
        g.cropped_area_top_pixels = None;
        let e = g.crop_for_image(300, 200).unwrap_err().to_string();
        assert!(e.contains("CroppedAreaTopPixels"), "{e}");
        g.cropped_area_top_pixels = Some(0.0);
        g.projection_type = Some("cylindrical".into());
        assert!(g.crop_for_image(300, 200).is_err());
        // missing full height: 2:1
        let mut g = gpano([1000.0, 0.0, 0.0, 0.0, 300.0, 200.0]);
        g.full_pano_height_pixels = None;
        assert_eq!(g.crop_for_image(300, 200).unwrap().full_height(), 500);
    }

    #[test]
    fn jpeg_walk_is_robust() {
        // truncated segments and garbage never panic
        let xmp = xmp_packet(&[("FullPanoWidthPixels", "10")]);
        let full = insert_xmp(&[0xFF, 0xD8, 0xFF, 0xD9], &xmp).unwrap();
        for n in 0..full.len() {
            let _ = read_gpano(&full[..n]);
        }
        assert!(read_gpano(&full).unwrap().is_some());
        assert!(insert_xmp(b"GIF89a", &xmp).is_err());
        assert!(insert_xmp(&[0xFF, 0xD8], &"x".repeat(70000)).is_err());
    }
}
