//! Boxes: the axis-aligned image box every source gives, and the oriented
//! 3D box of labels and the simulator.

use nalgebra::{Point2, Point3};
use serde::{Deserialize, Serialize};

use crate::coords::yaw_axes;

/// An axis-aligned image box in pixels.
///
/// Invariant: `left <= right`, `top <= bottom`, all finite.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BBox2D {
    /// Left edge, pixels.
    pub left: f64,
    /// Top edge, pixels.
    pub top: f64,
    /// Right edge, pixels.
    pub right: f64,
    /// Bottom edge, pixels.
    pub bottom: f64,
}

impl BBox2D {
    /// The smallest box enclosing image points `(u, v)`; `None` without
    /// points.
    pub fn enclosing(points: impl IntoIterator<Item = Point2<f64>>) -> Option<BBox2D> {
        let mut it = points.into_iter().map(|p| [p.x, p.y]);
        let [u, v] = it.next()?;
        let first = BBox2D {
            left: u,
            top: v,
            right: u,
            bottom: v,
        };
        Some(it.fold(first, |b, [u, v]| BBox2D {
            left: b.left.min(u),
            top: b.top.min(v),
            right: b.right.max(u),
            bottom: b.bottom.max(v),
        }))
    }

    /// Box width in pixels.
    pub fn width(&self) -> f64 {
        self.right - self.left
    }
    /// Box height in pixels.
    pub fn height(&self) -> f64 {
        self.bottom - self.top
    }
    /// Horizontal centre, pixels.
    pub fn center_x(&self) -> f64 {
        0.5 * (self.left + self.right)
    }
    /// Area in square pixels.
    pub fn area(&self) -> f64 {
        self.width().max(0.0) * self.height().max(0.0)
    }
    /// Intersection over union with another box (0 when disjoint).
    pub fn iou(&self, other: &BBox2D) -> f64 {
        let w = (self.right.min(other.right) - self.left.max(other.left)).max(0.0);
        let h = (self.bottom.min(other.bottom) - self.top.max(other.top)).max(0.0);
        let inter = w * h;
        let union = self.area() + other.area() - inter;
        if union > 0.0 { inter / union } else { 0.0 }
    }
    /// Clips the box to an image; `None` when nothing of it is inside.
    pub fn clip(&self, width: u32, height: u32) -> Option<BBox2D> {
        let b = BBox2D {
            left: self.left.max(0.0),
            top: self.top.max(0.0),
            right: self.right.min(f64::from(width) - 1.0),
            bottom: self.bottom.min(f64::from(height) - 1.0),
        };
        (b.left < b.right && b.top < b.bottom).then_some(b)
    }
    /// Whether the box satisfies its invariant.
    pub fn is_valid(&self) -> bool {
        [self.left, self.top, self.right, self.bottom]
            .iter()
            .all(|v| v.is_finite())
            && self.left <= self.right
            && self.top <= self.bottom
    }
}

/// An oriented 3D box: bottom-centre on its supporting surface, size
/// `[h, w, l]`, yaw about the Y axis (KITTI convention: yaw 0 faces +X).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Box3D {
    /// Bottom-centre, metres.
    pub center: [f64; 3],
    /// `[h, w, l]`, metres.
    pub size: [f64; 3],
    /// Heading, radians.
    pub yaw: f64,
}

impl Box3D {
    /// The 8 corners, in the frame the box is given in: bottom four (the
    /// footprint, in [`crate::geometry::footprint`]'s order) then top four
    /// (Y down, so top has `y - h`).
    pub fn corners(&self) -> [Point3<f64>; 8] {
        let [h, w, l] = self.size;
        let (along, across) = yaw_axes(self.yaw);
        let base = Point2::new(self.center[0], self.center[2]);
        let mut out = [Point3::origin(); 8];
        let local = [
            (l / 2.0, w / 2.0),
            (l / 2.0, -w / 2.0),
            (-l / 2.0, -w / 2.0),
            (-l / 2.0, w / 2.0),
        ];
        for (k, (dl, dw)) in local.into_iter().enumerate() {
            let p = base + along * dl + across * dw;
            out[k] = Point3::new(p.x, self.center[1], p.y);
            out[k + 4] = Point3::new(p.x, self.center[1] - h, p.y);
        }
        out
    }
}
