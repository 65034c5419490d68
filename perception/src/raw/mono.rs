//! Monocular metric depth of an object from its 2D box, without a depth model.
//!
//! Three estimators, each with its assumption stated; every estimate says
//! which one produced it ([`DepthSource`]).
//!
//! - **Flat ground** ([`MonoDepthMethod::FlatGround`]): the road is a plane
//!   `CameraConfig::height_m` below the optical centre, parallel to the
//!   optical axis, and the box's bottom edge is where the object touches it:
//!   `Z_near = fy · height / (v_bottom − cy)` (see [`super::ground`]).
//! - **Size prior** ([`MonoDepthMethod::SizePrior`]): the object has its
//!   class's prior height `H` and stands on locally flat ground at an
//!   *unknown* height below the camera. The box's bottom row images the
//!   nearest ground edge of the object (depth `Zc − d`), its top row the far
//!   top edge (depth `Zc + d`, since the roof of a car is below a 1.65 m
//!   camera, the far roof edge is the highest), where `d` is half the
//!   object's extent along the optical axis. With `b = (v_bottom − cy)/fy`
//!   and `t = (v_top − cy)/fy`: `Y_ground = b·(Zc − d)` and
//!   `Y_ground − H = t·(Zc + d)`, so
//!   `Zc = (H + (b + t)·d) / (b − t)` — with `d = 0` the textbook
//!   `Z = fy · H / h_px`. It needs the box's top and bottom inside the image
//!   and gives the local ground height as a by-product, so it does not
//!   assume the ground is at the camera's mounting height.
//! - **Fused** ([`MonoDepthMethod::Fused`]): the inverse-variance weighted
//!   mean of both, with standard deviations from their error sources (see
//!   [`MonoDepthConfig`]): flat ground's relative error is the ground height
//!   deviation over the camera height plus one edge-pixel error over the
//!   rows below the horizon; the size prior's is the class's height spread
//!   over its height plus the pixel error of the box height. Near and far
//!   the weights shift on their own: far boxes sit close to the horizon
//!   (flat ground degrades), small boxes make the height uncertain.
//!
//! Nearest face → centre: a box's bottom edge images the nearest point of
//! the object's footprint, while a 3D position (KITTI's label `Z`) is the
//! footprint's centre. With a size prior for the class, the flat-ground
//! estimate adds half the object's extent along the optical axis, taking the
//! object as aligned with the camera's heading (the road direction: a car's
//! length points along `Z`); [`MonoDepthConfig::centre_correction`] turns
//! this off for comparison.

use serde::{Deserialize, Serialize};

use super::ground::{GroundConfig, ground_point};
use crate::coords::CameraPoint;
use crate::model::{BBox2D, CameraConfig, DepthSource};

/// The estimator a frames run uses when no depth model is configured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MonoDepthMethod {
    /// Box bottom on a plane at the camera's mounting height.
    FlatGround,
    /// Box height against the class's prior height (flat ground when the
    /// class has no prior or the box is cut by the image's top edge).
    SizePrior,
    /// Inverse-variance fusion of flat ground and the size prior (the one
    /// available when only one applies). The default: best on the broad
    /// KITTI label evaluation (docs/models.md).
    Fused,
}

/// The prior 3D size of one object type, metres.
///
/// Invariant: all fields finite and positive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SizePrior {
    /// Mean height.
    pub height_m: f64,
    /// Standard deviation of the height over the class.
    pub height_std_m: f64,
    /// Mean width (across the heading).
    pub width_m: f64,
    /// Mean length (along the heading).
    pub length_m: f64,
}

impl SizePrior {
    /// Half the footprint's extent along the optical axis for an object
    /// aligned with the camera's heading (its length along `Z`).
    pub fn half_depth_extent_m(&self) -> f64 {
        0.5 * self.length_m
    }
}

