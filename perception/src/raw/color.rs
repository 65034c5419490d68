//! Names the colour of an object from the pixels inside its box, with the
//! LogicPad `ColorOf` values.
//!
//! Every pixel of the box's central region (the border is mostly background)
//! is named on its own from hue, saturation and value, and the most frequent
//! name wins (ties go to the earlier value in [`COLOR_VALUES`]); a vote is
//! robust to windows, shadows and highlights that would drag a mean colour
//! towards grey.

use image::RgbImage;

use crate::model::BBox2D;

/// The `ColorOf` values, in tie-breaking order.
pub const COLOR_VALUES: [&str; 13] = [
    "Black", "Blue", "Brown", "Cyan", "Green", "Grey", "Orange", "Red", "Violet", "White",
    "Yellow", "Silver", "Other",
];

/// Colour naming thresholds (HSV, all in `[0, 1]` except hue in degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColorConfig {
    /// Fraction of the box width and height kept around its centre.
    pub central_fraction: f64,
    /// Pixels darker than this value are `Black`.
    pub black_value: f32,
    /// Pixels less saturated than this are achromatic (white, silver, grey).
    pub grey_saturation: f32,
    /// Achromatic pixels brighter than this are `White`.
    pub white_value: f32,
    /// Achromatic pixels brighter than this (and not white) are `Silver`.
    pub silver_value: f32,
    /// Orange-hued pixels darker than this are `Brown`.
    pub brown_value: f32,
}

impl Default for ColorConfig {
    fn default() -> Self {
        ColorConfig {
            central_fraction: 0.6,
            black_value: 0.18,
            grey_saturation: 0.18,
            white_value: 0.78,
            silver_value: 0.55,
            brown_value: 0.55,
        }
    }
}

/// The name of one RGB pixel.
pub fn name_pixel(rgb: [u8; 3], config: &ColorConfig) -> &'static str {
    let [r, g, b] = rgb.map(|v| f32::from(v) / 255.0);
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    if max < config.black_value {
        return "Black";
    }
    let sat = if max > 0.0 { (max - min) / max } else { 0.0 };
    if sat < config.grey_saturation {
        return if max >= config.white_value {
            "White"
        } else if max >= config.silver_value {
            "Silver"
        } else {
            "Grey"
        };
    }
    let d = max - min;
    let hue = if max == r {
        60.0 * ((g - b) / d).rem_euclid(6.0)
    } else if max == g {
        60.0 * ((b - r) / d + 2.0)
    } else {
        60.0 * ((r - g) / d + 4.0)
    };
    match hue {
        h if !(15.0..330.0).contains(&h) => "Red",
        h if h < 40.0 => {
            if max < config.brown_value {
                "Brown"
            } else {
                "Orange"
            }
        }
        h if h < 70.0 => "Yellow",
        h if h < 160.0 => "Green",
        h if h < 200.0 => "Cyan",
        h if h < 260.0 => "Blue",
        _ => "Violet",
    }
}

/// The colour of the pixels in `bbox`, `None` when the box holds no pixel.
pub fn name_box(img: &RgbImage, bbox: &BBox2D, config: &ColorConfig) -> Option<&'static str> {
    let (w, h) = img.dimensions();
    let keep = config.central_fraction.clamp(0.05, 1.0);
    let cx = bbox.center_x();
    let cy = 0.5 * (bbox.top + bbox.bottom);
    let hw = 0.5 * bbox.width() * keep;
    let hh = 0.5 * bbox.height() * keep;
    let x0 = (cx - hw).floor().max(0.0) as u32;
    let y0 = (cy - hh).floor().max(0.0) as u32;
    let x1 = ((cx + hw).ceil().max(0.0) as u32).min(w);
    let y1 = ((cy + hh).ceil().max(0.0) as u32).min(h);
    let mut votes = [0usize; COLOR_VALUES.len()];
    for y in y0..y1 {
        for x in x0..x1 {
            let name = name_pixel(img.get_pixel(x, y).0, config);
            if let Some(i) = COLOR_VALUES.iter().position(|c| *c == name) {
                votes[i] += 1;
            }
        }
    }
    let (best, &count) = votes
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(&a.0)))?;
    (count > 0).then(|| COLOR_VALUES[best])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_are_named() {
        let c = ColorConfig::default();
        let cases = [
            ([10, 10, 12], "Black"),
            ([240, 240, 235], "White"),
            ([170, 172, 175], "Silver"),
            ([100, 100, 100], "Grey"),
            ([200, 20, 30], "Red"),
            ([230, 130, 20], "Orange"),
            ([110, 60, 20], "Brown"),
            ([230, 220, 30], "Yellow"),
            ([30, 160, 40], "Green"),
            ([30, 200, 210], "Cyan"),
            ([20, 40, 200], "Blue"),
            ([150, 40, 200], "Violet"),
        ];
        for (rgb, want) in cases {
            assert_eq!(name_pixel(rgb, &c), want, "{rgb:?}");
        }
    }

    #[test]
    fn box_vote_ignores_the_border_and_highlights() {
        let mut img = RgbImage::from_pixel(40, 40, image::Rgb([30, 160, 40]));
        // A red object 20x20 with a few white highlights.
        for y in 10..30 {
            for x in 10..30 {
                img.put_pixel(x, y, image::Rgb([200, 20, 30]));
            }
        }
        for x in 12..18 {
            img.put_pixel(x, 15, image::Rgb([250, 250, 250]));
        }
        let b = BBox2D {
            left: 8.0,
            top: 8.0,
            right: 32.0,
            bottom: 32.0,
        };
        assert_eq!(name_box(&img, &b, &ColorConfig::default()), Some("Red"));
        let outside = BBox2D {
            left: 100.0,
            top: 100.0,
            right: 120.0,
            bottom: 120.0,
        };
        assert_eq!(name_box(&img, &outside, &ColorConfig::default()), None);
    }
}
