//! Settings of a frames run, its progress reports, and the camera assumed
//! for uncalibrated frames.

use crate::model::{CameraConfig, CameraIntrinsics};
use crate::raw::camera::Calibration;
use crate::raw::color::ColorConfig;
use crate::raw::dense::InstanceConfig;
use crate::raw::detect::StageTimes;
use crate::raw::ground::GroundConfig;
use crate::raw::mono::MonoDepthConfig;
use crate::raw::tracker::TrackerConfig;

/// Camera height assumed when the caller gives no camera: KITTI's mounting
/// height (metres).
pub const DEFAULT_CAMERA_HEIGHT_M: f64 = 1.65;

/// Settings of the frames pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct FramesOptions {
    /// The camera's calibration (the frames give the image size); when
    /// `None`, [`assumed_camera`]: a pinhole with `fx = fy =` image width
    /// (about 53° horizontal field of view), principal point at the image
    /// centre and [`DEFAULT_CAMERA_HEIGHT_M`] — an assumption, recorded as
    /// the sequence's camera, that makes 3D only roughly metric.
    pub camera: Option<Calibration>,
    /// Frame rate of the frames, per second.
    pub fps: f64,
    /// Sequence name; the directory name when `None`.
    pub name: Option<String>,
    /// Tracker settings.
    pub tracker: TrackerConfig,
    /// Flat-ground settings.
    pub ground: GroundConfig,
    /// Monocular depth (flat ground / size prior / fused) when no metric
    /// depth model is configured; a metric depth model always takes
    /// precedence, and a relative one is fitted onto these estimates. Its
    /// centre offsets also apply to depth-map samples.
    pub mono: MonoDepthConfig,
    /// Colour naming settings.
    pub color: ColorConfig,
    /// Dense-instance settings.
    pub instances: InstanceConfig,
    /// Decode and resample the next frame on a second thread while the
    /// models run on the current one (same results, less wall time).
    pub prefetch: bool,
}

impl Default for FramesOptions {
    fn default() -> Self {
        FramesOptions {
            camera: None,
            fps: crate::model::DEFAULT_FPS,
            name: None,
            tracker: TrackerConfig::default(),
            ground: GroundConfig::default(),
            mono: MonoDepthConfig::default(),
            color: ColorConfig::default(),
            instances: InstanceConfig::default(),
            prefetch: true,
        }
    }
}

/// Progress of a long run, reported after every frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Frames done.
    pub done: u32,
    /// Frames in all.
    pub total: u32,
    /// Time in models and elsewhere so far.
    pub times: StageTimes,
}

/// The camera assumed for uncalibrated frames (see [`FramesOptions::camera`]).
pub fn assumed_camera(width: u32, height: u32) -> CameraConfig {
    let f = f64::from(width);
    CameraConfig {
        intrinsics: CameraIntrinsics {
            fx: f,
            fy: f,
            cx: f64::from(width) / 2.0,
            cy: f64::from(height) / 2.0,
            image_width: width,
            image_height: height,
        },
        height_m: DEFAULT_CAMERA_HEIGHT_M,
    }
}