/// KITTI mean car size (means and height spread over the 27,300 `Car`
/// labels of the 21 KITTI tracking training sequences: h 1.52 ± 0.13 m, w
/// 1.63 m, l 3.88 m).
pub const KITTI_CAR: SizePrior = SizePrior {
    height_m: 1.52,
    height_std_m: 0.13,
    width_m: 1.63,
    length_m: 3.88,
};
/// KITTI mean pedestrian size (11,470 labels: h 1.76 ± 0.10 m, w 0.73 m, l
/// 0.89 m).
pub const KITTI_PEDESTRIAN: SizePrior = SizePrior {
    height_m: 1.76,
    height_std_m: 0.10,
    width_m: 0.73,
    length_m: 0.89,
};
/// KITTI mean truck size (1,189 labels: h 3.47 ± 0.38 m, w 2.70 m, l 10.77 m).
pub const KITTI_TRUCK: SizePrior = SizePrior {
    height_m: 3.47,
    height_std_m: 0.38,
    width_m: 2.70,
    length_m: 10.77,
};
/// KITTI mean tram size (595 labels: h 3.65 ± 0.07 m, w 2.67 m, l 11.89 m).
pub const KITTI_TRAM: SizePrior = SizePrior {
    height_m: 3.65,
    height_std_m: 0.07,
    width_m: 2.67,
    length_m: 11.89,
};

/// Standard deviation of the labelled ground height under unoccluded cars
/// within 30 m across the 21 KITTI tracking sequences (their box bottom `Y`:
/// mean 1.57 m, spread 0.23 m): how far real roads are from one plane at the
/// mounting height.
pub const KITTI_GROUND_HEIGHT_STD_M: f64 = 0.23;

/// Monocular depth settings.
///
/// Invariant: `ground_height_std_m`, `box_edge_std_px` and
/// `top_margin_px` are finite and non-negative; priors are valid
/// [`SizePrior`]s keyed by `TypeOf` value.
#[derive(Debug, Clone, PartialEq)]
pub struct MonoDepthConfig {
    /// Which estimator a frames run uses.
    pub method: MonoDepthMethod,
    /// Whether flat ground adds the nearest-face → centre offset (for
    /// classes with a size prior).
    pub centre_correction: bool,
    /// Size priors by `TypeOf` value (`Car`, `Pedestrian`, …); types without
    /// one get flat ground only, uncorrected.
    pub priors: Vec<(String, SizePrior)>,
    /// Spread of the real ground height around `CameraConfig::height_m`,
    /// metres (flat ground's main error).
    pub ground_height_std_m: f64,
    /// Error of one box edge, pixels (an a-priori value for detectors and
    /// labels alike; on the two checked KITTI cars NanoDet's top and bottom
    /// edges differ from the labels' by 0.2–4.4 px).
    pub box_edge_std_px: f64,
    /// A box top within this many pixels of the image's first row counts as
    /// cut by the image (its height is not the object's).
    pub top_margin_px: f64,
}

impl Default for MonoDepthConfig {
    fn default() -> Self {
        MonoDepthConfig {
            method: MonoDepthMethod::Fused,
            centre_correction: true,
            priors: vec![
                ("Car".to_string(), KITTI_CAR),
                ("Pedestrian".to_string(), KITTI_PEDESTRIAN),
                ("Truck".to_string(), KITTI_TRUCK),
                ("Tram".to_string(), KITTI_TRAM),
            ],
            ground_height_std_m: KITTI_GROUND_HEIGHT_STD_M,
            box_edge_std_px: 1.5,
            top_margin_px: 3.0,
        }
    }
}

impl MonoDepthConfig {
    /// The size prior of a `TypeOf` value, if configured.
    pub fn prior(&self, type_name: Option<&str>) -> Option<&SizePrior> {
        let t = type_name?;
        self.priors
            .iter()
            .find(|(name, _)| name == t)
            .map(|(_, p)| p)
    }

    /// This config with another method.
    pub fn with_method(&self, method: MonoDepthMethod) -> MonoDepthConfig {
        MonoDepthConfig {
            method,
            ..self.clone()
        }
    }
}

/// A monocular position estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthEstimate {
    /// Bottom-centre of the object's footprint in camera coordinates (X
    /// right, Y down to the ground, Z forward), metres — the KITTI label
    /// convention.
    pub position: CameraPoint,
    /// Which estimator gave it.
    pub source: DepthSource,
    /// Its standard deviation from the stated error model, metres (`None`
    /// for flat ground of a type without a size prior, whose centre offset
    /// is unknown).
    pub std_m: Option<f64>,
    /// Whether the box is cut by the image's bottom edge: the ground contact
    /// is not visible and the depth is an overestimate.
    pub cut_by_image: bool,
    /// The nearest-face → centre offset included in `position`'s Z, metres
    /// (half the prior's length for a type with a size prior and
    /// [`MonoDepthConfig::centre_correction`] on, else 0). Both estimators
    /// use the same offset, so the fusion carries it unchanged.
    pub centre_offset_m: f64,
}

impl DepthEstimate {
    /// Forward depth `Z` of the footprint's centre, metres.
    pub fn z(&self) -> f64 {
        self.position.0.z
    }

    /// Forward depth of the object's nearest face (the surface a depth map
    /// sees at the box's lower half), metres: `z() − centre_offset_m`.
    pub fn near_z(&self) -> f64 {
        self.position.0.z - self.centre_offset_m
    }
}

/// The nearest-face → centre offset of a type, metres: half its prior's
/// extent along the optical axis when it has a prior and the correction is
/// on, else 0 (no known extent). The one offset every path adds to a
/// near-face depth (flat ground, the size prior, depth maps).
pub fn centre_offset_m(config: &MonoDepthConfig, type_name: Option<&str>) -> f64 {
    match config.prior(type_name) {
        Some(p) if config.centre_correction => p.half_depth_extent_m(),
        _ => 0.0,
    }
}

/// One estimator's raw result: centre depth, ground height, std.
#[derive(Debug, Clone, Copy)]
struct Part {
    z: f64,
    ground_y: f64,
    std: f64,
}

fn flat_part(
    bbox: &BBox2D,
    camera: &CameraConfig,
    ground: &GroundConfig,
    config: &MonoDepthConfig,
    offset: f64,
) -> Option<(Part, bool)> {
    let g = ground_point(bbox, camera, ground)?;
    let k = &camera.intrinsics;
    let z_near = g.position.0.z;
    let rows = bbox.bottom - k.cy;
    let rel = (config.ground_height_std_m / camera.height_m).hypot(config.box_edge_std_px / rows);
    Some((
        Part {
            z: z_near + offset,
            ground_y: camera.height_m,
            std: z_near * rel,
        },
        g.truncated_bottom,
    ))
}

fn size_part(
    bbox: &BBox2D,
    camera: &CameraConfig,
    ground: &GroundConfig,
    config: &MonoDepthConfig,
    prior: &SizePrior,
    d: f64,
) -> Option<Part> {
    let k = &camera.intrinsics;
    let bottom_cut = bbox.bottom >= f64::from(k.image_height) - 1.0 - ground.bottom_margin_px;
    let top_cut = bbox.top <= config.top_margin_px;
    let px = bbox.height();
    if bottom_cut || top_cut || px.is_nan() || px <= 0.0 {
        return None;
    }
    let b = (bbox.bottom - k.cy) / k.fy;
    let t = (bbox.top - k.cy) / k.fy;
    let z = (prior.height_m + (b + t) * d) / (b - t);
    if !(z.is_finite() && z > d && z <= ground.max_depth_m) {
        return None;
    }
    let rel = (prior.height_std_m / prior.height_m)
        .hypot(std::f64::consts::SQRT_2 * config.box_edge_std_px / px);
    Some(Part {
        z,
        ground_y: b * (z - d),
        std: z * rel,
    })
}

/// The monocular position of an object of type `type_name` seen in `bbox`,
/// by `config.method`, or `None` when no estimator applies (box bottom at or
/// above the horizon and no usable size prior).
pub fn estimate(
    bbox: &BBox2D,
    type_name: Option<&str>,
    camera: &CameraConfig,
    ground: &GroundConfig,
    config: &MonoDepthConfig,
) -> Option<DepthEstimate> {
    let prior = config.prior(type_name);
    // One offset for both estimators, so their fusion and `near_z` agree.
    let offset = centre_offset_m(config, type_name);
    let flat = flat_part(bbox, camera, ground, config, offset);
    let cut = flat.is_some_and(|(_, c)| c);
    let size = if config.method == MonoDepthMethod::FlatGround {
        None
    } else {
        prior.and_then(|p| size_part(bbox, camera, ground, config, p, offset))
    };
    let (part, source) = match (config.method, flat.filter(|_| !cut), size) {
        (MonoDepthMethod::Fused, Some((f, _)), Some(s)) => {
            let (wf, ws) = (f.std.powi(-2), s.std.powi(-2));
            let w = wf + ws;
            let fused = Part {
                z: (f.z * wf + s.z * ws) / w,
                ground_y: (f.ground_y * wf + s.ground_y * ws) / w,
                std: w.sqrt().recip(),
            };
            (fused, DepthSource::Fused)
        }
        (MonoDepthMethod::Fused | MonoDepthMethod::SizePrior, _, Some(s)) => {
            (s, DepthSource::SizePrior)
        }
        // Flat ground, also as the fallback (no prior, top cut, or a cut
        // bottom, which is then flagged).
        _ => (flat?.0, DepthSource::FlatGround),
    };
    let k = &camera.intrinsics;
    let x = (bbox.center_x() - k.cx) * part.z / k.fx;
    let std_m = (source != DepthSource::FlatGround || prior.is_some()).then_some(part.std);
    Some(DepthEstimate {
        position: CameraPoint::new(x, part.ground_y, part.z),
        source,
        std_m,
        cut_by_image: cut && source == DepthSource::FlatGround,
        centre_offset_m: offset,
    })
}

/// Test fixtures shared with the frames tests.
#[cfg(test)]
pub(crate) mod test_support {
    use super::SizePrior;
    use crate::coords::CameraPoint;
    use crate::model::{BBox2D, CameraConfig};

    /// The image box of a road-aligned car of `prior`'s size with its
    /// footprint centre at `(x, ground_y, z)`.
    pub(crate) fn car_box(
        cam: &CameraConfig,
        prior: &SizePrior,
        x: f64,
        ground_y: f64,
        z: f64,
    ) -> BBox2D {
        let (hw, hl) = (prior.width_m / 2.0, prior.length_m / 2.0);
        let mut b = BBox2D {
            left: f64::INFINITY,
            top: f64::INFINITY,
            right: f64::NEG_INFINITY,
            bottom: f64::NEG_INFINITY,
        };
        for dx in [-hw, hw] {
            for dz in [-hl, hl] {
                for y in [ground_y, ground_y - prior.height_m] {
                    let p = CameraPoint::new(x + dx, y, z + dz);
                    let [u, v]: [f64; 2] = cam.intrinsics.project(p, 0.1).unwrap().into();
                    b = BBox2D {
                        left: b.left.min(u),
                        top: b.top.min(v),
                        right: b.right.max(u),
                        bottom: b.bottom.max(v),
                    };
                }
            }
        }
        b
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::car_box;
    use super::*;

    fn kitti() -> CameraConfig {
        crate::kitti::KITTI_2011_09_26_CAMERA
    }

    #[test]
    fn every_method_recovers_a_prior_sized_car_on_flat_ground() {
        let cam = kitti();
        let config = MonoDepthConfig::default();
        for &(x, z) in &[(0.0, 8.0), (-3.0, 14.0), (2.5, 27.0)] {
            let b = car_box(&cam, &KITTI_CAR, x, cam.height_m, z);
            for m in [
                MonoDepthMethod::FlatGround,
                MonoDepthMethod::SizePrior,
                MonoDepthMethod::Fused,
            ] {
                let e = estimate(
                    &b,
                    Some("Car"),
                    &cam,
                    &GroundConfig::default(),
                    &config.with_method(m),
                )
                .unwrap();
                assert!((e.z() - z).abs() < 1e-6, "{m:?} at {z}: {e:?}");
                assert!((e.position.0.x - x).abs() < 0.05 * z, "{m:?}: {e:?}");
                assert!((e.position.0.y - cam.height_m).abs() < 1e-6, "{m:?}: {e:?}");
                let want = match m {
                    MonoDepthMethod::FlatGround => DepthSource::FlatGround,
                    MonoDepthMethod::SizePrior => DepthSource::SizePrior,
                    MonoDepthMethod::Fused => DepthSource::Fused,
                };
                assert_eq!(e.source, want);
                // The near face is the centre less half the car's length,
                // whichever estimator gave it (relative and metric depth
                // maps see that face).
                assert_eq!(e.centre_offset_m, KITTI_CAR.half_depth_extent_m());
                assert!((e.near_z() - (z - 1.94)).abs() < 1e-6, "{m:?}: {e:?}");
            }
        }
    }

    #[test]
    fn the_size_prior_finds_a_lower_ground_that_flat_ground_misses() {
        // The ground under the car is 0.4 m lower than the mounting height
        // (sequence 0001 has such a parking area): flat ground is short by
        // about a sixth, the size prior is exact and reports the ground.
        let cam = kitti();
        let b = car_box(&cam, &KITTI_CAR, -2.0, 2.05, 12.0);
        let config = MonoDepthConfig::default();
        let flat = estimate(
            &b,
            Some("Car"),
            &cam,
            &GroundConfig::default(),
            &config.with_method(MonoDepthMethod::FlatGround),
        )
        .unwrap();
        assert!(flat.z() < 10.5, "{flat:?}");
        let size = estimate(
            &b,
            Some("Car"),
            &cam,
            &GroundConfig::default(),
            &config.with_method(MonoDepthMethod::SizePrior),
        )
        .unwrap();
        assert!(
            (size.z() - 12.0).abs() < 1e-6 && (size.position.0.y - 2.05).abs() < 1e-6,
            "{size:?}"
        );
        let fused = estimate(&b, Some("Car"), &cam, &GroundConfig::default(), &config).unwrap();
        assert!(fused.z() > flat.z() && fused.z() < size.z(), "{fused:?}");
        assert!(fused.std_m.unwrap() < size.std_m.unwrap().min(flat.std_m.unwrap()));
    }

    #[test]
    fn fallbacks_are_named() {
        let cam = kitti();
        let config = MonoDepthConfig::default();
        let g = GroundConfig::default();
        // No prior for the type: uncorrected flat ground.
        let b = car_box(&cam, &KITTI_CAR, 0.0, cam.height_m, 10.0);
        let e = estimate(&b, Some("Motorcycle"), &cam, &g, &config).unwrap();
        assert_eq!(e.source, DepthSource::FlatGround);
        assert_eq!((e.centre_offset_m, e.near_z()), (0.0, e.z()));
        assert!(
            (e.z() - (10.0 - KITTI_CAR.half_depth_extent_m())).abs() < 1e-6 && e.std_m.is_none()
        );
        // Top cut by the image: the height is not the car's, flat ground.
        let cut_top = BBox2D { top: 0.0, ..b };
        assert_eq!(
            estimate(&cut_top, Some("Car"), &cam, &g, &config)
                .unwrap()
                .source,
            DepthSource::FlatGround
        );
        // Bottom cut by the image: flagged flat ground.
        let cut_bottom = BBox2D { bottom: 374.0, ..b };
        let e = estimate(&cut_bottom, Some("Car"), &cam, &g, &config).unwrap();
        assert!(
            e.cut_by_image && e.source == DepthSource::FlatGround,
            "{e:?}"
        );
        // Bottom above the horizon: only the size prior applies.
        let above = BBox2D {
            left: 100.0,
            top: 100.0,
            right: 160.0,
            bottom: 170.0,
        };
        assert_eq!(
            estimate(&above, Some("Car"), &cam, &g, &config)
                .unwrap()
                .source,
            DepthSource::SizePrior
        );
        assert!(estimate(&above, Some("Motorcycle"), &cam, &g, &config).is_none());
        // No centre correction: flat ground is the contact depth.
        let raw = MonoDepthConfig {
            centre_correction: false,
            ..config.with_method(MonoDepthMethod::FlatGround)
        };
        let e = estimate(&b, Some("Car"), &cam, &g, &raw).unwrap();
        assert!(
            (e.z() - (10.0 - KITTI_CAR.half_depth_extent_m())).abs() < 1e-6,
            "{e:?}"
        );
        assert_eq!((e.centre_offset_m, e.near_z()), (0.0, e.z()));
    }

    #[test]
    fn nan_boxes_give_nothing() {
        let cam = kitti();
        let b = BBox2D {
            left: f64::NAN,
            top: f64::NAN,
            right: f64::NAN,
            bottom: f64::NAN,
        };
        assert!(
            estimate(
                &b,
                Some("Car"),
                &cam,
                &GroundConfig::default(),
                &MonoDepthConfig::default()
            )
            .is_none()
        );
    }
}
